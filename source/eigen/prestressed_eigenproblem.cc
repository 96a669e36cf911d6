#include <rotorfit/base/input_error.h>
#include <rotorfit/eigen/prestressed_eigenproblem.h>
#include <rotorfit/linear_algebra/matrix_pattern.h>
#include <rotorfit/linear_algebra/replicated_blocks.h>
#include <rotorfit/statics/speed_schedule.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <numeric>
#include <set>
#include <sstream>

// PrestressedEigenproblem, part 1: parameters, set-up, the matrices of a
// speed. Part 2 (the solve and what is set apart): prestressed_solve.cc.

namespace rotorfit
{
  using namespace dealii;

  PrestressedEigenproblem::PrestressedEigenproblem(const Discretization &model,
                                                   Log                  &log,
                                                   TimerOutput          &timer)
    : model(model)
    , log(log)
    , timer(timer)
    , comm(model.mpi_communicator())
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
    static_spin_softening = spin_softening;
    compute  = prm.get_bool("Compute modes");
    n_wanted = prm.get_integer("Number of modes");
    const std::string model_name = prm.get("Contact model");
    contact_model = model_name == "bonded"       ? ContactModel::bonded :
                    model_name == "frictionless" ? ContactModel::frictionless :
                    model_name == "fixed"        ? ContactModel::fixed :
                                                   ContactModel::frozen;
    contact_scale = prm.get_double("Contact penalty scale");
    const std::string s = prm.get("Stress stiffening");
    stiffening = s == "off"               ? StressStiffening::off :
                 s == "interference only" ? StressStiffening::interference :
                                            StressStiffening::full;
    rigid_threshold_hz = prm.get_double("Rigid-body threshold");
    convective_term    = prm.get_bool("Convective stiffness");
    self_check         = prm.get_bool("Self-check");
    prm.leave_subsection();

    // normal-only ties with pre-stress give spurious twist and tilt modes,
    // some unstable (doc/theory.md 7.4): refuse rather than plot them
    if (compute && contact_model == ContactModel::frictionless &&
        stiffening != StressStiffening::off)
      throw InputError(
        "Eigenproblem/Contact model = frictionless with Stress stiffening = '" +
        s + "' produces spurious twist and tilt modes (some unstable) because "
            "normal-only ties carry no contact geometric stiffness; use "
            "Contact model = bonded, or Stress stiffening = off.");
    if (compute && spin_softening && stiffening == StressStiffening::interference)
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
    const auto &fe          = dof_handler.get_fe();
    bearings.setup(model, log);

    body_of_dof.assign(dof_handler.n_dofs(), 0);
    std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        cell->get_dof_indices(dofs);
        for (const auto d : dofs)
          body_of_dof[d] = cell->material_id();
      }

    // one pattern for every matrix: cells, all pairs in all directions (any
    // contact model), bearing blocks; no static supports (doc/theory.md P7)
    DynamicSparsityPattern sparsity(dof_handler.n_dofs(), dof_handler.n_dofs(),
                                    model.locally_owned_dofs());
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        cell->get_dof_indices(dofs);
        for (const auto d : dofs)
          sparsity.add_entries(d, dofs.begin(), dofs.end());
      }
    for (const auto &p : model.pairs().pairs())
      {
        std::vector<types::global_dof_index> d(p.shaft_dofs.begin(), p.shaft_dofs.end());
        d.insert(d.end(), p.hub_dofs.begin(), p.hub_dofs.end());
        std::sort(d.begin(), d.end());
        for (const auto i : d)
          sparsity.add_entries(i, d.begin(), d.end(), true);
      }
    bearings.add_sparsity(sparsity);
    // M, G, K_theta and K_sigma couple each displacement component only with
    // itself: a third of the entries (58 -> 21 MB a matrix on TS's benchmark
    // mesh, and a third of the work of each product); C = Omega G + C_b
    // adds the bearing blocks
    DynamicSparsityPattern component(dof_handler.n_dofs(), dof_handler.n_dofs(),
                                     model.locally_owned_dofs());
    {
      const unsigned int        n = fe.n_dofs_per_cell();
      std::vector<unsigned int> comp(n);
      for (unsigned int i = 0; i < n; ++i)
        comp[i] = fe.system_to_component_index(i).first;
      std::vector<types::global_dof_index> same;
      for (const auto &cell : dof_handler.active_cell_iterators())
        {
          cell->get_dof_indices(dofs);
          for (unsigned int c = 0; c < fe.n_components(); ++c)
            {
              same.clear();
              for (unsigned int i = 0; i < n; ++i)
                if (comp[i] == c)
                  same.push_back(dofs[i]);
              std::sort(same.begin(), same.end());
              for (const auto d : same)
                component.add_entries(d, same.begin(), same.end(), true);
            }
        }
    }
    matrices.reinit(model.locally_owned_dofs(), sparsity, comm, &component);
    matrices.reinit_like(tangent);
    made_for = {};
    bearings.add_sparsity(component);
    damping.reinit(model.locally_owned_dofs(), model.locally_owned_dofs(), component, comm);
    // the bearing matrices on their stations' blocks alone (a subset of the
    // pattern above): not two more copies of the full pattern, and their
    // products and projections cost next to nothing
    {
      DynamicSparsityPattern stations(dof_handler.n_dofs(), dof_handler.n_dofs(),
                                      model.locally_owned_dofs());
      bearings.add_sparsity(stations);
      // and the diagonal: deal.II walks an empty row of a
      // DynamicSparsityPattern by searching ahead for the next entry, which
      // made this quadratic in the DOFs (4 s on TS's benchmark mesh)
      for (const auto i : model.locally_owned_dofs())
        stations.add(i, i);
      for (auto *m : {&bearing_k, &bearing_c})
        m->reinit(model.locally_owned_dofs(), model.locally_owned_dofs(), stations, comm);
    }

    // more modes than the model has
    std::vector<bool>  loose;
    const std::size_t  n_pairs = model.pairs().pairs().size();
    const unsigned int zeros   = expected_zero_modes(std::vector<bool>(n_pairs, true), loose);
    const std::size_t  nev     = 2 * n_wanted + 2 * zeros + 1;
    // the most eigenvalues a speed may ask for: every fit open (each body
    // its own rigid group), plus what a retry adds
    const unsigned int loose_zeros = expected_zero_modes(std::vector<bool>(n_pairs, false), loose);
    max_nev = 2 * n_wanted + 2 * std::max(zeros, loose_zeros) + 1 + 2 * n_wanted +
              (reduced.enabled() ? 2 * reduced.margin() : 0);
    if (nev + 3 > 2 * dof_handler.n_dofs())
      throw InputError("Eigenproblem/Number of modes = " + std::to_string(n_wanted) +
                       " needs " + std::to_string(nev) +
                       " eigenvalues, but the model has only " +
                       std::to_string(2 * dof_handler.n_dofs()) +
                       " (2 x DOFs); ask for fewer modes or refine the mesh.");

    log << "Eigenproblem: " << n_wanted << " modes per speed, contact model "
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
    matrices.assemble(model.dofs(), model.mesh().mapping(), model.mesh().cell_quadrature(), model.bodies());
    // K_theta enters only as K_t2 = K_sigma(u_C) - K_theta where every
    // state is affine: it is assembled into K_sigma(u_C) with it, and its
    // own matrix (58 MB on TS's benchmark mesh) is freed after the
    // self-check has taken what it needs of it
    convective_folded =
      stiffening == StressStiffening::full && convective_term && !static_spin_softening;
    if (self_check)
      {
        const auto fields = check_fields();
        const auto energy = [&](const Vector<double> &v) {
          Vector<double> Av;
          replicated_vmult(matrices.convective, v, Av);
          return v * Av;
        };
        check_theta_tilt  = energy(fields[0]);
        check_theta_twist = energy(fields[1]);
      }
    if (convective_folded)
      matrices.convective.clear();
  }

  unsigned int
  PrestressedEigenproblem::expected_zero_modes(const std::vector<bool> &tied,
                                    std::vector<bool>       &loose_body) const
  {
    const unsigned int n_bodies = model.bodies().size();
    std::vector<unsigned int> group(n_bodies);
    std::iota(group.begin(), group.end(), 0);
    const auto find = [&](unsigned int b) {
      while (group[b] != b)
        b = group[b];
      return b;
    };
    const auto        &list = model.pairs().pairs();
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
      if (!b.station.dof_x.empty())
        stations_of[find(body_of_dof[b.station.dof_x[0]])].insert(
          std::lround(b.station.z * 1e6));
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
    // normal-only ties leave relative axial sliding and twist (doc/theory.md 7.4)
    if (contact_model == ContactModel::frictionless)
      zeros += 2 * sliding_hubs.size();
    return zeros;
  }

  void
  PrestressedEigenproblem::assemble_tangent(const StaticState &state, const std::vector<bool> &tied)
  {
    TimerOutput::Scope t(timer, "eigen: tangent (K_sigma, ties, bearings)");
    ++tangent_serial;
    const double w = state.w(), omega = SpeedSchedule::rpm_to_rad_per_s(state.rpm);
    // on the last tangent's contact segment (the same ties, K_sigma parts
    // and bearing coefficients) only the speed's own share changes:
    // K_t += (w - w_t) K_t2, C += (Omega - Omega_t) G, two passes over a
    // pattern instead of six (a fifth of a reduced speed on TS)
    const bool same_segment =
      made_for.valid && tied == made_for.tied && !bearings.speed_dependent() &&
      (stiffening == StressStiffening::off ||
       (state.decomposition().affine && state.decomposition().serial == k_sigma_serial));
    if (same_segment)
      {
        if (stiffening == StressStiffening::full)
          {
            add_subset(tangent, w - made_for.w, k_sigma_C);
            if (convective_term && !convective_folded)
              add_subset(tangent, made_for.w - w, matrices.convective);
          }
        add_subset(damping, omega - made_for.omega, matrices.gyroscopic);
        made_for.w     = w;
        made_for.omega = omega;
        return;
      }
    made_for = {true, tied, w, omega};
    ++segment_serial;
    if (bearings.speed_dependent() || speeds_done == 0)
      {
        bearing_k = 0;
        bearing_c = 0;
        bearings.assemble(state.rpm, bearing_k, bearing_c);
      }

    // K_t = (K + K_sigma(u_I)) + K_b + K_c (+ w K_sigma(u_C) - w K_theta)
    if (stiffening != StressStiffening::off)
      update_stiffness(state);
    MatCopy(matrices.stiffness, tangent, SAME_NONZERO_PATTERN);
    add_subset(tangent, 1., bearing_k);
    if (stiffening == StressStiffening::full)
      {
        if (state.decomposition().affine)
          add_subset(tangent, w, k_sigma_C);
        if (convective_term && !convective_folded) // (folded: in k_sigma_C)
          add_subset(tangent, -w, matrices.convective);
      }
    add_contact_ties(state, tied);
    tangent.compress(VectorOperation::add);

    // C = C_b + Omega G
    damping = 0;
    add_subset(damping, omega, matrices.gyroscopic);
    add_subset(damping, 1., bearing_c);
  }

  void
  PrestressedEigenproblem::update_stiffness(const StaticState &state)
  {
    // matrices.stiffness holds K + K_sigma(u_s), u_s = stiffened_by (the
    // active set's u_I; with spin softening the whole u of the speed).
    // K_sigma is linear in u: a new static state adds K_sigma(u - u_s),
    // assembled in the tangent's storage (made afresh right after), so
    // K_sigma(u_I) needs no matrix of its own (58 MB on TS's benchmark mesh).
    // The sum collects the rounding of one addition per contact segment.
    const auto &decomposition = state.decomposition();
    if (decomposition.affine && decomposition.serial == k_sigma_serial)
      return;
    const auto    &dofs   = model.dofs();
    const IndexSet all    = complete_index_set(dofs.n_dofs());
    const auto    &owned  = model.locally_owned_dofs();
    PETScWrappers::MPI::Vector u(owned, all, comm), before(owned, all, comm);
    {
      PETScWrappers::MPI::Vector b(owned, comm);
      if (stiffened_by.size() > 0)
        for (const auto i : owned)
          b(i) = stiffened_by[i];
      b.compress(VectorOperation::insert);
      before = b;
    }
    const auto &mesh = model.mesh();
    if (decomposition.affine)
      {
        // K_sigma is linear in u = u_I + w u_C: two parts per active set
        PETScWrappers::MPI::Vector u_C(owned, all, comm);
        u   = decomposition.u_I;
        u_C = decomposition.u_C;
        matrices.assemble_stress_stiffness(dofs, mesh.mapping(), mesh.cell_quadrature(),
                                           model.bodies(), {&u, &u_C}, {&tangent, &k_sigma_C},
                                           {&before, nullptr}, {false, convective_folded});
        k_sigma_serial = decomposition.serial;
      }
    else
      {
        // the whole solution at this speed (the tangent is exact there)
        state.displacement(u);
        matrices.assemble_stress_stiffness(dofs, mesh.mapping(), mesh.cell_quadrature(),
                                           model.bodies(), {&u}, {&tangent}, {&before});
        k_sigma_serial = 0;
      }
    MatAXPY(matrices.stiffness, 1., tangent, SAME_NONZERO_PATTERN);
    stiffened_by.reinit(dofs.n_dofs());
    for (types::global_dof_index i = 0; i < dofs.n_dofs(); ++i)
      stiffened_by[i] = u[i];
  }

  void
  PrestressedEigenproblem::add_contact_ties(const StaticState &state, const std::vector<bool> &tied)
  {
    // on the locally owned rows; bonded: eps (u_h - u_s) in every
    // direction; frictionless: eps n n^T on the radial direction only
    const auto  &list        = model.pairs().pairs();
    const auto   range       = tangent.local_range();
    const bool   normal_only = contact_model == ContactModel::frictionless;
    for (unsigned int i = 0; i < list.size(); ++i)
      if (tied[i])
        {
          const auto  &p   = list[i];
          const double eps = tie_spring(state, i);
          for (unsigned int a = 0; a < 3; ++a)
            for (unsigned int c = 0; c < 3; ++c)
              {
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
  }

  bool
  PrestressedEigenproblem::tie_update(const StaticState                       &state,
                                      const std::vector<bool>                 &tied,
                                      std::vector<DirectSolver::UpdateColumn> &columns) const
  {
    columns.clear();
    const auto &solver = eigensolver.linear_solver();
    // (bearing coefficients that change with speed: S would lack their change)
    if (!solver.factorized() || solver.n_factorizations() != factor_ties.factorizations ||
        bearings.speed_dependent())
      return false;
    // a fit that lets go of its last tie frees a body (or the factorised
    // one had it free): its rigid motions then rest on sigma^2 M alone, some
    // 1e14 below the ties' springs, more than the Woodbury sum keeps (TS at
    // the loss of fit: no mode converged)
    const auto &pair_list = model.pairs();
    for (unsigned int f = 0; f < pair_list.n_interfaces(); ++f)
      {
        bool then = false, now = false;
        for (const unsigned int p : pair_list.pairs_of(f))
          then |= factor_ties.eps[p] > 0, now |= tied[p];
        if (then != now)
          return false;
      }
    // the springs add_contact_ties() puts in: eps n n^T on the radial
    // direction (frictionless), eps in every direction (bonded), on the
    // relative motion of the pair's hub and shaft nodes
    const auto &list        = model.pairs().pairs();
    const bool  normal_only = contact_model == ContactModel::frictionless;
    for (unsigned int i = 0; i < list.size(); ++i)
      {
        const double now    = tied[i] ? tie_spring(state, i) : 0.;
        const double spring = now - factor_ties.eps[i];
        if (spring == 0)
          continue;
        const auto &p = list[i];
        for (unsigned int d = 0; d < (normal_only ? 1u : 3u); ++d)
          {
            DirectSolver::UpdateColumn u;
            u.key    = 3 * i + d;
            u.spring = spring;
            for (unsigned int a = 0; a < 3; ++a)
              {
                const double v = normal_only ? (a < 2 ? p.normal[a] : 0.) : (a == d ? 1. : 0.);
                if (v != 0)
                  {
                    u.entries.emplace_back(p.hub_dofs[a], v);
                    u.entries.emplace_back(p.shaft_dofs[a], -v);
                  }
              }
            columns.push_back(std::move(u));
          }
        if (columns.size() > reduced.tie_update_limit())
          return false;
      }
    return !columns.empty();
  }
} // namespace rotorfit
