#pragma once

#include <rotorfit/contact/contact_pairs.h>
#include <rotorfit/contact/contact_state.h>
#include <rotorfit/contact/low_rank_update.h>
#include <rotorfit/contact/pair_operators.h>
#include <rotorfit/linear_algebra/direct_solver.h>

#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/petsc_vector.h>

#include <optional>
#include <vector>

namespace rotorfit
{
  /**
   * The factorised base of the contact solve (doc/theory.md 7.7): K_base =
   * K + sum_A eps_i b_i b_i^T (- w M_perp) for the active set A it was made
   * for, the influence columns F(:,p) = B^T K_base^-1 b_p computed on it
   * (cached per base, by pair) and the low-rank (Woodbury) update from the
   * base to another active set. Everything cached here belongs to the base:
   * a new factorisation or a release drops it.
   */
  class BaseFactorization
  {
  public:
    /// The system: K (its pattern holds the pair couplings), M_perp or
    /// nullptr, and the pairs' operators (kept referenced).
    void
    initialize(const dealii::PETScWrappers::MPI::SparseMatrix &stiffness,
               const dealii::PETScWrappers::MPI::SparseMatrix *spin_softening_matrix,
               const dealii::AffineConstraints<double>        &constraints,
               const ContactPairs                             &pairs,
               const PairOperators                            &operators,
               const MPI_Comm                                  comm);

    /// Factorise K_A for @p active (at @p w with spin softening): the new base.
    void
    factorize(const std::vector<bool> &active, const double w);

    /// A base is factorised and was made at @p w (any w when affine).
    bool
    usable_at(const double w, const bool affine) const
    {
      return base.has_value() && (affine || base->w == w);
    }

    /// The active set of the base (a base must exist).
    const std::vector<bool> &
    active() const
    {
      return base->active;
    }

    /**
     * The update from the base to @p active: the changed pairs, their
     * influence columns and the capacitance matrix. False (no update) if
     * the changed pairs without a column exceed @p limit times the number
     * of pairs, the cached columns or the changed pairs exceed twice that,
     * or the capacitance matrix is singular.
     */
    bool
    prepare_update(const std::vector<bool> &active, const double limit);

    /// The current update (empty: K_A = K_base).
    const LowRankUpdate &
    update() const
    {
      return woodbury;
    }

    /// The cached influence columns, by pair (empty if not computed).
    const std::vector<std::vector<double>> &
    columns() const
    {
      return column;
    }

    /// Influence columns of the pairs @p missing (block back-substitutions).
    void
    compute_columns(const std::vector<unsigned int> &missing);

    /// Forget the influence columns and the update.
    void
    clear_update();

    /// Free the factorisation, its columns and update.
    void
    release();

    /// release(), and the matrix storage too: no factorisation follows.
    void
    finish();

    /// x = K_base^-1 b, timed as a load-case back-substitution.
    void
    solve(dealii::PETScWrappers::MPI::Vector &x, const dealii::PETScWrappers::MPI::Vector &b);

    /// The sparse direct solver holding the factorisation.
    DirectSolver &
    linear_solver()
    {
      return solver;
    }

    /// The sparse direct solver holding the factorisation.
    const DirectSolver &
    linear_solver() const
    {
      return solver;
    }

    /// Influence columns computed since initialize().
    unsigned int
    n_influence_columns() const
    {
      return influence_columns;
    }

    /// Wall time since initialize().
    const ContactTiming &
    timing() const
    {
      return times;
    }

  private:
    /// K + sum_A eps B B^T (- w M_perp) into system_matrix.
    void
    assemble(const std::vector<bool> &active, const double w);

    /// The influence columns of the pairs @p missing[start, start + m).
    void
    compute_block(const std::vector<unsigned int> &missing, const unsigned int start,
                  const unsigned int m);

    /// The active set and the speed a factorisation was made for.
    struct Base
    {
      std::vector<bool> active;
      double            w;
    };

    const dealii::PETScWrappers::MPI::SparseMatrix *K           = nullptr;
    const dealii::PETScWrappers::MPI::SparseMatrix *M_perp      = nullptr;
    const dealii::AffineConstraints<double>        *constraints = nullptr;
    const ContactPairs                             *pairs       = nullptr;
    const PairOperators                            *ops         = nullptr;
    MPI_Comm                                        comm        = MPI_COMM_SELF;

    dealii::PETScWrappers::MPI::SparseMatrix system_matrix;
    DirectSolver                             solver;
    std::optional<Base>                      base; ///< none: no factorisation to update
    std::vector<std::vector<double>>         column; ///< F(:,p), empty if not computed
    unsigned int                             n_cached = 0;
    LowRankUpdate woodbury; ///< D, S (+eps added, -eps removed), capacitance
    unsigned int  influence_columns = 0;
    ContactTiming times;
  };
} // namespace rotorfit
