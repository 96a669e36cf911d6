#include <rotorfit/base/input_error.h>
#include <rotorfit/eigen/modal_problem.h>
#include <rotorfit/statics/speed_schedule.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/utilities.h>

#include <deal.II/fe/fe_values.h>

#include <deal.II/lac/dynamic_sparsity_pattern.h>

#include <functional>

#include <deal.II/numerics/data_out.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <map>
#include <numeric>
#include <set>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

  ModalProblem::ModalProblem(StaticProblem &statics, Log &log)
    : statics(statics)
    , log(log)
    , comm(statics.mpi_communicator())
    , root(Utilities::MPI::this_mpi_process(statics.mpi_communicator()) == 0)
  {}

  void
  ModalProblem::declare_parameters(ParameterHandler &prm)
  {
    Bearings::declare_list(prm);
    DampedEigensolver::declare_parameters(prm);
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
                      "rigid tilt: both or neither, THEORY 4.3).");
    prm.declare_entry("Convective stiffness",
                      "true",
                      Patterns::Bool(),
                      "With centrifugal stress stiffening, add -Omega^2 K_theta. "
                      "'false' only to reproduce codes that add K_sigma alone in "
                      "the stationary frame: that stiffens rigid tilt by "
                      "Omega^2 Ip/2 and twist by Omega^2 Ip (THEORY 4.5, P2).");
    prm.declare_entry("Rigid-body threshold",
                      "1",
                      Patterns::Double(0.),
                      "Modes with |lambda| / 2 pi below this [Hz] are rigid-body "
                      "modes (or modes of a loose body): listed in "
                      "rigid_modes.csv, never plotted.");
    prm.declare_entry("Whirl stations",
                      "10",
                      Patterns::Integer(1),
                      "Axial slices whose mass-averaged lateral motion decides "
                      "forward / backward whirl.");
    prm.declare_entry("MAC threshold",
                      "0.8",
                      Patterns::Double(0., 1.),
                      "Least mass-weighted MAC for a mode to continue a line "
                      "of the previous speed.");
    prm.declare_entry("Excitation orders",
                      "1",
                      Patterns::List(Patterns::Integer(1)),
                      "Orders k of the k X lines whose crossings are critical "
                      "speeds.");
    prm.declare_entry("Write mode shapes",
                      "true",
                      Patterns::Bool(),
                      "One .pvtu per speed with every elastic mode (real and "
                      "imaginary parts) and the tied pairs, indexed by modes.pvd.");
    prm.declare_entry("Self-check",
                      "false",
                      Patterns::Bool(),
                      "At the first speed > 0, check the virial identity of "
                      "K_sigma on rigid tilt and twist and the tilt "
                      "cancellation with Omega^2 K_theta (THEORY 10e); values "
                      "in the log and summary.txt.");
    prm.declare_entry("Campbell plot",
                      "true",
                      Patterns::Bool(),
                      "Draw campbell.png at the end of the run (python3 + "
                      "matplotlib).");
    prm.leave_subsection();
  }

  void
  ModalProblem::parse_parameters(ParameterHandler  &prm,
                                 const std::string &prm_directory)
  {
    bearings.parse_parameters(prm, prm_directory);
    eigensolver.parse_parameters(prm);
    prm.enter_subsection("Eigenproblem");
    compute = prm.get_bool("Compute modes");
    n_modes = prm.get_integer("Number of modes");
    const std::string model = prm.get("Contact model");
    contact_model = model == "bonded"       ? ContactModel::bonded :
                    model == "frictionless" ? ContactModel::frictionless :
                    model == "fixed"        ? ContactModel::fixed :
                                              ContactModel::frozen;
    contact_scale = prm.get_double("Contact penalty scale");
    const std::string s = prm.get("Stress stiffening");
    stiffening = s == "off"                 ? StressStiffening::off :
                 s == "interference only"   ? StressStiffening::interference :
                                              StressStiffening::full;
    rigid_threshold_hz = prm.get_double("Rigid-body threshold");
    convective_term    = prm.get_bool("Convective stiffness");
    n_stations         = prm.get_integer("Whirl stations");
    mac_threshold      = prm.get_double("MAC threshold");
    orders.clear();
    check_unique(Utilities::split_string_list(prm.get("Excitation orders"), ','),
                 "Eigenproblem/Excitation orders");
    for (const auto &o : Utilities::split_string_list(prm.get("Excitation orders"), ','))
      orders.push_back(Utilities::string_to_int(o));
    write_shapes = prm.get_bool("Write mode shapes");
    plot         = prm.get_bool("Campbell plot");
    self_check   = prm.get_bool("Self-check");
    prm.leave_subsection();

    if (!(contact_scale > 0))
      throw InputError("Eigenproblem/Contact penalty scale = " +
                       std::to_string(contact_scale) + " must be > 0.");
    // normal-only ties with pre-stress give spurious twist and tilt modes,
    // some unstable (THEORY, correction 3): refuse rather than plot them
    if (compute && contact_model == ContactModel::frictionless &&
        stiffening != StressStiffening::off)
      throw InputError(
        "Eigenproblem/Contact model = frictionless with Stress stiffening = '" +
        s + "' produces spurious twist and tilt modes (some unstable) because "
            "normal-only ties carry no contact geometric stiffness; use "
            "Contact model = bonded, or Stress stiffening = off.");
    if (compute && statics.spin_softening_on() && stiffening == StressStiffening::interference)
      throw InputError("Eigenproblem/Stress stiffening = interference only needs "
                       "Physics/Spin softening = false (with spin softening "
                       "the static solution does not split into interference "
                       "and centrifugal parts).");
  }

  void
  ModalProblem::setup()
  {
    if (!compute)
      return;
    const auto &dof_handler = statics.dofs();
    const auto &mesh        = statics.assembly_mesh();
    const auto &fe          = dof_handler.get_fe();
    const auto &owned       = statics.locally_owned_dofs();
    bearings.setup(mesh, dof_handler);

    body_of_dof.assign(dof_handler.n_dofs(), 0);
    std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        cell->get_dof_indices(dofs);
        for (const auto d : dofs)
          body_of_dof[d] = cell->material_id();
      }

    // one pattern for every matrix: cells, all pairs in all directions (any
    // contact model), bearing blocks; no static supports (THEORY P7)
    DynamicSparsityPattern &dsp = sparsity;
    dsp.reinit(dof_handler.n_dofs(), dof_handler.n_dofs(), owned);
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        cell->get_dof_indices(dofs);
        for (const auto d : dofs)
          dsp.add_entries(d, dofs.begin(), dofs.end());
      }
    for (const auto &p : statics.contact_pairs().pairs())
      {
        std::vector<types::global_dof_index> d(p.shaft_dofs.begin(), p.shaft_dofs.end());
        d.insert(d.end(), p.hub_dofs.begin(), p.hub_dofs.end());
        std::sort(d.begin(), d.end());
        for (const auto i : d)
          dsp.add_entries(i, d.begin(), d.end(), true);
      }
    bearings.add_sparsity(dsp);
    matrices.reinit(owned, dsp, comm);
    for (auto *m : {&bearing_k, &bearing_c, &tangent, &damping, &shifted})
      matrices.reinit_like(*m);

    // whirl stations: mass-averaged lateral displacement of axial slices
    double z_min = std::numeric_limits<double>::max(), z_max = -z_min;
    for (const auto &p : statics.dof_support_points())
      {
        z_min = std::min(z_min, p[2]);
        z_max = std::max(z_max, p[2]);
      }
    const QGaussSimplex<3> quadrature(fe.degree + 2);
    FEValues<3>            fe_values(mesh.mapping(), fe, quadrature,
                          update_values | update_quadrature_points | update_JxW_values);
    std::vector<std::map<types::global_dof_index, std::pair<types::global_dof_index, double>>>
                        weights(n_stations);
    std::vector<double> slice_mass(n_stations, 0.);
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        fe_values.reinit(cell);
        cell->get_dof_indices(dofs);
        const double rho = statics.body_list()[cell->material_id()].density;
        for (unsigned int q = 0; q < quadrature.size(); ++q)
          {
            const double z = fe_values.quadrature_point(q)[2];
            const unsigned int k = std::min<unsigned int>(
              n_stations - 1, (z - z_min) / (z_max - z_min) * n_stations);
            slice_mass[k] += rho * fe_values.JxW(q);
            for (unsigned int i = 0; i < dofs.size(); ++i)
              if (fe.system_to_component_index(i).first == 0)
                {
                  auto &e = weights[k][dofs[i]];
                  e.first = dofs[fe.component_to_system_index(
                    1, fe.system_to_component_index(i).second)];
                  e.second += rho * fe_values.shape_value(i, q) * fe_values.JxW(q);
                }
          }
      }
    stations.assign(n_stations, {});
    for (unsigned int k = 0; k < n_stations; ++k)
      for (const auto &[dx, e] : weights[k])
        if (slice_mass[k] > 0)
          stations[k].push_back({dx, e.first, e.second / slice_mass[k]});

    // more modes than the model has
    std::vector<bool>  loose;
    const unsigned int zeros =
      expected_zero_modes(std::vector<bool>(statics.contact_pairs().pairs().size(), true), loose);
    const std::size_t nev = 2 * n_modes + 2 * zeros + 1;
    // the most eigenvalues a speed may ask for: every fit open (each body
    // its own rigid group), plus what a retry adds
    const unsigned int loose_zeros =
      expected_zero_modes(std::vector<bool>(statics.contact_pairs().pairs().size(), false), loose);
    max_nev = 2 * n_modes + 2 * std::max(zeros, loose_zeros) + 1 + 2 * n_modes;
    if (nev + 3 > 2 * dof_handler.n_dofs())
      throw InputError("Eigenproblem/Number of modes = " + std::to_string(n_modes) +
                       " needs " + std::to_string(nev) +
                       " eigenvalues, but the model has only " +
                       std::to_string(2 * dof_handler.n_dofs()) +
                       " (2 x DOFs); ask for fewer modes or refine the mesh.");

    log << "Eigenproblem: " << n_modes << " modes per speed, contact model "
        << (contact_model == ContactModel::bonded       ? "bonded" :
            contact_model == ContactModel::frictionless ? "frictionless" :
            contact_model == ContactModel::fixed        ? "fixed" : "frozen")
        << (convective_term ? "" : ", NO convective stiffness (K_sigma alone, for comparison)")
        << ", stress stiffening "
        << (stiffening == StressStiffening::off          ? "off" :
            stiffening == StressStiffening::interference ? "interference only" :
                                                           "interference + centrifugal")
        << ", shift " << eigensolver.shift() / (2 * M_PI) << " Hz, "
        << bearings.size() << " bearing(s)\n";
    for (const auto &b : bearings.list())
      log << "  bearing " << b.name << " on " << b.surface << ": area "
          << b.area * 1e6 << " mm^2 at z = " << b.z << " m, " << b.weight.size()
          << " weighted nodes, kxx " << b.k[0] << " N/m, cxx " << b.c[0]
          << " N s/m" << (b.table.empty() ? "" : " (speed table " + b.table_file + ")")
          << '\n';
  }

  void
  ModalProblem::assemble_constant_matrices()
  {
    TimerOutput::Scope t(statics.timer_output(), "eigen: assembly (M, K, G, K_theta)");
    matrices.assemble(statics.dofs(), statics.assembly_mesh().mapping(), statics.body_list());
    campbell.open(statics.output_directory(), root, orders, mac_threshold);
    if (root)
      {
        std::ofstream rigid(statics.output_directory() + "/rigid_modes.csv");
        rigid << "speed_rpm,kind,body,real_part_per_s,frequency_hz,backward_error\n";
      }
  }

  unsigned int
  ModalProblem::expected_zero_modes(const std::vector<bool> &tied,
                                    std::vector<bool>       &loose_body) const
  {
    const unsigned int n_bodies = statics.body_list().size();
    std::vector<unsigned int> group(n_bodies);
    std::iota(group.begin(), group.end(), 0);
    const auto find = [&](unsigned int b) {
      while (group[b] != b)
        b = group[b];
      return b;
    };
    const auto        &list = statics.contact_pairs().pairs();
    std::set<unsigned int> sliding_hubs;
    for (unsigned int i = 0; i < list.size(); ++i)
      if (tied[i])
        {
          const unsigned int s = body_of_dof[list[i].shaft_dofs[0]],
                             h = body_of_dof[list[i].hub_dofs[0]];
          group[find(h)] = find(s);
          sliding_hubs.insert(h);
        }
    // distinct bearing stations per group decide which rigid motions remain
    std::map<unsigned int, std::set<long>> stations_of;
    for (const auto &b : bearings.list())
      if (!b.dof_x.empty())
        stations_of[find(body_of_dof[b.dof_x[0]])].insert(std::lround(b.z * 1e6));
    unsigned int main = find(0), best = 0;
    for (const auto &[g, s] : stations_of)
      if (s.size() > best)
        {
          best = s.size();
          main = g;
        }
    unsigned int zeros = 0;
    std::set<unsigned int> groups;
    loose_body.assign(n_bodies, false);
    for (unsigned int b = 0; b < n_bodies; ++b)
      {
        groups.insert(find(b));
        loose_body[b] = !stations_of.empty() && find(b) != main;
      }
    for (const auto g : groups)
      {
        const std::size_t n = stations_of.count(g) ? stations_of[g].size() : 0;
        zeros += n == 0 ? 6 : n == 1 ? 4 : 2; // axial and twist always free
      }
    // normal-only ties leave relative axial sliding and twist (THEORY 7.4)
    if (contact_model == ContactModel::frictionless)
      zeros += 2 * sliding_hubs.size();
    return zeros;
  }

  void
  ModalProblem::assemble_tangent(const double rpm, const std::vector<bool> &tied)
  {
    const double omega = SpeedSchedule::rpm_to_rad_per_s(rpm), w = omega * omega;
    const auto  &decomposition = statics.contact_solver().decomposition();

    if (bearings.speed_dependent() || speeds_done == 0)
      {
        bearing_k = 0;
        bearing_c = 0;
        bearings.assemble(rpm, bearing_k, bearing_c);
      }

    // K_t = K + K_b + K_c (+ K_sigma (- Omega^2 K_theta))
    MatCopy(matrices.stiffness, tangent, SAME_NONZERO_PATTERN);
    MatAXPY(tangent, 1., bearing_k, SAME_NONZERO_PATTERN);
    if (stiffening != StressStiffening::off)
      {
        const auto &dofs    = statics.dofs();
        const auto &mapping = statics.assembly_mesh().mapping();
        const auto &bodies  = statics.body_list();
        const IndexSet all  = complete_index_set(dofs.n_dofs());
        PETScWrappers::MPI::Vector u(statics.locally_owned_dofs(), all, comm);
        if (decomposition.affine)
          {
            // K_sigma is linear in u = u_I + w u_C: two parts per active set
            if (decomposition.serial != k_sigma_serial)
              {
                u = decomposition.u_I;
                matrices.assemble_stress_stiffness(dofs, mapping, bodies, u, k_sigma_I);
                u = decomposition.u_C;
                matrices.assemble_stress_stiffness(dofs, mapping, bodies, u, k_sigma_C);
                k_sigma_serial = decomposition.serial;
              }
            MatAXPY(tangent, 1., k_sigma_I, SAME_NONZERO_PATTERN);
            if (stiffening == StressStiffening::full)
              MatAXPY(tangent, w, k_sigma_C, SAME_NONZERO_PATTERN);
          }
        else
          {
            // the whole solution at this speed (the tangent is exact there)
            statics.contact_solver().displacement(w, u);
            matrices.assemble_stress_stiffness(dofs, mapping, bodies, u, k_sigma_I);
            k_sigma_serial = 0;
            MatAXPY(tangent, 1., k_sigma_I, SAME_NONZERO_PATTERN);
          }
        if (stiffening == StressStiffening::full && convective_term)
          MatAXPY(tangent, -w, matrices.convective, SAME_NONZERO_PATTERN);
      }

    // contact ties on the locally owned rows
    const auto  &list   = statics.contact_pairs().pairs();
    const auto  &solver = statics.contact_solver();
    const double scale  = contact_scale / solver.penalty_scale();
    const auto   range  = tangent.local_range();
    const bool   normal_only = contact_model == ContactModel::frictionless;
    for (unsigned int i = 0; i < list.size(); ++i)
      if (tied[i])
        {
          const auto  &p   = list[i];
          const double eps = solver.penalty(i) * scale;
          for (unsigned int a = 0; a < 3; ++a)
            for (unsigned int c = 0; c < 3; ++c)
              {
                // bonded: eps (u_h - u_s) in every direction; frictionless:
                // eps n n^T on the radial direction only
                double k = normal_only ? (a < 2 && c < 2 ? p.normal[a] * p.normal[c] : 0.) :
                                         (a == c ? 1. : 0.);
                if (k == 0)
                  continue;
                k *= eps;
                const std::pair<types::global_dof_index, double> rows[2] = {
                  {p.hub_dofs[a], 1.}, {p.shaft_dofs[a], -1.}};
                const std::pair<types::global_dof_index, double> cols[2] = {
                  {p.hub_dofs[c], 1.}, {p.shaft_dofs[c], -1.}};
                for (const auto &[r, sr] : rows)
                  if (r >= range.first && r < range.second)
                    for (const auto &[col, sc] : cols)
                      tangent.add(r, col, sr * sc * k);
              }
        }
    tangent.compress(VectorOperation::add);

    // C = C_b + Omega G
    MatCopy(bearing_c, damping, SAME_NONZERO_PATTERN);
    MatAXPY(damping, omega, matrices.gyroscopic, SAME_NONZERO_PATTERN);
  }

  void
  ModalProblem::solve_speed(const unsigned int          step,
                            const double                rpm,
                            const ContactSolver::State &state)
  {
    if (!compute)
      return;
    if (speeds_done == 0)
      assemble_constant_matrices();
    const auto &list = statics.contact_pairs().pairs();

    // which pairs the eigenproblem ties
    std::vector<bool> tied;
    switch (contact_model)
      {
        case ContactModel::bonded:
        case ContactModel::frictionless:
          tied = state.active;
          break;
        case ContactModel::fixed:
          tied.assign(list.size(), true);
          break;
        case ContactModel::frozen:
          if (frozen_active.empty())
            frozen_active = state.active;
          tied = frozen_active;
          break;
      }

    {
      TimerOutput::Scope t(statics.timer_output(), "eigen: tangent (K_sigma, ties, bearings)");
      assemble_tangent(rpm, tied);
    }
    if (self_check && checks.empty() && rpm > 0)
      matrix_checks(rpm);
    std::vector<bool>  loose_body;
    const unsigned int zeros = expected_zero_modes(tied, loose_body);
    unsigned int       nev   = 2 * n_modes + 2 * zeros + 1;

    const auto &bodies = statics.body_list();
    std::vector<WhirlMode>   elastic;
    std::vector<std::string> rigid_rows;
    unsigned int             n_rigid = 0, n_loose = 0, n_overdamped = 0, unconverged = 0;
    double                   worst   = 0;
    DampedEigensolver::Statistics stats;
    // a second attempt on the same factorisation with twice the Krylov
    // space and restarts (and room for the modes that were missing); then
    // the run stops: a Campbell diagram with a missing line is wrong
    for (unsigned int attempt = 0;; ++attempt)
      {
        std::vector<EigenPair> pairs;
        {
          TimerOutput::Scope t(statics.timer_output(), "eigen: factorisation + ARPACK");
          pairs = eigensolver.solve(matrices.mass, damping, tangent, shifted, nev, stats, attempt);
        }
        TimerOutput::Scope t(statics.timer_output(), "eigen: post-processing + output");
        elastic.clear();
        rigid_rows.clear();
        n_rigid = n_loose = n_overdamped = 0;
        unconverged = stats.unconverged_slots;
        worst       = 0;
        for (auto &p : pairs)
          {
            if (std::isnan(p.backward_error) ||
                (!std::isnan(worst) && p.backward_error > worst)) // NaN sticks
              worst = p.backward_error;
            if (!(p.backward_error <= eigensolver.backward_error_limit()))
              {
                ++unconverged;
                continue;
              }
            WhirlMode m;
            m.lambda         = p.lambda;
            m.backward_error = p.backward_error;
            m.m_phi          = std::move(p.m_phi);
            // kinetic energy share per body: M is block diagonal by body
            std::vector<double> energy(bodies.size(), 0.);
            for (std::size_t i = 0; i < p.phi.re.size(); ++i)
              energy[body_of_dof[i]] += p.phi.re[i] * m.m_phi.re[i] + p.phi.im[i] * m.m_phi.im[i];
            const double total = std::accumulate(energy.begin(), energy.end(), 0.);
            const unsigned int dominant =
              std::max_element(energy.begin(), energy.end()) - energy.begin();
            const bool in_loose_body = loose_body[dominant] && energy[dominant] > 0.9 * total;
            const bool rigid_mode = std::abs(p.lambda) < 2 * M_PI * rigid_threshold_hz;
            const bool real_mode  = p.lambda.imag() == 0;
            if (rigid_mode || real_mode || in_loose_body)
              {
                const std::string kind = in_loose_body ? "loose" : rigid_mode ? "rigid" : "overdamped";
                // counted as state-space eigenvalues: a rigid motion is a
                // double zero that round-off splits into a tiny conjugate
                // pair (one row) or two tiny real values (two rows)
                (in_loose_body ? n_loose : rigid_mode ? n_rigid : n_overdamped) +=
                  (p.lambda.imag() != 0 ? 2 : 1);
                std::ostringstream row;
                row << std::setprecision(10) << rpm << ',' << kind << ','
                    << (in_loose_body ? bodies[dominant].name : "assembly") << ','
                    << p.lambda.real() << ',' << p.lambda.imag() / (2 * M_PI) << ','
                    << p.backward_error << '\n';
                rigid_rows.push_back(row.str());
                continue;
              }
            m.phi = std::move(p.phi);
            elastic.push_back(std::move(m));
          }
        const bool complete = unconverged == 0 && elastic.size() >= n_modes;
        if (complete)
          break;
        std::ostringstream m;
        m << "at " << rpm << " r/min: " << elastic.size() << " elastic modes converged ("
          << n_modes << " wanted; " << stats.unconverged_slots
          << " ARPACK slots unconverged, " << unconverged - stats.unconverged_slots
          << " eigenpairs with a backward error above Eigenproblem/Backward error limit = "
          << eigensolver.backward_error_limit() << ", worst " << std::setprecision(3) << worst
          << "; " << n_rigid << " rigid, " << n_loose << " loose-body, " << n_overdamped
          << " overdamped) with " << stats.requested << " eigenvalues, Krylov size "
          << stats.krylov_size << ", at most " << stats.max_restarts << " restarts";
        const unsigned int more = 2 * (n_modes - std::min<unsigned int>(n_modes, elastic.size()));
        if (attempt == 0 && nev + more + 3 <= 2 * statics.dofs().n_dofs())
          {
            nev += more;
            ++retried_speeds;
            log << "  eigen: retry " << m.str() << "; again with twice the Krylov space\n";
            continue;
          }
        throw SolverFailure(rpm,
                            "the eigensolver did not converge " + m.str() +
                              (attempt > 0 ? " (after one retry with twice the Krylov space)" :
                                             " (no retry: the model has too few DOFs for more "
                                             "eigenvalues)") +
                              "; raise Eigenproblem/Maximum restarts or Krylov size factor, or "
                              "move the Shift");
      }
    if (root)
      {
        std::ofstream rigid(statics.output_directory() + "/rigid_modes.csv", std::ios::app);
        for (const auto &row : rigid_rows)
          rigid << row;
      }

    std::ostringstream line;
    line << "  eigen: " << elastic.size() << " whirl modes";
    if (!elastic.empty())
      line << " " << std::setprecision(5) << elastic.front().frequency_hz() << " .. "
           << elastic.back().frequency_hz() << " Hz";
    line << ", " << n_rigid << " rigid, " << n_loose << " loose-body, " << n_overdamped
         << " overdamped (state-space eigenvalues); nev " << stats.requested << ", Krylov " << stats.krylov_size
         << ", " << stats.iterations << " restarts, " << stats.operator_applications
         << " solves, max backward error " << std::setprecision(2) << worst
         << "; " << std::setprecision(3) << stats.factorization_seconds << " s LU, "
         << stats.arnoldi_seconds << " s Arnoldi (" << stats.solve_seconds
         << " s back-substitutions), " << stats.check_seconds << " s checks\n";
    log << line.str();
    if (elastic.size() > n_modes)
      elastic.resize(n_modes);

    separate_degenerate_pairs(elastic);
    for (auto &m : elastic)
      classify_whirl(m);

    // fit state of the speed: closed / partial / open (any interface)
    std::string fit_state = "closed";
    for (unsigned int f = 0; f < statics.contact_pairs().n_interfaces(); ++f)
      {
        unsigned int closed = 0;
        const auto  &ids    = statics.contact_pairs().pairs_of(f);
        for (const auto i : ids)
          closed += state.active[i] ? 1 : 0;
        if (closed == 0)
          fit_state = "open";
        else if (closed < ids.size() && fit_state == "closed")
          fit_state = "partial";
      }
    if (fit_state == "open" && contact_model != ContactModel::fixed &&
        contact_model != ContactModel::frozen && !announced_loose)
      {
        announced_loose = true;
        std::string names;
        for (unsigned int b = 0; b < bodies.size(); ++b)
          if (loose_body[b])
            names += (names.empty() ? "" : ", ") + bodies[b].name;
        log << "  note: a fit is fully open at " << rpm << " r/min: "
            << (names.empty() ? "the assembly falls apart" : "body " + names + " is loose")
            << "; from here on the whirl lines are not assembly modes (fit_state = "
               "open in campbell.csv), loose-body modes go to rigid_modes.csv\n";
      }
    campbell.add_speed(rpm, elastic, fit_state, state.converged, state.asymmetry);
    if (write_shapes)
      write_modes(step, rpm, elastic, tied);
    worst_backward_error = std::max(worst_backward_error, worst);
    ++speeds_done;
  }

} // namespace rotorfit
