#include <rotorfit/base/format.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/harmonic/harmonic_problem.h>
#include <rotorfit/statics/speed_schedule.h>

#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>

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
  }

  void
  HarmonicProblem::setup(const Discretization &model, const Bearings &bearing_list)
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
    for (const auto &b : bearing_list.list())
      {
        Station s = b.station;
        meridian.station_weights(s);
        std::ostringstream m;
        m << std::setprecision(4) << "  " << s.owner << ": " << s.describe() << ": r "
          << s.radius * 1e3 << " mm, z " << s.z * 1e3 << " mm, area " << s.area * 1e6
          << " mm^2\n";
        log << m.str();
        stations.push_back(s);
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
          matrices.resize(harmonics.size());
          // (PETSc matrices cannot be moved: made in place)
          for (auto *p : {&petsc_m, &petsc_c, &petsc_k})
            *p = std::vector<PETScWrappers::MPI::SparseMatrix>(harmonics.size());
          for (unsigned int k = 0; k < harmonics.size(); ++k)
            {
              assembler->assemble_harmonic(harmonics[k], stations, matrices[k]);
              copy_to_petsc(matrices[k].M, petsc_m[k], comm);
              copy_to_petsc(matrices[k].K, petsc_c[k], comm);
              copy_to_petsc(matrices[k].K, petsc_k[k], comm);
            }
        }
    }
    log << "Mass properties (meridian, exact geometry):\n";
    for (unsigned int b = 0; b < meridian.bodies().size(); ++b)
      log << "  body " << meridian.bodies()[b].name << ": mass " << system.mass[b]
          << " kg, polar moment of inertia " << system.polar[b] << " kg m^2\n";
    for (const auto &h : matrices)
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
    contact_table.open(directory);
    opening_table.open(directory);
    if (contact.path() == ContactSolver::Path::exact)
      event_table.open(directory);
    if (compute_modes)
      campbell_table.open(directory);
  }

  const StaticState &
  HarmonicProblem::solve_speed(const unsigned int k, const double rpm)
  {
    state = StaticState::solve(contact, rpm, k, timer);
    for (const double f : state.contact.force)
      if (!std::isfinite(f))
        throw SolverFailure(rpm, "the static solve at " + format_number(rpm) +
                            " r/min gave a pair force that is not a number");
    history->record(state, state.decomposition(), contact.constraint_error_limit());
    contact_table.add(state);
    opening_table.add(state);
    event_table.add(state);
    if (compute_modes)
      {
        const auto modes = solve_modes(state);
        campbell_table.add(state, modes);
      }
    return state;
  }

  std::vector<HarmonicMode>
  HarmonicProblem::solve_modes(const StaticState &s)
  {
    const double omega = SpeedSchedule::rpm_to_rad_per_s(s.rpm);
    const double w     = omega * omega;
    // K_sigma of the law's two parts, once per law (doc/theory.md 2.3, 3); a
    // tangent law (spin softening) is not affine: its whole field at w
    const bool affine = s.decomposition().affine;
    if (prestress && (s.shared_law() != prestress_law || !affine))
      {
        TimerOutput::Scope         t(timer, "eigenproblem: K_sigma");
        PETScWrappers::MPI::Vector u0, u1;
        contact.displacement(s.decomposition(), affine ? 0. : w, u0);
        const Vector<double> u_I(u0);
        Vector<double>       u_C(u_I.size());
        if (affine && centrifugal_prestress)
          {
            contact.displacement(s.decomposition(), 1., u1);
            u_C = Vector<double>(u1);
            u_C -= u_I;
          }
        k_sigma_I.resize(matrices.size());
        k_sigma_C.resize(matrices.size());
        for (unsigned int k = 0; k < matrices.size(); ++k)
          {
            k_sigma_I[k] = std::make_unique<SparseMatrix<double>>();
            k_sigma_C[k] = std::make_unique<SparseMatrix<double>>();
            assembler->assemble_prestress(matrices[k], u_I, *k_sigma_I[k]);
            assembler->assemble_prestress(matrices[k], u_C, *k_sigma_C[k]);
            prestress_assemblies += 2;
          }
        prestress_law = s.shared_law();
      }
    // tie penalties from the radial stiffness of the two nodes (doc/theory.md 7.4)
    const auto         &pairs = meridian.pairs().pairs();
    std::vector<double> penalty(pairs.size());
    for (unsigned int i = 0; i < pairs.size(); ++i)
      penalty[i] = tie_scale * 0.5 *
                   (system.stiffness_diagonal[pairs[i].shaft_dofs[0]] +
                    system.stiffness_diagonal[pairs[i].hub_dofs[0]]);

    std::vector<HarmonicMode> result;
    for (unsigned int hk = 0; hk < matrices.size(); ++hk)
      {
        const auto &h = matrices[hk];
        std::unique_ptr<TimerOutput::Scope> phase =
          std::make_unique<TimerOutput::Scope>(timer, "eigenproblem: matrices of the speed");
        SparseMatrix<double> k(h.pattern), c(h.pattern);
        k.copy_from(h.K);
        if (prestress)
          {
            k.add(1., *k_sigma_I[hk]);
            if (affine && centrifugal_prestress)
              k.add(w, *k_sigma_C[hk]);
            if (centrifugal_prestress && convective)
              k.add(-w, h.K_theta);
          }
        assembler->add_ties(h, s.contact.active, penalty, k);
        c.copy_from(h.G);
        c *= omega;
        for (unsigned int b = 0; b < stations.size() && h.n == 1; ++b)
          {
            Bearings::Coefficients kb, cb;
            bearings->coefficients(b, s.rpm, kb, cb);
            // (row direction, column direction) -> coefficient index
            const unsigned int index[2][2] = {{0, 2}, {3, 1}};
            const std::vector<std::pair<unsigned int, double>> *a[2] = {&h.station_x[b],
                                                                         &h.station_y[b]};
            for (unsigned int p = 0; p < 2; ++p)
              for (unsigned int q = 0; q < 2; ++q)
                for (const auto &[I, wi] : *a[p])
                  for (const auto &[J, wj] : *a[q])
                    {
                      if (kb[index[p][q]] != 0)
                        k.add(I, J, kb[index[p][q]] * wi * wj);
                      if (cb[index[p][q]] != 0)
                        c.add(I, J, cb[index[p][q]] * wi * wj);
                    }
          }
        copy_values(c, petsc_c[hk]);
        copy_values(k, petsc_k[hk]);
        auto &pm = petsc_m[hk];
        auto &pc = petsc_c[hk];
        auto &pk = petsc_k[hk];
        // rigid motions on top of the modes wanted: axial translation and twist
        // (n = 0), translations and tilts (n = 1), of every body at most
        const unsigned int n_bodies = meridian.bodies().size();
        const unsigned int rigid    = h.n == 0 ? 2 * n_bodies : h.n == 1 ? 4 * n_bodies : 0;
        const unsigned int wanted   = std::min<unsigned int>(2 * (modes_per_harmonic + rigid),
                                                           h.free.n_free - 2);
        phase.reset();
        phase            = std::make_unique<TimerOutput::Scope>(timer, "eigenproblem: solve");
        auto pairs_found = eigensolver.solve(pm, pc, pk, wanted, statistics);
        phase.reset();
        unconverged_slots += statistics.unconverged_slots;
        restarts += statistics.iterations;
        factor_seconds += statistics.factorization_seconds;
        arnoldi_seconds += statistics.arnoldi_seconds;
        check_seconds += statistics.check_seconds;
        ++eigen_solves;

        std::vector<HarmonicMode> modes;
        for (auto &p : pairs_found)
          {
            worst_backward_error = std::max(worst_backward_error, p.backward_error);
            if (!(p.backward_error <= eigensolver.backward_error_limit()))
              {
                ++n_unconverged;
                std::ostringstream m;
                m << "harmonic " << h.n << " at " << format_number(s.rpm)
                  << " r/min: a mode at " << std::abs(p.lambda) / (2 * M_PI)
                  << " Hz has the backward error " << p.backward_error << " (limit "
                  << eigensolver.backward_error_limit() << ")";
                throw SolverFailure(s.rpm, m.str());
              }
            // rigid motions and overdamped (real) roots are not modes of the diagram
            if (std::abs(p.lambda) / (2 * M_PI) < rigid_threshold ||
                std::abs(p.lambda.imag()) <= 1e-9 * std::abs(p.lambda))
              continue;
            HarmonicMode mode;
            mode.harmonic         = h.n;
            mode.lambda           = p.lambda;
            mode.backward_error   = p.backward_error;
            mode.forward_fraction =
              h.n == 0 ? std::numeric_limits<double>::quiet_NaN() : forward_fraction(h, p.phi);
            // the 3D model's rule on the whirl ratio 2 f - 1 (doc/theory.md 9.2)
            const double ratio = 2 * mode.forward_fraction - 1;
            mode.travel        = h.n == 0      ? "-" :
                                 ratio >= 0.1  ? "forward" :
                                 ratio <= -0.1 ? "backward" :
                                                 "mixed";
            modes.push_back(mode);
          }
        std::sort(modes.begin(), modes.end(), [](const HarmonicMode &a, const HarmonicMode &b) {
          return a.lambda.imag() < b.lambda.imag();
        });
        // a degenerate pair (at rest on isotropic bearings) is one standing
        // wave twice, any mix of the two travelling ones: backward first,
        // then forward, as the 3D model lists a doublet at rest
        for (unsigned int i = 0; h.n > 0 && i + 1 < modes.size(); ++i)
          if (std::abs(modes[i + 1].lambda - modes[i].lambda) <= 1e-7 * std::abs(modes[i].lambda))
            {
              modes[i].travel     = "backward";
              modes[i + 1].travel = "forward";
              ++i;
            }
        for (auto &m : modes)
          m.whirl = h.n == 1 ? m.travel : "non-lateral";
        if (modes.size() > modes_per_harmonic)
          modes.resize(modes_per_harmonic);
        for (unsigned int i = 0; i < modes.size(); ++i)
          modes[i].index = i + 1;
        n_modes_written += modes.size();
        result.insert(result.end(), modes.begin(), modes.end());
      }
    return result;
  }

  double
  HarmonicProblem::forward_fraction(const HarmonicAssembler::Harmonic &h,
                                    const ComplexVector               &phi) const
  {
    // per node the cos and sin coefficients (C, S) of u_r, u_t, u_z; a wave
    // travelling forward has S = -i C: |C + i S|^2 forward, |C - i S|^2 backward
    std::vector<std::complex<double>> value(meridian.dofs().n_dofs());
    for (unsigned int I = 0; I < h.free.n_free; ++I)
      value[h.free.dof[I]] = {phi.re[I], phi.im[I]};
    const auto at = [&](const types::global_dof_index dof) { return value[dof]; };
    const std::complex<double> i(0., 1.);
    double                     forward = 0, backward = 0;
    for (const auto &node : meridian.nodes())
      {
        const std::complex<double> C[3] = {at(node[FourierBasis::a]), at(node[FourierBasis::c]),
                                           at(node[FourierBasis::e])};
        const std::complex<double> S[3] = {at(node[FourierBasis::b]), -at(node[FourierBasis::d]),
                                           at(node[FourierBasis::f])};
        for (unsigned int k = 0; k < 3; ++k)
          {
            forward += std::norm(C[k] + i * S[k]);
            backward += std::norm(C[k] - i * S[k]);
          }
      }
    return forward + backward > 0 ? forward / (forward + backward) : 0.5;
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
    summary.add("harmonic.meridian_cells", meridian.triangulation().n_active_cells());
    summary.add("harmonic.nodes", meridian.nodes().size());
    std::string list;
    for (const auto n : harmonics)
      list += (list.empty() ? "" : " ") + std::to_string(n);
    summary.add("harmonic.harmonics", list);
    for (const auto &h : matrices)
      summary.add("harmonic." + std::to_string(h.n) + ".dofs", h.free.n_free);
    summary.add("static.factorizations", contact.n_factorizations());
    summary.add("static.speed_path",
                contact.path() == ContactSolver::Path::exact ? "exact" : "sampled");
    summary.add("eigen.modes_written", n_modes_written);
    summary.add("eigen.prestress_assemblies", prestress_assemblies);
    summary.add("eigen.solves", eigen_solves);
    // ARPACK slots left unconverged are dropped, never reported as modes
    summary.add("eigen.unconverged_slots", unconverged_slots);
    summary.add("eigen.arnoldi_restarts", restarts);
    log << "Eigenproblem: " << eigen_solves << " solves (harmonics x speeds), "
        << std::setprecision(3) << factor_seconds << " s factorising, " << arnoldi_seconds
        << " s Arnoldi (back-substitutions included), " << check_seconds
        << " s backward errors; " << restarts << " restarts, " << unconverged_slots
        << " slots unconverged\n" << std::setprecision(6);
    summary.add("eigen.worst_backward_error", worst_backward_error, 12);
    summary.add("eigen.unconverged_modes", n_unconverged);
  }
} // namespace rotorfit
