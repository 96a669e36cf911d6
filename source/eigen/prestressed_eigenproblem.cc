#include <rotorfit/base/input_error.h>
#include <rotorfit/eigen/prestressed_eigenproblem.h>
#include <rotorfit/mesh/revolution_check.h>
#include <rotorfit/statics/speed_schedule.h>

#include <algorithm>
#include <cmath>
#include <sstream>

// The conductor of the eigen room: which of the reduced model, an undamped
// anchor or the full solve serves a speed, and the totals of a run.

namespace rotorfit
{
  using namespace dealii;

  PrestressedEigenproblem::PrestressedEigenproblem(const Discretization &model,
                                                   Log                  &log,
                                                   TimerOutput          &timer)
    : model(model)
    , log(log)
    , timer(timer)
    , tangent(model, bearings, timer)
    , classifier(model, bearings, tangent.settings, eigensolver, log)
    , self_checks(model, log)
    , ties(model, bearings, tangent)
    , reduced(tangent, bearings)
    , estimates(reduced, tangent, eigensolver, bearings, log)
    , anchor(model, reduced, estimates, ties, tangent, eigensolver, bearings, log, timer)
    , reduced_solve(reduced, estimates, tangent, eigensolver, classifier, log)
    , full(model, tangent, eigensolver, classifier, log, timer)
  {}

  void
  PrestressedEigenproblem::declare_parameters(ParameterHandler &prm)
  {
    Bearings::declare_list(prm);
    DampedEigensolver::declare_parameters(prm);
    ReducedBasis::declare_parameters(prm);
    prm.enter_subsection("Eigenproblem");
    prm.declare_entry("Compute modes",
                      "true",
                      Patterns::Bool(),
                      "Solve the damped eigenproblem at every speed (false: "
                      "static sweep only).");
    prm.declare_entry("Number of modes",
                      "12",
                      Patterns::Integer(1),
                      "Elastic whirl modes wanted per speed (each conjugate "
                      "pair once); rigid-body modes are requested on top.");
    prm.declare_entry("Contact model",
                      "bonded",
                      Patterns::Selection("bonded|frictionless|fixed|frozen"),
                      "Interface in the eigenproblem: 'bonded' ties the closed "
                      "pairs of the current static state in all directions; "
                      "'frictionless' ties them radially only (refused with "
                      "stress stiffening: spurious twist and tilt modes); "
                      "'fixed' ties every pair whatever the static state (the "
                      "frozen model of commercial codes); 'frozen' keeps the "
                      "first speed's closed pairs.");
    prm.declare_entry("Contact penalty scale",
                      "1000",
                      Patterns::Double(100., 1e8),
                      "Tie stiffness of a pair in the eigenproblem, times its "
                      "radial nodal stiffness [-], 100 .. 1e8; 1000 changes frequencies "
                      "by about 0.1 % against a rigid tie (the error goes as "
                      "1 / scale: a soft tie would move the modes of the fit "
                      "by whole percents; above 1e8 Q(sigma) loses its digits).");
    prm.declare_entry("Stress stiffening",
                      "interference + centrifugal",
                      Patterns::Selection("off|interference only|interference + centrifugal"),
                      "K_sigma from the static stress: 'off'; 'interference "
                      "only' (the fit's own stress at the current contact "
                      "state); 'interference + centrifugal', which also adds "
                      "the convective term -Omega^2 K_theta (they cancel on "
                      "rigid tilt: both or neither, doc/theory.md 4.3).");
    prm.declare_entry("Convective stiffness",
                      "true",
                      Patterns::Bool(),
                      "With centrifugal stress stiffening, add -Omega^2 K_theta. "
                      "'false' only to reproduce codes that add K_sigma alone in "
                      "the stationary frame: that stiffens rigid tilt by "
                      "Omega^2 Ip/2 and twist by Omega^2 Ip (doc/theory.md 4.5, P2).");
    prm.declare_entry("Rigid-body threshold",
                      "1",
                      Patterns::Double(0.),
                      "Modes with |lambda| / 2 pi below this [Hz] are rigid-body "
                      "modes (or modes of a loose body): listed in "
                      "rigid_modes.csv, never plotted.");
    prm.declare_entry("Self-check",
                      "false",
                      Patterns::Bool(),
                      "At the first speed > 0, check the virial identity of "
                      "K_sigma on rigid tilt and twist and the tilt "
                      "cancellation with Omega^2 K_theta (doc/theory.md 10e); values "
                      "in the log and summary.txt.");
    prm.leave_subsection();
  }

  void
  PrestressedEigenproblem::parse_parameters(ParameterHandler  &prm,
                                            const std::string &prm_directory,
                                            const bool         spin_softening)
  {
    bearings.parse_parameters(prm, prm_directory);
    eigensolver.parse_parameters(prm);
    reduced.parse_parameters(prm);
    prm.enter_subsection("Eigenproblem");
    auto &settings                 = tangent.settings;
    settings.static_spin_softening = spin_softening;
    compute  = prm.get_bool("Compute modes");
    n_wanted = prm.get_integer("Number of modes");
    const std::string model_name = prm.get("Contact model");
    settings.contact_model = model_name == "bonded"       ? ContactModel::bonded :
                             model_name == "frictionless" ? ContactModel::frictionless :
                             model_name == "fixed"        ? ContactModel::fixed :
                                                            ContactModel::frozen;
    settings.contact_scale = prm.get_double("Contact penalty scale");
    const std::string s = prm.get("Stress stiffening");
    settings.stiffening = s == "off"               ? StressStiffening::off :
                          s == "interference only" ? StressStiffening::interference :
                                                     StressStiffening::full;
    classifier.n_wanted           = n_wanted;
    classifier.rigid_threshold_hz = prm.get_double("Rigid-body threshold");
    settings.convective_term      = prm.get_bool("Convective stiffness");
    self_check                    = prm.get_bool("Self-check");
    prm.leave_subsection();

    // normal-only ties with pre-stress give spurious twist and tilt modes,
    // some unstable (doc/theory.md 7.4): refuse rather than plot them
    if (compute && settings.contact_model == ContactModel::frictionless &&
        settings.stiffening != StressStiffening::off)
      throw InputError(
        "Eigenproblem/Contact model = frictionless with Stress stiffening = '" +
        s + "' produces spurious twist and tilt modes (some unstable) because "
            "normal-only ties carry no contact geometric stiffness; use "
            "Contact model = bonded, or Stress stiffening = off.");
    if (compute && spin_softening && settings.stiffening == StressStiffening::interference)
      throw InputError("Eigenproblem/Stress stiffening = interference only needs "
                       "Physics/Spin softening = false (with spin softening "
                       "the static solution does not split into interference "
                       "and centrifugal parts).");
  }

  void
  PrestressedEigenproblem::setup()
  {
    if (!compute)
      return;
    const auto &dof_handler = model.dofs();
    bearings.setup(model, log);
    classifier.setup();
    tangent.setup();
    circumferential_share = RevolutionCheck::circumferential_share(
      model.mesh(), dof_handler, model.bodies().size(), dof_handler.get_communicator());
    inertia = RevolutionCheck::transverse_inertia(model.mesh(), dof_handler, model.bodies().size(),
                                                  dof_handler.get_communicator());
    log << RevolutionCheck::describe(circumferential_share, inertia, model.bodies());

    // more modes than the model has
    std::vector<bool>  loose;
    const std::size_t  n_pairs = model.pairs().pairs().size();
    const unsigned int zeros   = classifier.expected_zero_modes(std::vector<bool>(n_pairs, true), loose);
    const std::size_t  nev     = 2 * n_wanted + 2 * zeros + 1;
    // the most eigenvalues a speed may ask for: every fit open (each body
    // its own rigid group), plus what a retry adds
    const unsigned int loose_zeros =
      classifier.expected_zero_modes(std::vector<bool>(n_pairs, false), loose);
    const ReducedBasis &basis = reduced.basis();
    max_nev = 2 * n_wanted + 2 * std::max(zeros, loose_zeros) + 1 + 2 * n_wanted +
              (basis.enabled() ? 2 * basis.margin() : 0);
    if (nev + 3 > 2 * dof_handler.n_dofs())
      throw InputError("Eigenproblem/Number of modes = " + std::to_string(n_wanted) +
                       " needs " + std::to_string(nev) +
                       " eigenvalues, but the model has only " +
                       std::to_string(2 * dof_handler.n_dofs()) +
                       " (2 x DOFs); ask for fewer modes or refine the mesh.");

    const auto &settings = tangent.settings;
    log << "Eigenproblem: " << n_wanted << " modes per speed, contact model "
        << (settings.contact_model == ContactModel::bonded       ? "bonded" :
            settings.contact_model == ContactModel::frictionless ? "frictionless" :
            settings.contact_model == ContactModel::fixed        ? "fixed" : "frozen")
        << (settings.convective_term ? "" : ", NO convective stiffness (K_sigma alone, for comparison)")
        << ", stress stiffening "
        << (settings.stiffening == StressStiffening::off          ? "off" :
            settings.stiffening == StressStiffening::interference ? "interference only" :
                                                                    "interference + centrifugal")
        << ", shift " << eigensolver.shift() / (2 * M_PI) << " Hz, "
        << bearings.size() << " bearing(s)\n";
    // every coefficient: a cross-coupled bearing must be checkable here
    for (unsigned int n = 0; n < bearings.size(); ++n)
      {
        const auto         &b = bearings.list()[n];
        Bearings::Coefficients k, c;
        bearings.coefficients(n, 0., k, c);
        const Station &s = b.station;
        log << "  bearing " << b.name << " on " << (s.is_band() ? s.describe() : s.surface)
            << ": area " << s.area * 1e6 << " mm^2 at z = " << s.z << " m, "
            << s.weight.size() << " weighted nodes, "
            << (b.table.empty() ? "" : "at rest (speed table " + b.table_file + ") ") << "kxx "
            << k[0] << ", kyy " << k[1] << ", kxy " << k[2] << ", kyx " << k[3] << " N/m, cxx "
            << c[0] << ", cyy " << c[1] << ", cxy " << c[2] << ", cyx " << c[3] << " N s/m\n";
      }
  }

  void
  PrestressedEigenproblem::assemble_speed_independent_matrices()
  {
    if (!compute)
      return;
    TimerOutput::Scope t(timer, "eigen: assembly (M, K, G, K_theta)");
    tangent.assemble_speed_independent([&](const RotorMatrices &matrices) {
      if (self_check)
        self_checks.record_convective(matrices);
    });
  }

  unsigned int
  PrestressedEigenproblem::begin_speed(const StaticState &state,
                                       EigenSolution     &solution,
                                       std::vector<bool> &loose_body)
  {
    solution.rpm   = state.rpm;
    solution.index = state.index;
    solution.tied  = tangent.tied_pairs(state);
    // an anisotropic rotor has no doublets at rest and excites its
    // backward lines as well, like anisotropic bearings
    solution.isotropic_supports =
      bearings.isotropic(state.rpm) &&
      std::all_of(inertia.begin(), inertia.end(), [](const RevolutionCheck::Inertia &i) {
        return i.anisotropy <= RevolutionCheck::anisotropy_limit;
      });
    if (state.rpm > 0)
      warn_not_of_revolution(state.rpm);
    tangent.assemble(state, solution.tied, speeds_done == 0);
    last_rpm      = state.rpm;
    speed_reduced = false;
    if (self_check && self_checks.pending() && state.rpm > 0)
      self_checks.check(state, tangent);
    const unsigned int zeros = classifier.expected_zero_modes(solution.tied, loose_body);
    return 2 * n_wanted + 2 * zeros + 1;
  }

  bool
  PrestressedEigenproblem::solve_trial(const StaticState &state, EigenSolution &solution)
  {
    // only where the speed's own solve left a basis of this tied set
    if (!reduced.basis().enabled() || reduced.basis().size() == 0 ||
        tangent.tied_pairs(state) != basis_tied)
      return false;
    solution = EigenSolution();
    std::vector<bool>  loose_body;
    const unsigned int nev = begin_speed(state, solution, loose_body);
    std::string        unused;
    TimerOutput::Scope t(timer, "eigen: reduced model");
    double             worst = 0; // (a trial's backward errors are not checked)
    if (!reduced_solve.solve(state, loose_body, nev, solution, unused, false, worst))
      return false;
    ++reduced_trials;
    if (solution.elastic.size() > n_wanted)
      solution.elastic.resize(n_wanted);
    return true;
  }

  EigenSolution
  PrestressedEigenproblem::solve(const StaticState &state)
  {
    EigenSolution     solution;
    std::vector<bool> loose_body;
    unsigned int      nev = begin_speed(state, solution, loose_body);

    bool margin_pays = false;
    if (reduced.basis().enabled())
      {
        if (solve_on_basis(state, loose_body, nev, solution, margin_pays))
          return solution;
        // the anchor's margin: modes that may move into the wanted range
        if (margin_pays)
          nev = std::min<unsigned int>(nev + 2 * reduced.basis().margin(),
                                       2 * model.dofs().n_dofs() - 3);
      }

    // the reduced products serve no full solve and its anchor makes them
    // stale: free them before the factorisation, the memory peak
    reduced.free_products();
    const double worst = full.solve(state, loose_body, nev,
                                    reduced.basis().enabled() ? &anchor : nullptr, margin_pays,
                                    solution);
    if (solution.elastic.size() > n_wanted)
      solution.elastic.resize(n_wanted);
    warn_far_shift(solution, state.rpm);
    classifier.announce_loose_bodies(state, loose_body);
    worst_backward_error = std::max(worst_backward_error, worst);
    ++speeds_done;
    return solution;
  }

  bool
  PrestressedEigenproblem::solve_on_basis(const StaticState       &state,
                                          const std::vector<bool> &loose_body,
                                          const unsigned int       nev,
                                          EigenSolution           &solution,
                                          bool                    &margin_pays)
  {
    // a contact segment (tied set) of its own starts a new basis. A set
    // that just changed with every fit part open, part closed is likely
    // to change again at the next speed (a fit opening gradually): its
    // anchor skips the margin. Fits wholly closed or wholly open last.
    const auto &pair_list = model.pairs();
    bool        settled   = true;
    for (unsigned int i = 0; i < pair_list.n_interfaces(); ++i)
      {
        const auto &ids = pair_list.pairs_of(i);
        const auto  n_tied =
          std::count_if(ids.begin(), ids.end(), [&](unsigned int p) { return solution.tied[p]; });
        settled &= n_tied == 0 || n_tied == static_cast<long>(ids.size());
      }
    margin_pays = solution.tied == basis_tied || basis_tied.empty() || settled;
    if (solution.tied != basis_tied)
      {
        reduced.clear();
        basis_tied = solution.tied;
      }
    std::string why;
    bool        done = false;
    {
      TimerOutput::Scope t(timer, "eigen: reduced model");
      done = reduced_solve.solve(state, loose_body, nev, solution, why, true, worst_backward_error);
    }
    if (done)
      {
        served(state, loose_body, solution, reduced_solves);
        return true;
      }
    if (reduced.basis().size() > 0)
      {
        ++reduced_refusals;
        log << "  eigen: reduced model refused at " << state.rpm << " r/min (" << why
            << "): full solve, a new anchor\n";
      }
    // an undamped anchor where K_t is symmetric (LDL^T instead of LU)
    return reduced.basis().undamped_anchors() && bearings.symmetric(state.rpm, false) &&
           solve_on_undamped_anchor(state, loose_body, nev, margin_pays, solution, why);
  }

  bool
  PrestressedEigenproblem::solve_on_undamped_anchor(const StaticState       &state,
                                                    const std::vector<bool> &loose_body,
                                                    const unsigned int       nev,
                                                    const bool               lasting,
                                                    EigenSolution           &solution,
                                                    std::string             &why)
  {
    // on the last LDL^T where few ties changed since (a fit opening
    // pair by pair), else on a new one
    std::vector<DirectSolver::UpdateColumn> columns;
    const unsigned int                      limit = reduced.basis().tie_update_limit();
    if (limit > 0 &&
        ties.columns(eigensolver.linear_solver(), state, solution.tied, limit, columns))
      {
        const std::size_t anchors_before = reduced.basis().anchors.size();
        if (anchor_and_solve(state, loose_body, nev, lasting, solution, why, true))
          {
            ++ties.anchors;
            served(state, loose_body, solution, undamped_served);
            return true;
          }
        ++ties.anchors_refused;
        log << "  eigen: undamped anchor on the tie update refused at " << state.rpm
            << " r/min (" << why << "): a new LDL^T\n";
        // its vectors stay in the basis, the new anchor's join them
        // (TS at 23,900 r/min: the two together serve the speed,
        // the new anchor's alone do not, and the speed would need
        // the damped full solve, its LU the 301-speed run's peak);
        // its coverage claim goes (the checks refused it)
        reduced.keep_anchors(anchors_before);
      }
    if (anchor_and_solve(state, loose_body, nev, lasting, solution, why, false))
      {
        served(state, loose_body, solution, undamped_served);
        return true;
      }
    ++undamped_refused;
    log << "  eigen: undamped anchor at " << state.rpm << " r/min refused (" << why
        << "): the damped full solve\n";
    return false;
  }

  bool
  PrestressedEigenproblem::anchor_and_solve(const StaticState       &state,
                                            const std::vector<bool> &loose_body,
                                            const unsigned int       nev,
                                            const bool               lasting,
                                            EigenSolution           &solution,
                                            std::string             &why,
                                            const bool               on_update)
  {
    if (!anchor.make(state, solution.tied, nev, n_wanted, lasting, why, on_update))
      return false;
    TimerOutput::Scope t(timer, "eigen: reduced model");
    return reduced_solve.solve(state, loose_body, nev, solution, why, true, worst_backward_error);
  }

  void
  PrestressedEigenproblem::served(const StaticState       &state,
                                  const std::vector<bool> &loose_body,
                                  EigenSolution           &solution,
                                  unsigned int            &counter)
  {
    speed_reduced = true;
    ++counter;
    if (solution.elastic.size() > n_wanted)
      solution.elastic.resize(n_wanted);
    warn_far_shift(solution, state.rpm);
    classifier.announce_loose_bodies(state, loose_body);
    ++speeds_done;
  }

  PrestressedEigenproblem::SpeedOperators
  PrestressedEigenproblem::operators()
  {
    // the factorisation of the latest full solve serves the response's
    // basis (it checks its residual on this speed's matrices); a new one
    // only if there is none
    if (!eigensolver.linear_solver().factorized())
      {
        TimerOutput::Scope t(timer, "eigen: factorisation + ARPACK");
        eigensolver.factorize(tangent.mass(), tangent.damping(), tangent.stiffness());
      }
    SpeedOperators op{tangent.mass(), tangent.damping(), tangent.stiffness(),
                      eigensolver.linear_solver(), last_rpm};
    if (tangent.affine_segment())
      {
        op.segment     = tangent.segment();
        op.speed_share = [this](const std::vector<const Vector<double> *> &x,
                                std::vector<Vector<double>>               &gx,
                                std::vector<Vector<double>>               &k2x) {
          tangent.speed_share(x, gx, k2x);
        };
      }
    // the reduced model of this speed, for the response: only with the
    // products its projections were made of (freed by a full solve)
    const auto &p = reduced.projections();
    if (speed_reduced && !p.av_mass.empty())
      {
        op.basis = &reduced.basis();
        op.Mr    = &p.mass;
        op.Cr    = &reduced.speed_damping();
        op.Kr    = &reduced.speed_stiffness();
        const double omega = SpeedSchedule::rpm_to_rad_per_s(last_rpm);
        op.products = [this, omega](const std::vector<std::complex<double>> &y,
                                    ComplexVector                           &Mu,
                                    ComplexVector                           &Cu,
                                    ComplexVector                           &Ku) {
          ReducedModel::Expanded e = reduced.expanded({y}, omega, omega * omega, false);
          Mu                       = std::move(e.m[0]);
          Cu                       = std::move(e.c[0]);
          Ku                       = std::move(e.k[0]);
        };
        op.w_tangent = p.w_tangent;
        op.row_parts = [this](const std::vector<const Vector<double> *> &x,
                              std::array<std::vector<double>, 5>        &parts) {
          reduced.row_parts(x, parts);
        };
      }
    return op;
  }

  void
  PrestressedEigenproblem::finish(Summary &summary) const
  {
    bool of_revolution = true;
    for (unsigned int b = 0; b < circumferential_share.size(); ++b)
      {
        summary.add("body." + model.bodies()[b].name + ".circumferential_share",
                    circumferential_share[b]);
        of_revolution = of_revolution && circumferential_share[b] <= RevolutionCheck::limit;
      }
    if (!circumferential_share.empty())
      summary.add("eigen.rotor_of_revolution", of_revolution ? 1 : 0);
    bool isotropic = true;
    for (unsigned int b = 0; b < inertia.size(); ++b)
      {
        summary.add("body." + model.bodies()[b].name + ".transverse_anisotropy",
                    inertia[b].anisotropy);
        summary.add("body." + model.bodies()[b].name + ".centroid_offset_m", inertia[b].offset);
        isotropic = isotropic && inertia[b].anisotropy <= RevolutionCheck::anisotropy_limit;
      }
    if (!inertia.empty())
      summary.add("eigen.rotor_isotropic", isotropic ? 1 : 0);
    if (!compute || speeds_done == 0)
      return;
    for (const auto &[key, value] : self_checks.results())
      summary.add(key, value, 12);
    summary.add("eigen.speeds", speeds_done);
    summary.add("eigen.worst_backward_error", worst_backward_error, 12);
    summary.add("eigen.retried_speeds", full.retried_speeds);
    summary.add("eigen.full_solves", full.solves);
    summary.add("eigen.reduced_solves", reduced_solves);
    summary.add("eigen.reduced_refusals", reduced_refusals);
    summary.add("eigen.reduced_root_trials", reduced_trials);
    summary.add("eigen.undamped_anchors", undamped_served);
    summary.add("eigen.undamped_anchors_refused", undamped_refused);
    summary.add("eigen.undamped_anchors_on_tie_updates", ties.anchors);
    summary.add("eigen.tie_update_anchors_refused", ties.anchors_refused);
    // (an undamped anchor's speed is a reduced solve with the same checks)
    const bool any_reduced = reduced_solves + undamped_served > 0;
    if (any_reduced)
      {
        summary.add("eigen.reduced_worst_error_estimate", reduced_solve.worst_estimate, 12);
        summary.add("eigen.reduced_worst_product_mismatch", reduced_solve.worst_products, 12);
        summary.add("eigen.product_checks_skipped", reduced_solve.checks_skipped);
        summary.add("eigen.estimate_gram_matrices", estimates.builds);
        summary.add("eigen.estimate_gram_worst_difference", estimates.worst_difference, 12);
        summary.add("eigen.residual_norm_gram_worst_difference", estimates.norms_worst_difference, 12);
        summary.add("eigen.residual_norms_from_gram", estimates.norm_speeds);
      }
    summary.add("eigen.workspace_retries", eigensolver.linear_solver().n_workspace_retries());
    summary.add("eigen.factorizations", eigensolver.linear_solver().n_factorizations());
    summary.add("eigen.factorizations_on_earlier_analysis",
                eigensolver.linear_solver().n_reused_analyses());
    log << "Eigenproblem: " << speeds_done << " speeds (" << full.solves << " full, "
        << reduced_solves << " on the reduced model, " << reduced_refusals
        << " refused by it; " << undamped_served << " on undamped anchors (" << ties.anchors
        << " on tie updates of an earlier LDL^T), "
        << undamped_refused << " refused by them; " << reduced_trials
        << " unchecked root-solve trials on it), "
        << eigensolver.linear_solver().n_factorizations()
        << " factorisations (LU of Q(sigma) or LDL^T of K_t + sigma^2 M), worst backward error "
        << worst_backward_error
        << (any_reduced ? ", largest estimated error of a reduced mode " : "");
    if (any_reduced)
      log << reduced_solve.worst_estimate;
    log << '\n';
  }

  void
  PrestressedEigenproblem::warn_not_of_revolution(const double rpm)
  {
    if (revolution_warned)
      return;
    revolution_warned = true;
    for (unsigned int b = 0; b < inertia.size(); ++b)
      if (inertia[b].anisotropy > RevolutionCheck::anisotropy_limit)
        log << "Warning: body " << model.bodies()[b].name << " is anisotropic about the axis "
            << "(second moments " << inertia[b].anisotropy
            << "): in the stationary frame (doc/theory.md 4.1) such a rotor is parametrically "
               "excited, and no mode of it, the whirl included, is a mode of this eigenproblem "
               "from " << rpm << " r/min on.\n";
    for (unsigned int b = 0; b < circumferential_share.size(); ++b)
      if (circumferential_share[b] > RevolutionCheck::limit &&
          !(b < inertia.size() && inertia[b].anisotropy > RevolutionCheck::anisotropy_limit))
        log << "Warning: body " << model.bodies()[b].name << " is not a body of revolution ("
            << 100 * circumferential_share[b]
            << " % of its surface faces the circumferential direction: blades, keys, flats). "
               "The stationary frame (doc/theory.md 4.1) holds above 0 r/min only for the "
               "modes that move such parts rigidly with their hub, as the whirl pairs do "
               "(checked against CalculiX's rotating frame: doc/bladed_impeller.md); modes "
               "that deform them (blade modes) are wrong from " << rpm << " r/min on.\n";
  }

  void
  PrestressedEigenproblem::warn_far_shift(const EigenSolution &solution, const double rpm)
  {
    // shift-invert orders the spectrum by |lambda - sigma|: far above the
    // lowest modes the wanted eigenvalues crowd together and ARPACK can
    // miss a member of a doublet (doc/limits.md)
    const double sigma_hz = eigensolver.shift() / (2 * M_PI);
    if (!shift_warned && !solution.elastic.empty() &&
        sigma_hz > std::abs(solution.elastic.front().lambda.imag()) / (2 * M_PI))
      {
        shift_warned = true;
        log << "Warning: Eigenproblem/Shift = " << sigma_hz
            << " Hz lies above the lowest elastic frequency found at " << rpm
            << " r/min (" << std::abs(solution.elastic.front().lambda.imag()) / (2 * M_PI)
            << " Hz): the shift-inverted eigenvalues crowd together and modes can be missed; "
               "keep the Shift below the lowest frequency of interest.\n";
      }
  }
} // namespace rotorfit
