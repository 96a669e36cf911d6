#pragma once

#include <rotorfit/contact/base_factorization.h>
#include <rotorfit/contact/contact_pairs.h>
#include <rotorfit/contact/contact_parameters.h>
#include <rotorfit/contact/contact_state.h>
#include <rotorfit/contact/pair_operators.h>

#include <deal.II/base/index_set.h>

#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/petsc_vector.h>

#include <vector>

namespace rotorfit
{
  /**
   * The law of one active set from sparse solves (the sampled path,
   * doc/theory.md 7): one penalty solve or the Uzawa iteration of the
   * augmented Lagrangian per load case, on the base factorisation with a
   * low-rank update where that is cheaper than a new factorisation, and a
   * factorisation when the update fails its residual check. Spin softening
   * off: the interference and the unit-centrifugal load cases (affine in
   * w = Omega^2). On: the tangent at w (the solution and its derivative).
   */
  class SampledLaw
  {
  public:
    /// What the law acts on (kept referenced).
    struct System
    {
      const ContactParameters                        &parameters;
      const ContactPairs                             &pairs;
      const PairOperators                            &operators;
      const dealii::AffineConstraints<double>        &constraints;
      const dealii::PETScWrappers::MPI::Vector       &unit_centrifugal_load; ///< F_c
      const dealii::PETScWrappers::MPI::SparseMatrix *spin_softening_matrix; ///< or nullptr
      const dealii::IndexSet                         &owned;
      MPI_Comm                                        comm;
      double w_max; ///< the largest Omega^2 of the run (scales the Uzawa tolerance)
    };

    /// @p base: the factorisation it solves on and updates.
    void
    initialize(const System &system, BaseFactorization &base);

    /// The law of @p active at @p w, continuing from the multipliers of
    /// @p previous (augmented Lagrangian).
    ContactDecomposition
    decompose(const std::vector<bool> &active, const double w,
              const ContactDecomposition &previous);

    /// Start counting the Uzawa iterations (of one speed).
    void
    reset_uzawa_count()
    {
      uzawa_count = 0;
    }

    /// Uzawa iterations since reset_uzawa_count().
    unsigned int
    n_uzawa_iterations() const
    {
      return uzawa_count;
    }

    /// Active sets solved by low-rank updates since initialize().
    unsigned int
    n_low_rank_updates() const
    {
      return low_rank_updates;
    }

  private:
    /// A load case: @p factor times @p load (none: nullptr), with the
    /// interference of the pairs or without; the constraint error is
    /// measured times @p gap_scale (w_max for the unit centrifugal case).
    struct LoadCase
    {
      const dealii::PETScWrappers::MPI::Vector *load;
      double                                    factor;
      bool                                      with_interference;
      double                                    gap_scale;

      /// The interference of the closed pairs alone.
      static LoadCase
      interference()
      {
        return {nullptr, 0., true, 1.};
      }
      /// @p load per unit Omega^2, no interference; errors scaled by @p w_max.
      static LoadCase
      per_unit_w(const dealii::PETScWrappers::MPI::Vector &load, const double w_max)
      {
        return {&load, 1., false, w_max};
      }
      /// Interference and @p w times @p load (one speed, spin softening).
      static LoadCase
      at_speed(const dealii::PETScWrappers::MPI::Vector &load, const double w)
      {
        return {&load, w, true, 1.};
      }
    };

    /// An empty law of @p active at @p w with the multipliers of @p previous.
    ContactDecomposition
    start_from(const ContactDecomposition &previous, const std::vector<bool> &active,
               const double w) const;

    /// The two load cases of an affine law.
    void
    solve_affine(ContactDecomposition &next);

    /// The tangent at @p w: X(w) and X'(w), stored as X_I + w' X_C.
    void
    solve_tangent(ContactDecomposition &next, const double w);

    /// Uzawa (or one penalty solve) for one load case; returns iterations.
    unsigned int
    solve_load_case(const LoadCase                     &load,
                    const std::vector<bool>            &active,
                    std::vector<double>                &force,
                    std::vector<double>                &gap,
                    dealii::PETScWrappers::MPI::Vector &u);

    /// u = K_base^-1 (rhs - B_D c) after a low-rank update, and the
    /// residual of that update against K_A (kept as update_residual).
    void
    check_update(const std::vector<double>          &c,
                 const std::vector<bool>            &active,
                 const std::vector<double>          &force,
                 dealii::PETScWrappers::MPI::Vector &rhs,
                 dealii::PETScWrappers::MPI::Vector &u);

    const ContactParameters                        *parameters  = nullptr;
    const ContactPairs                             *pairs       = nullptr;
    const PairOperators                            *ops         = nullptr;
    const dealii::AffineConstraints<double>        *constraints = nullptr;
    const dealii::PETScWrappers::MPI::Vector       *F_c         = nullptr;
    const dealii::PETScWrappers::MPI::SparseMatrix *M_perp      = nullptr;
    BaseFactorization                              *base        = nullptr;
    dealii::IndexSet                                owned;
    MPI_Comm                                        comm  = MPI_COMM_SELF;
    double                                          w_max = 0;

    unsigned int uzawa_count      = 0;
    unsigned int low_rank_updates = 0;
    bool         uzawa_capped     = false; ///< in the law being built
    double       update_residual  = 0;     ///< of the law being built
  };
} // namespace rotorfit
