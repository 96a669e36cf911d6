#pragma once

#include <rotorfit/contact/contact_pairs.h>
#include <rotorfit/contact/low_rank_update.h>
#include <rotorfit/linear_algebra/direct_solver.h>

#include <deal.II/base/index_set.h>
#include <deal.II/base/parameter_handler.h>

#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/petsc_vector.h>
#include <deal.II/lac/vector.h>

#include <set>
#include <string>
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
   * Parameters: subsection "Contact".
   */
  class ContactSolver
  {
  public:
    enum class Method
    {
      penalty,
      augmented_lagrangian
    };

    /// How the active set follows the speed: from event to event in
    /// Omega^2 (exact), or settled anew at each requested speed (sampled).
    enum class Path
    {
      exact,
      sampled
    };

    /// A pair that changed state on the exact path.
    struct Event
    {
      double       w;       ///< Omega^2 at the change [rad^2/s^2]
      unsigned int pair;    ///< index into ContactPairs::pairs()
      bool         opening; ///< true: closed -> open; false: open -> closed
    };

    /**
     * Solution of one active set: X(w) = X_I + w X_C. Affine (spin softening
     * off): the interference and unit-centrifugal load cases, exact for all
     * w. Otherwise the tangent at w_fixed: exact there, first order around.
     */
    struct Decomposition
    {
      std::vector<bool>   active;
      std::vector<double> force_I, force_C; ///< N = force_I + w force_C [N]
      std::vector<double> gap_I, gap_C;     ///< g = gap_I + w gap_C [m]
      std::vector<double> pressure_I, pressure_C; ///< p = M_surface^-1 N [Pa]
      /// exact path: the pair loads of the two load cases on the base,
      /// u = K_base^-1 (F + B q) (empty on the sampled path)
      std::vector<double> q_I, q_C;
      dealii::PETScWrappers::MPI::Vector u_I, u_C; ///< locally owned
      bool   affine  = true; ///< false: a tangent at w_fixed
      double w_fixed = 0;
      bool   valid   = false;
      bool   uzawa_converged = true; ///< false: a load case hit the Uzawa cap
      unsigned int serial = 0; ///< changes with every new decomposition
    };

    /// Result at one speed.
    struct State
    {
      std::vector<bool>   active;
      std::vector<double> force; ///< N_i >= 0 on closed pairs [N]
      std::vector<double> gap;   ///< g_i [m]
      std::vector<double> pressure; ///< p_i [Pa], from the surface mass matrix
      unsigned int        active_set_iterations = 0;
      unsigned int        uzawa_iterations      = 0;
      unsigned int        factorizations        = 0;
      unsigned int        low_rank_updates      = 0; ///< active sets solved by Woodbury
      unsigned int        influence_columns     = 0; ///< columns computed
      unsigned int        flipped_back          = 0; ///< pairs that flipped back (cycling)
      bool                converged             = true;
      std::string         reason; ///< why not converged (empty if it is)
      /// largest ContactPairs::asymmetry() over the interfaces (set by the sweep)
      double              asymmetry = 0;
      /// exact path: the changes since the previous speed, in order of w
      std::vector<Event>  events;
    };

    static void
    declare_parameters(dealii::ParameterHandler &prm);

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

    /// Displacement at w of decomposition @p d, ghosted (all DoFs).
    void
    displacement(const Decomposition &d, const double w, dealii::PETScWrappers::MPI::Vector &u) const;

    Method
    method() const
    {
      return contact_method;
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
      return contact_method == Method::penalty ? penalty_error_limit : 10 * uzawa_tolerance;
    }

    double
    penalty_scale() const
    {
      return alpha;
    }

    /// Penalty of pair @p i [N/m] (Penalty scale times its radial stiffness).
    double
    penalty(const unsigned int i) const
    {
      return epsilon[i];
    }

    DirectSolver &
    linear_solver()
    {
      return solver;
    }

    unsigned int
    n_factorizations() const
    {
      return solver.n_factorizations();
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
      return low_rank_updates;
    }

    /// Wall time so far [s] in factorisations, influence columns and the
    /// back-substitutions of the load cases.
    struct Timing
    {
      double factorize = 0, columns = 0, solves = 0;
    };

    const Timing &
    timing() const
    {
      return times;
    }

    /// Influence columns computed so far (block back-substitutions).
    unsigned int
    n_influence_columns() const
    {
      return influence_columns;
    }

    /// Largest relative residual of a pair-space solve (exact path).
    double
    worst_path_residual() const
    {
      return worst_pair_residual;
    }

  private:
    /// The active-set iteration at @p w from the current set (counts and
    /// failure added to @p state).
    void
    settle(const double w, State &state);

    /// The exact path is in use (asked for, and the law is affine).
    bool
    exact_path() const
    {
      return requested_path == Path::exact && M_perp == nullptr;
    }

    // the exact path (contact_path.cc; doc/theory.md 7.8)
    /// Factorise the base (every pair closed), all influence columns and
    /// t_C = B^T K_base^-1 F_c: the pair-space problem of every active set.
    void
    start_path();
    /// Follow the events from the last speed up to (not including) @p w.
    void
    advance_path(const double w, State &state);
    /// Smallest w' > @p w where pair @p i leaves its state under the
    /// current law (infinity: never).
    double
    event_w(const unsigned int i, const double w) const;
    /// The law of @p active in pair space (no sparse solve).
    void
    pair_space_decomposition(const std::vector<bool> &active);
    /// Row @p i of the pair-space matrix for @p closed, and its two
    /// right-hand sides (interference, unit centrifugal load).
    void
    pair_space_row(const unsigned int i, const bool closed, std::vector<double> &row,
                   double &rhs_I, double &rhs_C) const;
    /// The two right-hand sides of that row alone.
    void
    pair_space_rhs(const unsigned int i, const bool closed, double &rhs_I, double &rhs_C) const;
    /// Invert the pair-space matrix of @p active into path_inverse.
    void
    invert_pair_space(const std::vector<bool> &active);
    /// u_I, u_C of the current decomposition (two back-substitutions).
    void
    ensure_displacements();

    /// Forces, gaps and pressures of the current decomposition at @p w.
    void
    evaluate(const double w, State &state) const;

    /// The pairs closed according to @p state (opening and closing rules).
    std::vector<bool>
    next_active_set(const std::vector<bool> &active, const State &state) const;

    /// The set to try after @p active when @p next is wanted: @p next without
    /// the pairs that flipped back (@p flips), or one pair at a time; false
    /// when every way on leads to a set in @p seen.
    bool
    guard_cycling(const std::vector<bool>           &active,
                  const std::vector<bool>           &next,
                  const State                       &state,
                  const std::vector<unsigned int>   &flips,
                  const std::set<std::vector<bool>> &seen,
                  std::vector<bool>                 &proposal) const;

    void
    compute_decomposition(const std::vector<bool> &active, const double w);

    /// Factorise K_A for @p active (at w when not affine): the new base.
    void
    factorize_base(const std::vector<bool> &active, const double w);

    /// Forget the influence columns and the update (the base changed or went).
    void
    clear_update();

    /// Changed pairs against the base, their springs and the capacitance
    /// matrix; false if the update is not worth it (too many new columns).
    bool
    prepare_update(const std::vector<bool> &active);

    /// Influence columns of the changed pairs that are not cached yet.
    void
    compute_columns(const std::vector<unsigned int> &missing);

    /// B^T x for every pair (replicated on all ranks).
    std::vector<double>
    project(const dealii::PETScWrappers::MPI::Vector &x) const;

    /// rhs += sum_i f_i b_i (locally owned rows only).
    void
    add_pair_forces(const std::vector<double>          &f,
                    dealii::PETScWrappers::MPI::Vector &rhs) const;

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

    Method       contact_method = Method::augmented_lagrangian;
    double       alpha          = 10;
    unsigned int max_active_set_iterations = 30;
    unsigned int max_uzawa_iterations      = 100;
    double       uzawa_tolerance           = 1e-8;
    double       update_limit              = 0.25;
    double       penalty_error_limit       = 0.01;
    Path         requested_path            = Path::exact;
    bool         uzawa_capped              = false; ///< in the decomposition being built

    const ContactPairs                             *pairs       = nullptr;
    const dealii::AffineConstraints<double>        *constraints = nullptr;
    const dealii::PETScWrappers::MPI::SparseMatrix *K           = nullptr;
    const dealii::PETScWrappers::MPI::Vector       *F_c         = nullptr;
    const dealii::PETScWrappers::MPI::SparseMatrix *M_perp      = nullptr;
    dealii::IndexSet                                owned, all_dofs;
    MPI_Comm                                        comm;
    double                                          w_max = 0;
    unsigned int                                    this_rank = 0;

    std::vector<double>                      epsilon;
    std::vector<bool>                        owner_adds; // pair assembled here
    /// b_i after the static constraints (b~ = C^T b): g_i = b~_i . u - delta_i
    /// on the unconstrained DoFs; identical on every rank
    std::vector<std::vector<std::pair<dealii::types::global_dof_index, double>>> projection;
    dealii::types::global_dof_index first_owned = 0, end_owned = 0;

    // base factorisation and its low-rank update to the current active set
    std::vector<bool>                base_active;
    double                           base_w     = 0;
    bool                             base_valid = false;
    std::vector<std::vector<double>> column; ///< F(:,p), empty if not computed
    unsigned int                     n_cached = 0;
    LowRankUpdate                    woodbury;  ///< D, S (+eps added, -eps removed), capacitance
    unsigned int                     low_rank_updates  = 0;
    unsigned int                     influence_columns = 0;
    double                           update_residual   = 0;
    Timing                           times;
    dealii::PETScWrappers::MPI::SparseMatrix system_matrix;
    DirectSolver                             solver;
    Decomposition                            current;
    unsigned int                             uzawa_count = 0;
    unsigned int                             decompositions = 0;

    // exact path: F = B^T K_base^-1 B (row-major, n x n), t_C = B^T K_base^-1
    // F_c, the base springs e (eps on the base's closed pairs), the inverse
    // of the pair-space matrix of path_active (Sherman-Morrison updates)
    bool                path_started  = false;
    bool                path_finished = false; ///< finish_path() was called
    double              path_w       = 0;
    std::vector<double> flexibility, t_C, base_spring, path_inverse;
    std::vector<bool>   path_active;
    unsigned int        u_serial = 0;
    double              worst_pair_residual = 0;
  };
} // namespace rotorfit
