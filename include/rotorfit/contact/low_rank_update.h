#pragma once

#include <deal.II/lac/lapack_full_matrix.h>

#include <vector>

namespace rotorfit
{
  /**
   * The pair-space algebra of a low-rank (Woodbury) update (doc/theory.md 7.7):
   * K_A = K_base + B_D S B_D^T over the changed pairs D with springs S
   * (+eps for a pair that closed, -eps for one that opened). With the
   * influence columns F(:,p) = B^T K_base^-1 b_p and the capacitance matrix
   * S^-1 + F_DD,
   *   K_A^-1 r = K_base^-1 (r - B_D c),   c = (S^-1 + F_DD)^-1 B_D^T K_base^-1 r,
   *   B^T K_A^-1 r = t - F(:,D) c,       t = B^T K_base^-1 r.
   * Dense and serial (identical on every rank): the columns are computed
   * and cached by the caller (ContactSolver), indexed by pair.
   */
  class LowRankUpdate
  {
  public:
    /// The update of @p changed pairs with springs @p springs (S); every
    /// @p column[changed[a]] must hold F(:,changed[a]). Returns false, and
    /// is left empty, when the capacitance matrix is singular.
    bool
    reinit(const std::vector<unsigned int>        &changed,
           const std::vector<double>              &springs,
           const std::vector<std::vector<double>> &column);

    /// No update (K_A = K_base).
    void
    clear();

    bool
    empty() const
    {
      return d.empty();
    }

    /// D: the changed pairs.
    const std::vector<unsigned int> &
    changed() const
    {
      return d;
    }

    /// S: the spring of each changed pair, in the order of changed().
    const std::vector<double> &
    springs() const
    {
      return s;
    }

    /// t = B^T K_base^-1 r in, B^T K_A^-1 r out; returns c, one entry per
    /// changed pair (K_A^-1 r = K_base^-1 (r - B_D c)). @p column as in reinit().
    std::vector<double>
    apply(std::vector<double> &t, const std::vector<std::vector<double>> &column) const;

  private:
    std::vector<unsigned int>        d;
    std::vector<double>              s;
    dealii::LAPACKFullMatrix<double> capacitance; ///< S^-1 + F_DD, LU-factorised
  };
} // namespace rotorfit
