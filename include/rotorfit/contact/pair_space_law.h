#pragma once

#include <rotorfit/contact/contact_pairs.h>
#include <rotorfit/contact/contact_parameters.h>
#include <rotorfit/contact/contact_state.h>
#include <rotorfit/contact/pair_operators.h>

#include <deal.II/base/mpi.h>

#include <vector>

namespace rotorfit
{
  /**
   * The law of any active set as a dense problem in pair space
   * (doc/theory.md 7.8). With every influence column of the base
   * factorisation (every pair closed) known, the pair loads q with
   * u = K_base^-1 (F + B q) solve an n x n system per active set: the
   * flexibility F = B^T K_base^-1 B, t_C = B^T K_base^-1 F_c and the base
   * springs e give g = t + F q - delta and N = q - e (g + delta). The
   * inverse Z of the pair-space matrix is kept for the active set it was
   * made for and follows a changed set by Sherman-Morrison updates, one
   * per changed pair; no sparse solve.
   */
  class PairSpaceLaw
  {
  public:
    /// Parameters, pairs and their operators (kept referenced); @p w_max:
    /// the largest Omega^2 of the run (scales the centrifugal residual).
    void
    initialize(const ContactParameters &parameters,
               const ContactPairs      &pairs,
               const PairOperators     &operators,
               const MPI_Comm           comm,
               const double             w_max);

    /// F from the base's influence columns @p column (one per pair) and
    /// the base springs from its active set @p base_active.
    void
    set_flexibility(const std::vector<std::vector<double>> &column,
                    const std::vector<bool>                &base_active);

    /// t_C = B^T K_base^-1 F_c.
    void
    set_centrifugal_load(std::vector<double> &&t_C);

    /// The law of @p active (affine, w_fixed = 0), identical on every rank.
    ContactDecomposition
    decompose(const std::vector<bool> &active);

    /// Free the pair-space matrices (n^2 doubles each).
    void
    clear();

    /// Largest relative residual of a pair-space solve since initialize().
    double
    worst_residual() const
    {
      return worst_pair_residual;
    }

    /// Active sets reached by updates of the inverse since initialize().
    unsigned int
    n_low_rank_updates() const
    {
      return low_rank_updates;
    }

  private:
    /// Row @p i of the pair-space matrix for @p closed, and its two
    /// right-hand sides (interference, unit centrifugal load).
    void
    row(const unsigned int i, const bool closed, std::vector<double> &values, double &rhs_I,
        double &rhs_C) const;

    /// The two right-hand sides of that row alone.
    void
    rhs(const unsigned int i, const bool closed, double &rhs_I, double &rhs_C) const;

    /// Invert the pair-space matrix of @p active into inverse.
    void
    invert(const std::vector<bool> &active);

    /// Bring the inverse to @p active: Sherman-Morrison on few changed
    /// rows, a new inverse on many.
    void
    update_inverse(const std::vector<bool> &active);

    /// Row @p k of the inverse's set changes to that of @p active: a rank-one
    /// update of the inverse; false if it was near-singular and the
    /// inverse of @p active was made afresh instead.
    bool
    update_row(const unsigned int k, const std::vector<bool> &active);

    /// q = Z rhs, the gaps and forces of @p next and the relative residual
    /// of the rows of @p active.
    double
    solve_rows(const std::vector<bool> &active, const std::vector<double> &rhs,
               ContactDecomposition &next) const;

    const ContactParameters *parameters = nullptr;
    const ContactPairs      *pairs      = nullptr;
    const PairOperators     *ops        = nullptr;
    MPI_Comm                 comm       = MPI_COMM_SELF;
    double                   w_max      = 0;

    // F (row-major, n x n), t_C, the base springs e (eps on the base's
    // closed pairs), the inverse Z of the pair-space matrix of inverse_active
    std::vector<double> flexibility, t_C, base_spring, inverse;
    std::vector<bool>   inverse_active; ///< empty: no inverse
    double              worst_pair_residual = 0;
    unsigned int        low_rank_updates    = 0;
  };
} // namespace rotorfit
