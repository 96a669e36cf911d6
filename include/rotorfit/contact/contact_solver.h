#pragma once

#include <rotorfit/contact/active_set.h>
#include <rotorfit/contact/base_factorization.h>
#include <rotorfit/contact/contact_pairs.h>
#include <rotorfit/contact/contact_parameters.h>
#include <rotorfit/contact/contact_state.h>
#include <rotorfit/contact/exact_path.h>
#include <rotorfit/contact/pair_operators.h>
#include <rotorfit/contact/sampled_law.h>
#include <rotorfit/linear_algebra/direct_solver.h>

#include <deal.II/base/index_set.h>
#include <deal.II/base/parameter_handler.h>

#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/petsc_vector.h>
#include <deal.II/lac/vector.h>

#include <memory>
#include <vector>

namespace rotorfit
{
  /**
   * Node-to-node frictionless contact of the static solve (doc/theory.md 7; the affine law 2.3, 2.4; the updates 7.7):
   * penalty or augmented Lagrangian (Uzawa), active-set iteration with an
   * iteration cap and a cycling guard.
   *
   * For a fixed active set and spin softening off the problem is linear in
   * the load, and the load is interference + Omega^2 * (unit centrifugal
   * load). Each active set is therefore solved once for the two load cases,
   * u = u_I + w u_C, N = N_I + w N_C with w = Omega^2, on one factorisation:
   * every speed with the same active set costs nothing, and the speed at
   * which each pair opens (N_i = 0) follows without further solves.
   * With spin softening on the matrix depends on w: every speed gets its own
   * factorisation, and the decomposition is the tangent at that speed (the
   * solution and its derivative in w), so openings between speeds are still
   * predicted, to first order in the step.
   *
   * A new active set differs from the factorised one (the base) by a few
   * penalty springs: K_A = K_base + B_D S B_D^T over the changed pairs D.
   * It is solved on the base factorisation with the Woodbury identity in
   * pair space: the influence columns F(:,p) = B^T K_base^-1 b_p of the
   * changed pairs (block back-substitutions, cached per base) and a dense
   * capacitance matrix S^-1 + F_DD. The matrix is factorised again when the
   * changed pairs without a column exceed "Low-rank update limit" times the
   * number of pairs (or the cached columns or the changed pairs exceed twice
   * that), when the capacitance matrix is singular, or when the update fails
   * its residual check.
   *
   * The conductor of the contact room: ActiveSetIteration settles a speed,
   * SampledLaw or (exact path) ExactPath with its PairSpaceLaw makes the
   * law of each active set, BaseFactorization holds the factorisation, its
   * influence columns and the low-rank update (LowRankUpdate).
   *
   * Parameters: subsection "Contact" (ContactParameters).
   */
  class ContactSolver
  {
  public:
    using Method        = ContactParameters::Method;
    using Path          = ContactParameters::Path;
    using Event         = ContactEvent;
    using Decomposition = ContactDecomposition;
    using State         = ContactState;
    using Timing        = ContactTiming;

    /// Declare subsection "Contact" (ContactParameters).
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Read subsection "Contact" and the linear solver's entries.
    void
    parse_parameters(dealii::ParameterHandler &prm);

    /// The static system the contact acts on (kept referenced).
    struct StaticSystem
    {
      const ContactPairs                             &pairs;
      const dealii::AffineConstraints<double>        &constraints; ///< the static supports
      /// K with the supports, its pattern with the pair couplings
      const dealii::PETScWrappers::MPI::SparseMatrix &stiffness;
      const dealii::PETScWrappers::MPI::Vector &unit_centrifugal_load; ///< F_c per unit Omega^2
      /// M_perp, or nullptr without spin softening
      const dealii::PETScWrappers::MPI::SparseMatrix *spin_softening_matrix;
      /// replicated diagonal of the unconstrained K (sets the penalties)
      const dealii::Vector<double> &stiffness_diagonal;
      const dealii::IndexSet       &owned;
      MPI_Comm                      comm;
    };

    /// @p w_max: the largest Omega^2 of the run (scales the Uzawa
    /// tolerance of the centrifugal load case).
    void
    initialize(const StaticSystem &system, const double w_max);

    /// Contact state at w = Omega^2 [rad^2/s^2], continuing from the last one.
    State
    solve(const double w);

    /// Decomposition behind the last solve() (for opening-speed predictions).
    const Decomposition &
    decomposition() const
    {
      return current;
    }

    /**
     * The same law, shared: one object for every speed on it until a new
     * law is made, so that its identity is the pointer (a keeper of the law
     * needs no serial number) and speeds on one law share its storage.
     */
    std::shared_ptr<const Decomposition>
    law() const;

    /// Displacement at w of decomposition @p d, ghosted (all DoFs).
    void
    displacement(const Decomposition &d, const double w, dealii::PETScWrappers::MPI::Vector &u) const;

    /// Enforcement of the contact constraints.
    Method
    method() const
    {
      return settings.method;
    }

    /// The path in use (exact needs spin softening off).
    Path
    path() const
    {
      return exact_path() ? Path::exact : Path::sampled;
    }

    /// Largest constraint error max |g| / delta of the closed pairs that
    /// still counts as converged [-]: 10 x Uzawa tolerance (augmented
    /// Lagrangian), Constraint error limit (penalty).
    double
    constraint_error_limit() const
    {
      return settings.constraint_error_limit();
    }

    /// Penalty scale alpha [-].
    double
    penalty_scale() const
    {
      return settings.penalty_scale;
    }

    /// Penalty of pair @p i [N/m] (Penalty scale times its radial stiffness).
    double
    penalty(const unsigned int i) const
    {
      return operators.penalty(i);
    }

    /// The sparse direct solver of the static system.
    DirectSolver &
    linear_solver()
    {
      return base.linear_solver();
    }

    /// Factorisations so far.
    unsigned int
    n_factorizations() const
    {
      return base.linear_solver().n_factorizations();
    }

    /**
     * Free the factorisation and its influence columns (the decomposition
     * stays): for a memory-hungry step between speeds. The next changed
     * active set is factorised again.
     */
    void
    release_factorization();

    /**
     * The exact path has been followed through every speed of the run and
     * the owner keeps each speed's decomposition: free the factorisation
     * (only the path's displacements needed it). solve() refuses from here.
     */
    void
    finish_path();

    /// Active sets solved by low-rank updates of a factorisation, so far.
    unsigned int
    n_low_rank_updates() const
    {
      return sampled.n_low_rank_updates() + exact.n_low_rank_updates();
    }

    /// Wall time so far [s] in factorisations, influence columns and the
    /// back-substitutions of the load cases.
    const Timing &
    timing() const
    {
      return base.timing();
    }

    /// Influence columns computed so far (block back-substitutions).
    unsigned int
    n_influence_columns() const
    {
      return base.n_influence_columns();
    }

    /// Largest relative residual of a pair-space solve (exact path).
    double
    worst_path_residual() const
    {
      return exact.worst_residual();
    }

  private:
    /// The active-set iteration at @p w from the current set (counts and
    /// failure added to @p state).
    void
    settle(const double w, State &state);

    /// The current law becomes that of @p active at @p w.
    void
    compute_decomposition(const std::vector<bool> &active, const double w);

    /// The exact path is in use (asked for, and the law is affine).
    bool
    exact_path() const
    {
      return settings.path == Path::exact && M_perp == nullptr;
    }

    ContactParameters settings;

    const ContactPairs                             *pairs  = nullptr;
    const dealii::PETScWrappers::MPI::SparseMatrix *M_perp = nullptr;
    dealii::IndexSet                                owned, all_dofs;
    MPI_Comm                                        comm = MPI_COMM_SELF;

    PairOperators      operators;
    BaseFactorization  base;
    SampledLaw         sampled;
    ExactPath          exact;
    ActiveSetIteration active_set;

    Decomposition current;
    unsigned int  decompositions = 0; ///< laws made so far (their serial)
    /// the copy of current that law() hands out; dropped when current changes
    mutable std::shared_ptr<const Decomposition> shared_law;
  };
} // namespace rotorfit
