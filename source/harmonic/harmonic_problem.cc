#include <rotorfit/base/format.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/eigen/backward_error.h>
#include <rotorfit/harmonic/harmonic_problem.h>
#include <rotorfit/harmonic/meridian_stress.h>
#include <rotorfit/modal/line_root.h>
#include <rotorfit/statics/speed_schedule.h>

#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>
#include <deal.II/lac/sparse_direct.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>
#include <tuple>

namespace rotorfit
{
  using namespace dealii;

  HarmonicProblem::HarmonicProblem(const MPI_Comm comm, Log &log, TimerOutput &timer)
    : comm(comm)
    , log(log)
    , timer(timer)
    , meridian(log)
  {}

  void
  HarmonicProblem::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Harmonic model");
    prm.declare_entry("Harmonics",
                      "0, 1, 2, 3",
                      Patterns::List(Patterns::Integer(0, 64), 1),
                      "With Geometry/Model = axisymmetric: the Fourier harmonics "
                      "whose damped modes are solved at every speed. 0: axial, "
                      "torsional and radial modes; 1: lateral whirl (the only "
                      "harmonic a bearing holds); n >= 2: disk modes with n "
                      "nodal diameters. The static contact state is harmonic 0 "
                      "whatever is listed.");
    prm.declare_entry("Modes per harmonic",
                      "6",
                      Patterns::Integer(1),
                      "Elastic modes kept per harmonic and speed, lowest first "
                      "(each conjugate pair once; forward and backward count "
                      "separately); rigid-body modes are solved on top and left out.");
    prm.leave_subsection();
  }

  void
  HarmonicProblem::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Harmonic model");
    harmonics.clear();
    for (const auto &item : Utilities::split_string_list(prm.get("Harmonics"), ','))
      {
        const unsigned int n = Utilities::string_to_int(item);
        if (std::find(harmonics.begin(), harmonics.end(), n) != harmonics.end())
          throw InputError("Harmonic model/Harmonics lists " + item + " twice.");
        harmonics.push_back(n);
      }
    modes_per_harmonic = prm.get_integer("Modes per harmonic");
    prm.leave_subsection();

    prm.enter_subsection("Eigenproblem");
    compute_modes = prm.get_bool("Compute modes");
    if (prm.get("Contact model") != "bonded")
      throw InputError("Eigenproblem/Contact model = " + prm.get("Contact model") +
                       ": the axisymmetric model ties the closed ring pairs of each speed "
                       "(bonded) only; set Contact model = bonded, or Geometry/Model = 3d.");
    tie_scale                   = prm.get_double("Contact penalty scale");
    const std::string stiffening = prm.get("Stress stiffening");
    prestress                   = stiffening != "off";
    centrifugal_prestress       = stiffening == "interference + centrifugal";
    convective                  = prm.get_bool("Convective stiffness");
    rigid_threshold             = prm.get_double("Rigid-body threshold");
    // the 3D model's line tracking (ModalAnalysis declares the entries)
    tracker_template = ModeTracker::from_parameters(prm);
    prm.leave_subsection();
    prm.enter_subsection("Physics");
    spin_softening = prm.get_bool("Spin softening");
    prm.leave_subsection();
    if (compute_modes && spin_softening && prestress && !centrifugal_prestress)
      throw InputError("Eigenproblem/Stress stiffening = interference only needs Physics/Spin "
                       "softening = false (with spin softening the static solution does not "
                       "split into interference and centrifugal parts).");
    contact.parse_parameters(prm);
    eigensolver.parse_parameters(prm);
    reduced_settings.parse_parameters(prm);
    // one solver per harmonic: each keeps its latest anchor's factorisation
    // (the response's enrichments, doc/theory.md 14.6)
    solvers.clear();
    for (unsigned int k = 0; k < harmonics.size(); ++k)
      {
        solvers.push_back(std::make_unique<DampedEigensolver>());
        solvers.back()->parse_parameters(prm);
      }
  }

  void
  HarmonicProblem::setup(const Discretization &model,
                         const Bearings       &bearing_list,
                         UnbalanceResponse    &unbalance)
  {
    if (Utilities::MPI::n_mpi_processes(comm) > 1)
      throw InputError("Geometry/Model = axisymmetric runs on one MPI rank (its matrices are "
                       "those of a plane mesh); start it without mpirun, or use Geometry/Model "
                       "= 3d for a distributed run.");
    interfaces = &model.interfaces();
    const auto strains = model.bodies().free_thermal_strains(model.interfaces().reference_temperature());
    if (!model.roller_surfaces().empty() &&
        std::any_of(strains.begin(), strains.end(), [](const double e) { return e != 0; }))
      throw InputError("Supports/Axial roller surfaces hold u_z = 0, which would restrain the "
                       "thermal expansion of a body off the reference temperature; remove the "
                       "rollers or keep every body at Fit design/Reference temperature.");
    meridian.setup(model.mesh().sections(), model.element_order(), model.bodies(),
                   model.interfaces(), model.roller_surfaces());
    bearings = &bearing_list;
    stations.clear();
    bearing_bodies.clear();
    for (const auto &b : bearing_list.list())
      {
        Station s = b.station;
        meridian.station_weights(s);
        for (const auto dof : s.dof_x)
          bearing_bodies.push_back(meridian.node_bodies()[meridian.node_of(dof)]);
        std::ostringstream m;
        m << std::setprecision(4) << "  " << s.owner << ": " << s.describe() << ": r "
          << s.radius * 1e3 << " mm, z " << s.z * 1e3 << " mm, area " << s.area * 1e6
          << " mm^2\n";
        log << m.str();
        stations.push_back(s);
      }
    response = nullptr;
    if (unbalance.enabled())
      {
        if (std::find(harmonics.begin(), harmonics.end(), 1u) == harmonics.end())
          throw InputError("Unbalances are given, but Harmonic model/Harmonics does not list 1: "
                           "an unbalance forces harmonic 1 (the lateral whirl); add 1 to the "
                           "list or remove the Unbalances.");
        unbalance.setup(bearing_list, [&](Station &s) { meridian.station_weights(s); });
        for (const auto &u : unbalance.unbalance_list())
          stations.push_back(u.station);
        for (const auto &p : unbalance.probe_list())
          stations.push_back(p.station);
        response = &unbalance;
      }
  }

  void
  HarmonicProblem::start(const std::string &directory, const double w_max)
  {
    assembler = std::make_unique<HarmonicAssembler>(meridian);
    {
      TimerOutput::Scope t(timer, "assembly (harmonic model)");
      assembler->assemble_static(system, spin_softening, comm);
      owned = complete_index_set(meridian.dofs().n_dofs());
      if (compute_modes)
        {
          operators = std::make_unique<HarmonicOperators>(
            *assembler, contact, *bearings, harmonics, stations, system.stiffness_diagonal,
            HarmonicOperators::Settings{prestress, centrifugal_prestress, convective, tie_scale},
            comm);
          previous_law.assign(harmonics.size(), 0);
          reduced.clear();
          for (const auto &h : operators->harmonics())
            reduced.push_back(std::make_unique<HarmonicReducedModel>(h.n, reduced_settings));
          if (response)
            harmonic_response =
              std::make_unique<HarmonicResponse>(*operators, bearings->size(), *response, log);
        }
    }
    log << "Mass properties (meridian, exact geometry):\n";
    for (unsigned int b = 0; b < meridian.bodies().size(); ++b)
      log << "  body " << meridian.bodies()[b].name << ": mass " << system.mass[b]
          << " kg, polar moment of inertia " << system.polar[b] << " kg m^2\n";
    for (const auto &h : harmonic_matrices())
      log << "Harmonic " << h.n << ": " << h.free.n_free << " DoFs\n";
    contact.initialize({meridian.pairs(),
                        meridian.static_constraints(),
                        system.stiffness,
                        system.unit_centrifugal_load,
                        spin_softening ? &system.spin_softening : nullptr,
                        system.stiffness_diagonal,
                        owned,
                        comm},
                       w_max);
    history = std::make_unique<FitHistory>(meridian.pairs(), *interfaces, log);
    assessment =
      std::make_unique<FitAssessment>(meridian.pairs(), *interfaces, meridian.bodies());
    assessment->initialize(std::make_unique<MeridianStress>(meridian));
    // the swept mesh: at least 8 sectors per wave of the highest harmonic
    paraview = std::make_unique<MeridianOutput>(
      meridian, directory,
      std::max(24u, 8 * *std::max_element(harmonics.begin(), harmonics.end())));
    trackers.assign(harmonics.size(), tracker_template);
    onsets.clear();
    for (unsigned int k = 0; k < harmonics.size(); ++k)
      onsets.push_back(std::make_unique<StabilityOnsets>(log));
    contact_table.open(directory);
    opening_table.open(directory);
    if (contact.path() == ContactSolver::Path::exact)
      event_table.open(directory);
    if (!meridian.pairs().pairs().empty())
      fit_table.open(directory);
    body_stress_table.open(directory);
    if (compute_modes)
      {
        campbell_table.open(directory);
        critical_table.open(directory, true);
        rigid_table.open(directory, true);
        onset_table.open(directory, true);
        if (response)
          response_table.open(directory);
      }
  }

  const StaticState &
  HarmonicProblem::solve_speed(const unsigned int k, const double rpm, const ParaViewFiles files)
  {
    files_now = files;
    state     = StaticState::solve(contact, rpm, k, timer);
    for (const double f : state.contact.force)
      if (!std::isfinite(f))
        throw SolverFailure(rpm, "the static solve at " + format_number(rpm) +
                            " r/min gave a pair force that is not a number");
    history->record(state, state.decomposition(), contact.constraint_error_limit());
    PETScWrappers::MPI::Vector u;
    state.displacement(u);
    {
      TimerOutput::Scope t(timer, "fit assessment (capacity, stresses)");
      assessment->record(state, u);
    }
    contact_table.add(state);
    opening_table.add(state);
    event_table.add(state);
    fit_table.add(state);
    body_stress_table.add(state);
    if (files.solution || indicators)
      {
        if (indicators)
          indicators->add_meridian_static(meridian, Vector<double>(u));
        if (files.solution)
          {
            TimerOutput::Scope t(timer, "output (ParaView)");
            paraview->write_static(Vector<double>(u), state, "solution", k);
          }
      }
    if (compute_modes)
      {
        std::vector<MeridianOutput::Shape> shapes;
        {
          TimerOutput::Scope t(timer, "eigenproblem (harmonic model)");
          campbell_table.add(state, solve_modes(state, files.modes ? &shapes : nullptr));
        }
        if (files.modes)
          {
            TimerOutput::Scope t(timer, "output (ParaView)");
            paraview->write_modes(shapes, state.rpm, "modes", k);
          }
        if (response)
          {
            const unsigned int k = std::find_if(operators->harmonics().begin(), operators->harmonics().end(),
                                                [](const auto &h) { return h.n == 1; }) -
                                   operators->harmonics().begin();
            TimerOutput::Scope t(timer, "unbalance response");
            ResponseAtSpeed    r = harmonic_response->solve(
              k, state, reduced_settings.enabled() ? reduced[k].get() : nullptr, *solvers[k]);
            response->record(r, "The direct solve of harmonic 1 is singular or ill-conditioned "
                                "at this speed (a free rotor at rest, or a speed on an "
                                "undamped critical speed)");
            response_table.add(r);
          }
      }
    return state;
  }

  namespace
  {
    /// The @p n eigenvalues of @p pairs nearest @p sigma (a conjugate pair,
    /// kept once, counts twice), as the shift-invert solve picks them,
    /// ordered by |lambda| as it returns them.
    void
    keep_nearest(std::vector<EigenPair> &pairs, const unsigned int n, const double sigma)
    {
      std::stable_sort(pairs.begin(), pairs.end(), [&](const EigenPair &a, const EigenPair &b) {
        return std::abs(a.lambda - sigma) < std::abs(b.lambda - sigma);
      });
      unsigned int count = 0, kept = 0;
      while (kept < pairs.size() && count < n)
        count += pairs[kept++].lambda.imag() != 0 ? 2 : 1;
      pairs.resize(kept);
      std::stable_sort(pairs.begin(), pairs.end(), [](const EigenPair &a, const EigenPair &b) {
        return std::abs(a.lambda) < std::abs(b.lambda);
      });
    }
  } // namespace

  EigenSolution
  HarmonicProblem::solve_harmonic(const unsigned int hk, const StaticState &s)
  {
    const auto &h = operators->harmonic(hk);
    // rigid motions on top of the modes wanted: axial translation and twist
    // (n = 0) of every group of bodies the closed pairs tie together,
    // translations and tilts (n = 1) of every such group no bearing holds
    const unsigned int rigid = rigid_motions(h.n, s);
    const unsigned int wanted =
      std::min<unsigned int>(2 * (modes_per_harmonic + rigid), h.free.n_free - 2);
    const std::size_t law = operators->law_matrices(hk, s);
    // the reduced model serves the affine laws (doc/theory.md 14.6)
    const bool use_reduced = reduced_settings.enabled() && s.decomposition().affine;
    std::vector<EigenPair> pairs_found;
    bool                   solved = false;
    if (use_reduced && reduced[hk]->serves(law))
      {
        const auto                   t0 = std::chrono::steady_clock::now();
        HarmonicReducedModel::Speed speed;
        speed.rpm            = s.rpm;
        speed.couplings      = operators->bearing_couplings(hk, s.rpm);
        speed.n_wanted       = wanted;
        speed.sigma          = eigensolver.shift();
        speed.backward_limit = eigensolver.backward_error_limit();
        speed.rigid_hz       = rigid_threshold;
        std::string why;
        solved = reduced[hk]->solve(operators->law_operators(hk), speed, pairs_found, why);
        reduced_seconds +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (solved)
          ++reduced_solves;
        else
          {
            ++refusals;
            log << "  harmonic " << h.n << " at " << format_number(s.rpm)
                << " r/min: reduced solve refused (" << why << "); solved in full\n";
          }
      }
    // a law of a fit opening ring by ring rarely lasts a second speed: its
    // full solve builds no basis (no margin, directions, Gram matrix); the
    // law's second solve (a root solve, or a speed the law lasted to) does
    const bool transient = s.fit_state == "partial" && law != previous_law[hk];
    previous_law[hk]     = law;
    // the full solve; with the reduced model an anchor with the margin modes
    if (!solved || (s.rpm == 0 && h.n > 0))
      matrix_seconds += operators->assemble_speed(hk, s);
    if (!solved)
      {
        const auto         t0     = std::chrono::steady_clock::now();
        const bool         anchor = use_reduced && !transient;
        const unsigned int margin = anchor ? 2 * reduced_settings.margin() : 0;
        const unsigned int asked  = std::min<unsigned int>(wanted + margin, h.free.n_free - 2);
        pairs_found = solvers[hk]->solve(operators->mass(hk), operators->damping(hk),
                                           operators->stiffness(hk), asked, statistics);
        unconverged_slots += statistics.unconverged_slots;
        restarts += statistics.iterations;
        factor_seconds += statistics.factorization_seconds;
        arnoldi_seconds += statistics.arnoldi_seconds;
        check_seconds += statistics.check_seconds;
        ++eigen_solves;
        if (anchor)
          {
            // every eigenvalue within the farthest one found was found
            double radius = 0;
            for (const auto &p : pairs_found)
              radius = std::max(radius, std::abs(p.lambda - eigensolver.shift()));
            if (statistics.unconverged_slots > 0)
              radius = 0;
            std::vector<Vector<double>> loads;
            if (response && h.n == 1)
              {
                const auto f = harmonic_response->unbalance_load(hk);
                loads.assign(2, Vector<double>(f.size()));
                for (unsigned int i = 0; i < f.size(); ++i)
                  loads[0][i] = f[i].real(), loads[1][i] = f[i].imag();
              }
            reduced[hk]->add_anchor(operators->law_operators(hk), law, s.rpm, pairs_found, radius,
                                    solvers[hk]->linear_solver(), loads);
            ++anchors;
            keep_nearest(pairs_found, wanted, eigensolver.shift());
          }
        else if (use_reduced)
          ++transient_solves;
        anchor_seconds +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      }

    EigenSolution solution;
    solution.rpm                = s.rpm;
    solution.index              = s.index;
    solution.isotropic_supports = bearings->isotropic(s.rpm);
    for (auto &p : pairs_found)
      {
        worst_backward_error = std::max(worst_backward_error, p.backward_error);
        if (!(p.backward_error <= eigensolver.backward_error_limit()))
          {
            ++n_unconverged;
            std::ostringstream m;
            m << "harmonic " << h.n << " at " << format_number(s.rpm) << " r/min: a mode at "
              << std::abs(p.lambda) / (2 * M_PI) << " Hz has the backward error "
              << p.backward_error << " (limit " << eigensolver.backward_error_limit() << ")";
            throw SolverFailure(s.rpm, m.str());
          }
        // rigid motions and overdamped (real) roots are not modes of the
        // diagram: rigid_modes.csv lists them, a loose body's by its name
        const bool rigid = std::abs(p.lambda) / (2 * M_PI) < rigid_threshold;
        if (rigid || std::abs(p.lambda.imag()) <= 1e-9 * std::abs(p.lambda))
          {
            RigidMode r;
            r.kind           = rigid ? "rigid" : "overdamped";
            r.body           = "assembly";
            r.lambda         = p.lambda;
            r.backward_error = p.backward_error;
            r.harmonic       = h.n;
            // a mode (nearly) all on one body of several: that body is loose
            std::vector<double> share(meridian.bodies().size(), 0.);
            double              total = 0;
            for (unsigned int I = 0; I < h.free.n_free; ++I)
              {
                const double a = p.phi.re[I] * p.phi.re[I] + p.phi.im[I] * p.phi.im[I];
                share[meridian.node_bodies()[meridian.node_of(h.free.dof[I])]] += a;
                total += a;
              }
            const auto b = std::max_element(share.begin(), share.end()) - share.begin();
            if (rigid && share.size() > 1 && share[b] > 0.99 * total)
              {
                r.kind = "loose";
                r.body = meridian.bodies()[b].name;
              }
            solution.rigid.push_back(std::move(r));
            continue;
          }
        solution.elastic.push_back(std::move(p));
      }
    auto &e = solution.elastic;
    std::sort(e.begin(), e.end(), [](const EigenPair &a, const EigenPair &b) {
      return a.lambda.imag() < b.lambda.imag();
    });
    if (h.n > 0 && s.rpm == 0 && (h.n >= 2 || solution.isotropic_supports) &&
        add_missing_partners(hk, e) > 0)
      std::sort(e.begin(), e.end(), [](const EigenPair &a, const EigenPair &b) {
        return a.lambda.imag() < b.lambda.imag();
      });
    // a degenerate pair (at rest on isotropic bearings) is one standing wave
    // twice, any mix of the two travelling ones: as travelling waves, backward
    // first (as the 3D model lists a doublet at rest), they continue the
    // lines of the next speed
    for (unsigned int i = 0; h.n > 0 && i + 1 < e.size(); ++i)
      if (std::abs(e[i + 1].lambda - e[i].lambda) <= 1e-7 * std::abs(e[i].lambda))
        waves.split(h, e[i], e[i + 1]), ++i;
    if (e.size() > modes_per_harmonic)
      e.resize(modes_per_harmonic);
    return solution;
  }

  std::vector<HarmonicMode>
  HarmonicProblem::solve_modes(const StaticState &s, std::vector<MeridianOutput::Shape> *shapes)
  {
    std::vector<HarmonicMode>   result;
    ModalResult                 crossings;
    std::vector<StabilityOnset> found;
    crossings.rpm                = s.rpm;
    crossings.isotropic_supports = bearings->isotropic(s.rpm);
    for (unsigned int hk = 0; hk < operators->size(); ++hk)
      {
        const unsigned int n        = operators->harmonic(hk).n;
        EigenSolution      solution = solve_harmonic(hk, s);
        for (const auto &p : solution.elastic)
          sweep_worst_estimate = std::max(sweep_worst_estimate, p.error_estimate);
        crossings.rigid.insert(crossings.rigid.end(), solution.rigid.begin(), solution.rigid.end());
        ModalResult        r;
        r.rpm   = s.rpm;
        r.index = s.index;
        std::vector<HarmonicMode> modes;
        for (auto &p : solution.elastic)
          {
            HarmonicMode mode;
            mode.harmonic         = n;
            mode.lambda           = p.lambda;
            mode.backward_error   = p.backward_error;
            mode.forward_fraction = n == 0 ? std::numeric_limits<double>::quiet_NaN() :
                                             waves.forward_fraction(operators->harmonic(hk), p.phi);
            // the 3D model's rule on the whirl ratio 2 f - 1 (doc/theory.md 9.2)
            const double ratio = 2 * mode.forward_fraction - 1;
            mode.travel        = n == 0         ? "-" :
                                 ratio >= 0.1  ? "forward" :
                                 ratio <= -0.1 ? "backward" :
                                                 "mixed";
            mode.whirl         = n == 1 ? mode.travel : "non-lateral";
            mode.index         = modes.size() + 1;
            modes.push_back(mode);
            if (shapes)
              shapes->push_back(shape(hk, mode.index, p.phi));
            if (indicators && n == 1)
              indicators->add_meridian_mode(meridian, mode.index, shape(hk, mode.index, p.phi).value);
            // a line continues only in its direction of travel
            r.modes.emplace_back(std::move(p));
            r.modes.back().whirl = n == 0 ? "non-lateral" : mode.travel;
          }
        auto lines = trackers[hk].track(s.rpm, r.modes);
        const auto number = [&](const unsigned int local) {
          const auto [it, added] = line_ids.emplace(std::make_pair(n, local), line_ids.size() + 1);
          return it->second;
        };
        for (unsigned int i = 0; i < modes.size(); ++i)
          modes[i].tracked_id = r.modes[i].tracked_id = number(r.modes[i].tracked_id);
        HarmonicEigenproblem eigen(*this, hk);
        for (auto &c : lines)
          {
            c.tracked_id    = number(c.tracked_id);
            const auto line = std::find_if(r.modes.begin(), r.modes.end(), [&](const WhirlMode &m) {
              return m.tracked_id == c.tracked_id;
            });
            const LineRoot root = solve_crossing(c, *line, s, eigen, log);
            // the line's mode at the crossing: the root solve's mode at its frequency
            const auto    &at   = root.solution.elastic;
            for (unsigned int m = 0; c.solved && m < at.size(); ++m)
              if (c.mode == 0 || std::abs(at[m].lambda.imag() - 2 * M_PI * c.frequency_hz) <
                                   std::abs(at[c.mode - 1].lambda.imag() - 2 * M_PI * c.frequency_hz))
                c.mode = m + 1;
            if (c.solved && (files_now.critical_solution || files_now.critical_modes))
              write_critical_files(hk, c, s, root.solution);
            c.harmonic = n;
            c.travel   = n == 0 ? "-" : c.whirl;
            c.whirl    = n == 1 ? c.whirl : "non-lateral";
            n_unsolved += c.solved ? 0 : 1;
            crossings.crossings.push_back(c);
          }
        for (auto o : onsets[hk]->find(r, s, eigen))
          {
            o.harmonic = n;
            o.travel   = n == 0 ? "-" : o.whirl;
            o.whirl    = n == 1 ? o.whirl : "non-lateral";
            found.push_back(o);
          }
        n_modes_written += modes.size();
        result.insert(result.end(), modes.begin(), modes.end());
      }
    n_critical += crossings.crossings.size();
    critical_table.add(crossings);
    rigid_table.add(crossings);
    onset_table.add(found);
    return result;
  }

  unsigned int
  HarmonicProblem::rigid_motions(const unsigned int n, const StaticState &s) const
  {
    if (n >= 2)
      return 0;
    // groups of bodies: union-find over the interfaces with a closed pair
    const unsigned int        n_bodies = meridian.bodies().size();
    std::vector<unsigned int> group(n_bodies);
    for (unsigned int b = 0; b < n_bodies; ++b)
      group[b] = b;
    const auto root = [&](unsigned int b) {
      while (group[b] != b)
        b = group[b];
      return b;
    };
    const auto &pairs = meridian.pairs();
    for (unsigned int i = 0; i < pairs.n_interfaces(); ++i)
      for (const unsigned int p : pairs.pairs_of(i))
        if (p < s.contact.active.size() && s.contact.active[p])
          {
            const auto b = pairs.bodies(i);
            group[root(b[0])] = root(b[1]);
            break;
          }
    std::vector<bool> held(n_bodies, false), counted(n_bodies, false);
    for (const unsigned int b : bearing_bodies)
      held[root(b)] = true;
    unsigned int groups = 0, free_groups = 0;
    for (unsigned int b = 0; b < n_bodies; ++b)
      if (!counted[root(b)])
        {
          counted[root(b)] = true;
          ++groups;
          free_groups += held[root(b)] ? 0 : 1;
        }
    return n == 0 ? 2 * groups : 4 * free_groups;
  }

  unsigned int
  HarmonicProblem::max_harmonic_dofs() const
  {
    unsigned int n = 0;
    for (const auto &h : harmonic_matrices())
      n = std::max(n, h.free.n_free);
    return n;
  }

  MeridianOutput::Shape
  HarmonicProblem::shape(const unsigned int   hk,
                         const unsigned int   index,
                         const ComplexVector &phi) const
  {
    return {operators->harmonic(hk).n, index, waves.expand(operators->harmonic(hk), phi)};
  }

  void
  HarmonicProblem::write_critical_files(const unsigned int   hk,
                                        const CriticalSpeed &c,
                                        const StaticState   &s,
                                        const EigenSolution &solution)
  {
    // the state at the critical speed on this speed's law, as the root
    // solve used it; the modes of the crossing's harmonic there
    StaticState at = s;
    at.rpm         = c.rpm;
    if (files_now.critical_solution)
      {
        PETScWrappers::MPI::Vector u;
        at.displacement(u);
        paraview->write_static(Vector<double>(u), at, "critical_solution", n_critical_files);
      }
    if (files_now.critical_modes)
      {
        std::vector<MeridianOutput::Shape> shapes;
        for (unsigned int m = 0; m < solution.elastic.size(); ++m)
          shapes.push_back(shape(hk, m + 1, solution.elastic[m].phi));
        paraview->write_modes(shapes, c.rpm, "critical_modes", n_critical_files);
      }
    ++n_critical_files;
  }

  unsigned int
  HarmonicProblem::add_missing_partners(const unsigned int hk, std::vector<EigenPair> &modes) const
  {
    const auto         &h = operators->harmonic(hk);
    const BackwardError backward_error(operators->mass(hk), operators->damping(hk),
                                       operators->stiffness(hk));
    std::vector<EigenPair> added;
    for (unsigned int i = 0; i < modes.size(); ++i)
      {
        const auto near = [&](const unsigned int j) {
          return j < modes.size() &&
                 std::abs(modes[j].lambda - modes[i].lambda) <= 1e-7 * std::abs(modes[i].lambda);
        };
        if ((i > 0 && near(i - 1)) || near(i + 1))
          continue;
        EigenPair q;
        q.lambda         = modes[i].lambda;
        q.phi            = waves.turned(h, modes[i].phi);
        const double norm = std::sqrt(q.phi.re.norm_sqr() + q.phi.im.norm_sqr());
        if (!(norm > 0))
          continue;
        q.phi.re /= norm;
        q.phi.im /= norm;
        q.backward_error = backward_error(q.lambda, q.phi, q.m_phi);
        // (the turned mode of a rotationally symmetric system is exact: a
        // failed check means the mode was not one member of a doublet)
        if (q.backward_error <= eigensolver.backward_error_limit())
          added.push_back(std::move(q));
      }
    for (auto &q : added)
      modes.push_back(std::move(q));
    return added.size();
  }

  void
  HarmonicProblem::finish(Summary &summary) const
  {
    summary.add("model", "axisymmetric");
    for (unsigned int b = 0; b < meridian.bodies().size(); ++b)
      {
        const std::string key = "body." + meridian.bodies()[b].name + ".";
        summary.add(key + "mass_kg", system.mass.empty() ? 0. : system.mass[b]);
        summary.add(key + "polar_moment_kgm2", system.polar.empty() ? 0. : system.polar[b]);
      }
    if (history)
      history->add_to_summary(summary);
    if (assessment)
      assessment->add_to_summary(summary);
    summary.add("harmonic.meridian_cells", meridian.triangulation().n_active_cells());
    summary.add("harmonic.nodes", meridian.nodes().size());
    std::string list;
    for (const auto n : harmonics)
      list += (list.empty() ? "" : " ") + std::to_string(n);
    summary.add("harmonic.harmonics", list);
    for (const auto &h : harmonic_matrices())
      summary.add("harmonic." + std::to_string(h.n) + ".dofs", h.free.n_free);
    summary.add("static.factorizations", contact.n_factorizations());
    summary.add("static.speed_path",
                contact.path() == ContactSolver::Path::exact ? "exact" : "sampled");
    summary.add("eigen.modes_written", n_modes_written);
    summary.add("eigen.prestress_assemblies", operators ? operators->prestress_assemblies() : 0);
    summary.add("eigen.solves", eigen_solves);
    // ARPACK slots left unconverged are dropped, never reported as modes
    summary.add("eigen.unconverged_slots", unconverged_slots);
    summary.add("eigen.arnoldi_restarts", restarts);
    log << "Eigenproblem: " << eigen_solves << " full solves (of harmonics x speeds and root solves), "
        << std::setprecision(3) << factor_seconds << " s factorising, " << arnoldi_seconds
        << " s Arnoldi (back-substitutions included), " << check_seconds
        << " s backward errors, " << matrix_seconds << " s the speeds' matrices; " << restarts << " restarts, " << unconverged_slots
        << " slots unconverged\n" << std::setprecision(6);
    summary.add("eigen.reduced_solves", reduced_solves);
    if (reduced_settings.enabled() && spin_softening)
      log << "Reduced model: not used (with spin softening the static law is not affine in "
             "Omega^2: every solve full)\n";
    else if (reduced_settings.enabled())
      {
        log << "Reduced model: " << reduced_solves << " reduced solves (" << std::setprecision(3)
            << reduced_seconds << " s); full solves: " << anchors
            << " anchors (with their bases), " << transient_solves
            << " without a basis (first solve on a law of a fit opening ring by ring), "
            << anchor_seconds << " s with the bases and Gram matrices; " << refusals
            << " reduced solves refused (each then an anchor)\n"
            << std::setprecision(6);
        double worst = 0;
        for (const auto &r : reduced)
          worst = std::max(worst, r->worst_estimate);
        summary.add("eigen.anchors", anchors);
        summary.add("eigen.full_solves_without_basis", transient_solves);
        summary.add("eigen.reduced_refused", refusals);
        summary.add("eigen.reduced_worst_error_estimate", worst, 3);
        summary.add("eigen.sweep_worst_error_estimate", sweep_worst_estimate, 3);
      }
    summary.add("eigen.worst_backward_error", worst_backward_error, 12);
    if (response)
      summary.add("response.worst_backward_error",
                  harmonic_response ? harmonic_response->worst_backward_error() : 0., 3);
    summary.add("eigen.critical_speeds", n_critical);
    summary.add("eigen.critical_speeds_unsolved", n_unsolved);
    summary.add("eigen.root_solve_eigen_solves", root_solves);
    std::vector<StabilityOnset> all;
    for (const auto &o : onsets)
      all.insert(all.end(), o->list().begin(), o->list().end());
    summary.add("modal.stability_onsets", all.size());
    if (!all.empty())
      summary.add("modal.first_stability_onset_rpm",
                  std::min_element(all.begin(), all.end(), [](const auto &x, const auto &y) {
                    return x.rpm < y.rpm;
                  })->rpm);
    log << "Critical speeds: " << n_critical << " crossing(s) in critical_speeds.csv\n";
    summary.add("eigen.unconverged_modes", n_unconverged);
  }
} // namespace rotorfit
