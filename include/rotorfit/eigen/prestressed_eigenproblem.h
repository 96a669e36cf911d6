#pragma once

#include <rotorfit/mesh/revolution_check.h>

#include <rotorfit/base/log.h>
#include <rotorfit/bearing/bearings.h>
#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/eigen/eigen_solution.h>
#include <rotorfit/eigen/full_solve.h>
#include <rotorfit/eigen/mode_classifier.h>
#include <rotorfit/eigen/reduced_basis.h>
#include <rotorfit/eigen/reduced_estimates.h>
#include <rotorfit/eigen/reduced_model.h>
#include <rotorfit/eigen/reduced_solve.h>
#include <rotorfit/eigen/speed_eigenproblem.h>
#include <rotorfit/eigen/speed_tangent.h>
#include <rotorfit/eigen/stress_self_check.h>
#include <rotorfit/eigen/tie_update.h>
#include <rotorfit/eigen/undamped_anchor.h>
#include <rotorfit/model/discretization.h>
#include <rotorfit/base/summary.h>
#include <rotorfit/statics/static_state.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/timer.h>

#include <deal.II/lac/petsc_sparse_matrix.h>

#include <functional>
#include <string>
#include <tuple>
#include <vector>

namespace rotorfit
{
  /**
   * The pre-stressed damped eigenproblem at one speed (doc/theory.md,
   * sections 3 to 5, 7.4 and 8), on top of a static state:
   *
   *   M q'' + (C_b + Omega G) q' + (K + K_sigma - Omega^2 K_theta + K_c + K_b) q = 0
   *
   * in the stationary frame, with the contact of the eigenproblem chosen per
   * run (bonded, frictionless, fixed, frozen) and the stress stiffening from
   * the static displacement. Eigenvalues of rigid-body motions, of loose
   * bodies and overdamped ones are set apart; a speed whose modes do not all
   * converge is solved once more with a larger Krylov space, then the run
   * stops (SolverFailure).
   *
   * The conductor of the eigen room: the speed's operators (SpeedTangent),
   * the reduced model (ReducedModel, ReducedSolve, ReducedEstimates), its
   * anchors (UndampedAnchor, TieUpdate) and the full solve (FullSolve) are
   * classes of their own; this one decides which of them serves a speed.
   *
   * Parameters: subsections "Eigenproblem" (model and solver entries),
   * "Bearings" and "Bearing <name>".
   */
  class PrestressedEigenproblem : public SpeedEigenproblem
  {
  public:
    using ContactModel     = SpeedTangent::ContactModel;
    using StressStiffening = SpeedTangent::StressStiffening;

    PrestressedEigenproblem(const Discretization &model, Log &log, dealii::TimerOutput &timer);
    /// (its parts hold references to each other)
    PrestressedEigenproblem(const PrestressedEigenproblem &) = delete;
    PrestressedEigenproblem &
    operator=(const PrestressedEigenproblem &) = delete;

    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// @p spin_softening: the static problem's (refused with
    /// interference-only stress stiffening).
    void
    parse_parameters(dealii::ParameterHandler &prm,
                     const std::string        &prm_directory,
                     const bool                spin_softening);

    bool
    enabled() const
    {
      return compute;
    }

    unsigned int
    n_modes() const
    {
      return n_wanted;
    }

    const Bearings &
    bearing_list() const
    {
      return bearings;
    }

    /// Vectors of length 2 n the eigensolver may hold at once (Krylov space
    /// of a retry and the eigenvectors), for the memory estimate.
    double
    state_vectors_needed(const double n_dofs) const
    {
      // the reduced model: its basis and A V of five matrices (n-vectors,
      // half a state vector each)
      const ReducedBasis &v     = reduced.basis();
      const double        basis = v.enabled() ? 4. * v.capacity(max_nev + 2 * v.margin()) : 0.;
      return std::min<double>(2 * n_dofs, eigensolver.krylov_size(max_nev, 2)) + max_nev + 1 +
             basis;
    }

    /// Bearing faces, sparsity; refuses more modes than the model has.
    void
    setup();

    /// M, K, G, K_theta (and the bearings of a speed-independent set).
    void
    assemble_speed_independent_matrices();

    /// The modes at the speed of @p state.
    EigenSolution
    solve(const StaticState &state) override;

    /// A root-solve trial (doc/theory.md 9.5, 9.7): the modes of @p state on the
    /// reduced model alone, without the full-space checks, where the
    /// speed's own solve left a basis of its tied set (false otherwise:
    /// nothing solved). Only to locate a root; what is reported there comes
    /// from solve().
    bool
    solve_trial(const StaticState &state, EigenSolution &solution) override;

    /// The matrices of the last solve() (valid until the next solve) and
    /// the factorisation of Q(sigma) = K_t + sigma C + sigma^2 M of the
    /// latest full solve (the speed's own unless it was solved on the
    /// reduced model: then an approximate inverse, good for building bases).
    struct SpeedOperators
    {
      const dealii::PETScWrappers::MPI::SparseMatrix &mass, &damping, &stiffness;
      const DirectSolver                             &shifted_inverse;
      double                                          rpm;
      /// The reduced model this speed was solved on, V^T M V, V^T C V and
      /// V^T K_t V at this speed, and the products below; null after a full
      /// solve.
      const ReducedBasis               *basis = nullptr;
      const dealii::FullMatrix<double> *Mr = nullptr, *Cr = nullptr, *Kr = nullptr;
      /// M V y, C V y, K_t V y from the products kept with the projections
      /// (rounded as the projections were)
      std::function<void(const std::vector<std::complex<double>> &y,
                         ComplexVector                           &Mu,
                         ComplexVector                           &Cu,
                         ComplexVector                           &Ku)>
        products;
      /// (A V)^T X (m x k, column-major) for the columns X = [x_1 .. x_k]
      /// from the same products, for A = M, C_b, G, K_t (at w_tangent),
      /// K_t2: C = C_b + Omega G, K_t = K_t(w_tangent) + (w - w_tangent) K_t2
      std::function<void(const std::vector<const dealii::Vector<double> *> &x,
                         std::array<std::vector<double>, 5>                &parts)>
        row_parts;
      double w_tangent = 0;
      /// Where the speeds of one contact segment differ only by their affine
      /// share (D = D_s + (Omega - Omega_s) G, K_t = K_s + (w - w_s) K_t2,
      /// w = Omega^2): the segment's number (0: not so) and G X, K_t2 X
      unsigned int segment = 0;
      std::function<void(const std::vector<const dealii::Vector<double> *> &x,
                         std::vector<dealii::Vector<double>>               &gx,
                         std::vector<dealii::Vector<double>>               &k2x)>
        speed_share;
    };
    SpeedOperators
    operators();

    /// Log the totals, add the eigen entries to @p summary.
    void
    finish(Summary &summary) const;

  private:
    /// What every solve of a speed starts with: the solution's speed and
    /// tied pairs, the tangent; returns the eigenvalues to ask for.
    unsigned int
    begin_speed(const StaticState &state, EigenSolution &solution, std::vector<bool> &loose_body);
    /// The speed on the reduced model: on the basis so far, else on a new
    /// undamped anchor; false where it needs the damped full solve
    /// (@p margin_pays: its anchor is to take the margin modes).
    bool
    solve_on_basis(const StaticState       &state,
                   const std::vector<bool> &loose_body,
                   const unsigned int       nev,
                   EigenSolution           &solution,
                   bool                    &margin_pays);
    /// A new undamped anchor for the speed (on a tie update of the last
    /// LDL^T where few ties changed, else on a new one) and the speed on it.
    bool
    solve_on_undamped_anchor(const StaticState       &state,
                             const std::vector<bool> &loose_body,
                             const unsigned int       nev,
                             const bool               lasting,
                             EigenSolution           &solution,
                             std::string             &why);
    /// UndampedAnchor::make(), then the speed on the basis with every check
    /// of a reduced solve.
    bool
    anchor_and_solve(const StaticState       &state,
                     const std::vector<bool> &loose_body,
                     const unsigned int       nev,
                     const bool               lasting,
                     EigenSolution           &solution,
                     std::string             &why,
                     const bool               on_update);
    /// A speed served by the reduced model (of the basis so far, or of an
    /// undamped anchor made for it), counted in @p counter.
    void
    served(const StaticState       &state,
           const std::vector<bool> &loose_body,
           EigenSolution           &solution,
           unsigned int            &counter);
    /// What every solved speed ends with.
    void
    end_speed(const StaticState &state, const std::vector<bool> &loose_body, EigenSolution &solution);
    /// Once per run: the Shift above the lowest elastic frequency found.
    void
    warn_far_shift(const EigenSolution &solution, const double rpm);

    /// Once, at the first speed above 0: the bodies that are not of revolution.
    void
    warn_not_of_revolution(const double rpm);

    const Discretization &model;
    Log                  &log;
    dealii::TimerOutput  &timer;

    // parameters
    bool         compute    = true;
    unsigned int n_wanted   = 12;
    bool         self_check = false;

    Bearings          bearings;
    DampedEigensolver eigensolver;
    SpeedTangent      tangent;
    ModeClassifier    classifier;
    StressSelfCheck   self_checks;
    TieUpdate         ties;
    ReducedModel      reduced;
    ReducedEstimates  estimates;
    UndampedAnchor    anchor;
    ReducedSolve      reduced_solve;
    FullSolve         full;

    /// the tied pairs the basis was built for (a change starts a new basis)
    std::vector<bool> basis_tied;
    /// the latest speed was solved on the reduced model
    bool speed_reduced = false;

    unsigned int speeds_done = 0;
    double       last_rpm    = 0;
    unsigned int max_nev     = 0; ///< eigenvalues asked at the most tied state
    double       worst_backward_error = 0;
    bool         shift_warned         = false;
    /// Per body: the share of its surface facing the circumferential
    /// direction (RevolutionCheck); the warning at the first speed above 0
    /// when a body is not one of revolution.
    std::vector<double> circumferential_share;
    /// per body: centroid and second moments about the axis
    std::vector<RevolutionCheck::Inertia> inertia;
    bool                revolution_warned = false;
    unsigned int reduced_solves = 0, reduced_refusals = 0, reduced_trials = 0;
    /// speeds served by an undamped anchor, and those whose undamped anchor
    /// failed the checks (then solved in full)
    unsigned int undamped_served = 0, undamped_refused = 0;
  };
} // namespace rotorfit
