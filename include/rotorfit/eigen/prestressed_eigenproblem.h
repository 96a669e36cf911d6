#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/bearing/bearings.h>
#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/eigen/eigen_solution.h>
#include <rotorfit/eigen/reduced_basis.h>
#include <rotorfit/eigen/rotor_matrices.h>
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
   * Parameters: subsections "Eigenproblem" (model and solver entries),
   * "Bearings" and "Bearing <name>".
   */
  class PrestressedEigenproblem
  {
  public:
    enum class ContactModel
    {
      bonded,
      frictionless,
      fixed,
      frozen
    };
    enum class StressStiffening
    {
      off,
      interference,
      full
    };

    PrestressedEigenproblem(const Discretization &model, Log &log, dealii::TimerOutput &timer);

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
      const double basis =
        reduced.enabled() ? 4. * reduced.capacity(max_nev + 2 * reduced.margin()) : 0.;
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
    solve(const StaticState &state);

    /// A root-solve trial (doc/theory.md 9.5, 9.7): the modes of @p state on the
    /// reduced model alone, without the full-space checks, where the
    /// speed's own solve left a basis of its tied set (false otherwise:
    /// nothing solved). Only to locate a root; what is reported there comes
    /// from solve().
    bool
    solve_trial(const StaticState &state, EigenSolution &solution);

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
    /// Once per run: the Shift above the lowest elastic frequency found.
    void
    warn_far_shift(const EigenSolution &solution, const double rpm);
    /// What every solve of a speed starts with: the solution's speed and
    /// tied pairs, the tangent; returns the eigenvalues to ask for.
    unsigned int
    begin_speed(const StaticState &state, EigenSolution &solution, std::vector<bool> &loose_body);
    void
    assemble_tangent(const StaticState &state, const std::vector<bool> &tied);
    /// matrices.stiffness = K + K_sigma(u_I) of @p state's static state,
    /// and k_sigma_C = K_sigma(u_C) (doc/theory.md 7.8)
    void
    update_stiffness(const StaticState &state);
    /// the self-check's fields on the support points: tilt e_x x x, twist
    /// e_z x x, and y in the x component
    std::vector<dealii::Vector<double>>
    check_fields() const;
    void
    add_contact_ties(const StaticState &state, const std::vector<bool> &tied);
    std::vector<bool>
    tied_pairs(const StaticState &state);
    /// Zero eigenvalues the supports leave (rigid and loose-body motions).
    unsigned int
    expected_zero_modes(const std::vector<bool> &tied,
                        std::vector<bool>       &loose_body) const;
    /// Split eigenpairs into elastic and rigid; false if incomplete.
    bool
    sort_eigenpairs(std::vector<EigenPair>        &pairs,
                    const std::vector<bool>       &loose_body,
                    EigenSolution                 &solution,
                    unsigned int                  &unconverged,
                    double                        &worst) const;
    void
    log_speed(const EigenSolution &solution, const DampedEigensolver::Statistics &stats,
              const double worst) const;
    /// Reduced model (prestressed_reduced.cc; its checks reduced_estimates.cc): the modes of @p state from
    /// the basis, checked on the full matrices; false (and @p why) if they
    /// do not pass and the speed needs the full solve.
    bool
    solve_reduced(const StaticState       &state,
                  const std::vector<bool> &loose_body,
                  const unsigned int       nev,
                  EigenSolution           &solution,
                  std::string             &why,
                  const bool               checked = true);
    /// The projections of the matrices of this speed, cached per basis,
    /// active set and (speed-dependent) bearing coefficients.
    void
    update_projections(const StaticState &state);
    /// V y_c and M V y_c, C V y_c, K_t V y_c at @p omega, @p w = omega^2
    /// from the products A V kept with the projections (one dgemm per
    /// matrix for all columns); for @p transpose C_b - omega G and K_t,
    /// which are C^T and K_t^T where the bearings are symmetric.
    struct Expanded
    {
      std::vector<ComplexVector> v, m, c, k;
      /// how far the kept products of the sum of all columns are from the
      /// sparse ones (BackwardError::mismatch): one combination checks all
      double
      mismatch(const BackwardError &backward_error, bool transpose) const;
    };
    Expanded
    expanded(const std::vector<std::vector<std::complex<double>>> &y,
             const double                                          omega,
             const double                                          w,
             const bool                                            transpose) const;
    /// Q(lambda_c) V y_c for each column y_c, from the kept products (one
    /// dgemm per product for all columns; no M, C, K products per mode
    /// held); Q(lambda_c)^H V y_c with @p transpose, as expanded() makes it.
    std::vector<ComplexVector>
    residuals(const std::vector<std::vector<std::complex<double>>> &y,
              const std::vector<std::complex<double>>              &lambda,
              double                                                omega,
              double                                                w,
              bool                                                  transpose) const;
    /// Estimated relative errors of reduced modes' eigenvalues, from their
    /// residuals (of the vectors V y / scale; null where the reduced solve
    /// made none: then made here if back-substituted) and the reduced
    /// damping matrix @p Cr of the speed.
    std::vector<double>
    error_estimates(const BackwardError                           &backward_error,
                    const std::vector<const EigenPair *>          &modes,
                    const std::vector<const ReducedBasis::Pair *> &dense,
                    const std::vector<double>                     &scale,
                    const std::vector<const ComplexVector *>      &residual,
                    const dealii::FullMatrix<double>              &Cr,
                    const double                                   omega,
                    const double                                   w);
    /// The Gram matrix of the residual blocks for the current basis, tangent
    /// and factorisation: made where @p due (the estimates have cost as many
    /// back-substituted columns) or the basis is a lasting anchor's. Called
    /// by a reduced solve before it expands its modes, so that the block
    /// solves and the mode vectors are not held at once.
    void
    prepare_gram(bool due);
    /// The kept products A V whose columns span every residual of a reduced
    /// speed on the current projections: M, C_b, G, K_t, K_t2, the dense ones
    /// first and those kept by their rows last (zero ones left out; the
    /// order of residual_coefficients() and of the Gram matrices).
    std::vector<const RowBlock *>
    residual_blocks() const;
    /// x with Q(lambda) V y = [A_1 V .. A_b V] x for @p blocks, those of
    /// residual_blocks() (the left residual Q(lambda)^H V y with @p transpose).
    std::vector<std::complex<double>>
    residual_coefficients(const std::vector<std::complex<double>> &y,
                          std::complex<double>                     lambda,
                          double                                   omega,
                          double                                   w,
                          bool                                     transpose,
                          const std::vector<const RowBlock *> &blocks) const;
    /// A full solve's converged eigenvectors into the basis.
    void
    add_anchor(const double rpm, const std::vector<EigenPair> &pairs, const bool lasting);
    /// Each of @p parts' first-order change with the speed, solved with the
    /// latest factorisation (Q(sigma) or S) into the basis: S^-1 G x,
    /// S^-1 K_t2 x (where stress stiffening moves with the speed) and, with
    /// @p bearing_damping, S^-1 C_b x.
    void
    add_directions(const std::vector<const dealii::Vector<double> *> &parts,
                   const bool                                         bearing_damping,
                   const bool                                         gyroscopic = true);
    /// A new anchor from the undamped modes of this speed and their
    /// directions (doc/theory.md 8.7), then the speed on the basis with
    /// every check of a reduced solve; false (and @p why) where they fail:
    /// the speed then needs the damped full solve. A @p lasting anchor
    /// (a contact state expected to hold over several speeds) also gets the
    /// directions other speeds need.
    /// With @p on_update the anchor solves on the last LDL^T of S with a
    /// low-rank update for the ties that changed since (tie_update()),
    /// without a factorisation of its own.
    bool
    anchor_undamped(const StaticState       &state,
                    const std::vector<bool> &loose_body,
                    const unsigned int       nev,
                    const bool               lasting,
                    EigenSolution           &solution,
                    std::string             &why,
                    const bool               on_update = false);
    /// Pair @p i's tie spring in the eigenproblem (doc/theory.md 7.4).
    double
    tie_spring(const StaticState &state, const unsigned int i) const
    {
      return state.pair_penalty(i) * (contact_scale / state.penalty_scale());
    }
    /// The tie springs that changed between the last LDL^T of S and the
    /// ties @p tied of @p state (+eps for a pair tied since, -eps for one
    /// released; one column per pair, three for bonded fits): false where
    /// there is no such factorisation or more than Reduced anchor tie
    /// updates changed.
    bool
    tie_update(const StaticState                       &state,
               const std::vector<bool>                 &tied,
               std::vector<DirectSolver::UpdateColumn> &columns) const;
    /// The ties of the last LDL^T of S (each pair's spring, 0 where
    /// untied), its speed and the factorisation count it was made at.
    struct FactorTies
    {
      unsigned int        factorizations = ~0u;
      double              rpm            = 0;
      std::vector<double> eps;
    } factor_ties;
    /// anchors made on a tie update, and those refused (then a new LDL^T)
    unsigned int updated_anchors = 0, updated_anchors_refused = 0;
    /// Free the products A V kept with the projections (before a
    /// factorisation: the memory peak).
    void
    free_products();
    void
    announce_loose_bodies(const StaticState &state, const std::vector<bool> &loose_body);
    /// Virial checks of K_sigma on rigid tilt and twist (doc/theory.md 10e).
    void
    matrix_checks(const StaticState &state);

    const Discretization &model;
    Log                  &log;
    dealii::TimerOutput  &timer;
    MPI_Comm              comm;

    // parameters
    bool             compute       = true;
    unsigned int     n_wanted      = 12;
    ContactModel     contact_model = ContactModel::bonded;
    double           contact_scale = 1000;
    StressStiffening stiffening    = StressStiffening::full;
    double           rigid_threshold_hz = 1;
    bool             self_check      = false;
    bool             convective_term = true;
    /// K_theta lives in k_sigma_C (K_t2 = K_sigma(u_C) - K_theta in one
    /// matrix) and matrices.convective is freed: every static state is
    /// affine (no spin softening) and stress stiffening is full
    bool             convective_folded = false;
    bool             static_spin_softening = false;
    /// the self-check's w^T K_theta w for the tilt and twist fields, made
    /// before K_theta is folded away
    double           check_theta_tilt = 0, check_theta_twist = 0;
    std::vector<std::pair<std::string, double>> checks;

    Bearings                       bearings;
    DampedEigensolver              eigensolver;
    ReducedBasis                   reduced;
    /// the tied pairs the basis was built for (a change starts a new basis)
    std::vector<bool> basis_tied;
    /// V^T X V of M, G, the tangent at w = 0 and its d/dw, bearing damping
    dealii::FullMatrix<double> p_mass, p_gyro, p_tangent0, p_tangent2, p_bearing_c;
    /// the reduced C and K_t of the latest speed, if it was solved reduced
    dealii::FullMatrix<double> speed_Cr, speed_Kr;
    bool                       speed_reduced = false;
    /// A V of the projections, the tangent's at w_tangent: a reduced
    /// speed's residuals and the response are made of them (C_b V by the
    /// bearings' rows alone)
    RowBlock            av_mass, av_gyro, av_tangent, av_tangent2, av_bearing_c;
    double              w_tangent = 0;
    /// assemblies of the tangent so far, the one av_tangent was made of, and
    /// (factorisation count, tangent) of the latest undamped anchor's S =
    /// K_t + sigma^2 M: where both name the same tangent, S^-1 K_t V = V -
    /// sigma^2 S^-1 M V spares the Gram matrix a fifth of its columns
    unsigned int tangent_serial = 0, av_tangent_serial = ~0u;
    /// what the tangent and damping matrices hold: the ties, w = Omega^2
    /// and Omega they were made for (assemble_tangent)
    struct TangentState
    {
      bool              valid = false;
      std::vector<bool> tied;
      double            w = 0, omega = 0;
    } made_for;
    std::pair<unsigned int, unsigned int> undamped_factor{~0u, ~0u};
    /// The residual blocks' Gram matrix in the S^-1 norm of the latest
    /// factorisation (replicated_inverse_gram): the error estimates of a
    /// basis that serves many speeds without a back-substitution per speed
    /// (doc/theory.md 8.6). Built for a lasting anchor's basis at once, for
    /// another once its estimates have cost as many back-substituted columns
    /// as the Gram matrix does.
    struct ResidualGram
    {
      std::vector<double>                      g;
      std::vector<const RowBlock *> blocks; ///< residual_blocks()
      /// basis version, K_sigma serial, tangent and bearing speeds,
      /// factorisations: what it was made for
      std::tuple<unsigned int, unsigned int, double, double, unsigned int> key{~0u, 0, -1, -1, 0};
      unsigned int spent   = 0;     ///< columns back-substituted for estimates on this key
      bool         refused = false; ///< disagreed with the back-substitutions
      bool         checked = false; ///< compared with them (once, at its first speed)
      double       seconds = 0;
      /// B^T B of the same blocks B: the right residuals' norms of a
      /// speed's modes without their n-long vectors (made with g, checked
      /// once against the vectors at its first speed)
      std::vector<double>                      e;
      bool e_checked = false, e_refused = false;
    } gram;
    /// An anchor's directions are made for this many modes at a time: the
    /// products, their back-substitutions and MUMPS's copies for a whole
    /// anchor (78 columns on TS's benchmark mesh) were a run's memory peak.
    static constexpr std::size_t modes_per_block = 8;
    /// How far the kept products (A V) y may stray from A (V y), relative.
    /// Rounding, amplified by the cancellation that penalty ties cause in
    /// K_t phi, reaches 6.7e-9 on the tutorial disk and 5e-10 on TS; a
    /// product kept from another speed or tied set errs by the speed's own
    /// share of the tangent or more (Omega^2 K_t2 phi: 1e-3 .. 1e-2 of
    /// K_t phi), a tangent 1e-4 off is refused.
    static constexpr double product_tolerance = 1e-6;
    /// how far a new Gram matrix's estimates may stray from the
    /// back-substituted ones: relative, or by gram_floor (its rounding
    /// floor, with a margin) where they are smaller; used where the
    /// tolerance is 10 x the floor
    static constexpr double gram_agreement = 1e-2, gram_floor = 1e-10;
    unsigned int gram_builds = 0;
    double       gram_worst_difference = 0;
    /// largest relative difference of residual norms from ResidualGram::e
    /// against the vectors' (at each such matrix's first speed)
    double gram_norms_worst_difference = 0;
    /// reduced solves whose residual norms came from ResidualGram::e alone
    unsigned int gram_norm_speeds = 0;
    /// the basis version a lasting anchor made (its Gram matrix is built at once)
    unsigned int gram_eager_version = ~0u;
    /// what the projections were made for
    struct ProjectionKey
    {
      unsigned int basis = 0, k_sigma = 0;
      double       rpm   = -1;
      bool
      operator==(const ProjectionKey &o) const
      {
        return basis == o.basis && k_sigma == o.k_sigma && rpm == o.rpm;
      }
    } key_basis{~0u, 0, -1}, key_tangent{~0u, 0, -1}, key_bearing{~0u, 0, -1};
    /// full assemblies of the tangent (a new contact segment, ties or
    /// bearing coefficients); between two, the tangent and the damping move
    /// by the speed's affine share alone
    unsigned int segment_serial = 0;
    /// The kept products' check on this speed's sparse matrices
    /// (solve_reduced): made at the first speed of each basis, projections
    /// and tangent segment, then every product_check_interval-th speed.
    /// Between, the sparse matrices and the kept products move by the same
    /// affine share of the speed, so the check would repeat the first one's
    /// rounding (a fifth of a reduced speed on TS: six sparse products).
    struct ProductCheck
    {
      ProjectionKey tangent, bearing;
      unsigned int  basis = ~0u, segment = ~0u, speeds = 0;
      double        mismatch = 0, rpm = 0;
      bool          transposed_known = false, transposed_kept = false;
      bool          due = false; ///< checked at this speed
    } product_check;
    static constexpr unsigned int product_check_interval = 10;
    unsigned int                  product_checks_skipped = 0;
    /// true where this speed's products are to be checked (and the key
    /// moved on)
    bool
    product_check_due(const double rpm);
    unsigned int full_solves = 0, reduced_solves = 0, reduced_refusals = 0, reduced_trials = 0;
    /// speeds served by an undamped anchor, and those whose undamped anchor
    /// failed the checks (then solved in full)
    unsigned int undamped_served = 0, undamped_refused = 0;
    double       reduced_worst = 0; ///< largest error estimate of a reduced solve
    double       reduced_worst_products = 0; ///< largest product mismatch of a reduced solve
    RotorMatrices                  matrices;

    /// (the factorisations take the tangent's storage: no matrix of their own)
    dealii::PETScWrappers::MPI::SparseMatrix bearing_k, bearing_c, k_sigma_C, tangent, damping;
    /// the displacement whose K_sigma matrices.stiffness holds (empty: none)
    dealii::Vector<double> stiffened_by;
    unsigned int k_sigma_serial = 0;

    std::vector<unsigned int> body_of_dof;
    std::vector<bool>         frozen_active;
    unsigned int speeds_done    = 0;
    double       last_rpm       = 0;
    unsigned int retried_speeds = 0; ///< speeds solved a second time (eigen retry)
    unsigned int max_nev        = 0; ///< eigenvalues asked at the most tied state
    double       worst_backward_error = 0;
    bool         shift_warned         = false;
    bool         announced_loose      = false;
  };
} // namespace rotorfit
