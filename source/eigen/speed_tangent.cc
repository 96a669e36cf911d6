#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/linear_algebra/replicated_blocks.h>
#include <rotorfit/eigen/speed_tangent.h>
#include <rotorfit/linear_algebra/matrix_pattern.h>
#include <rotorfit/statics/speed_schedule.h>

#include <deal.II/lac/dynamic_sparsity_pattern.h>

#include <algorithm>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    /// One pattern for every matrix: cells, all pairs in all directions (any
    /// contact model), bearing blocks; no static supports (doc/theory.md P7).
    DynamicSparsityPattern
    full_pattern(const Discretization &model, const Bearings &bearings)
    {
      const auto &dof_handler = model.dofs();
      std::vector<types::global_dof_index> dofs(dof_handler.get_fe().n_dofs_per_cell());
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
      return sparsity;
    }

    /// M, G, K_theta and K_sigma couple each displacement component only with
    /// itself: a third of the entries (58 -> 21 MB a matrix on TS's benchmark
    /// mesh, and a third of the work of each product).
    DynamicSparsityPattern
    component_pattern(const Discretization &model)
    {
      const auto &dof_handler = model.dofs();
      const auto &fe          = dof_handler.get_fe();
      DynamicSparsityPattern component(dof_handler.n_dofs(), dof_handler.n_dofs(),
                                       model.locally_owned_dofs());
      const unsigned int        n = fe.n_dofs_per_cell();
      std::vector<unsigned int> comp(n);
      for (unsigned int i = 0; i < n; ++i)
        comp[i] = fe.system_to_component_index(i).first;
      std::vector<types::global_dof_index> dofs(n), same;
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
      return component;
    }
  } // namespace

  SpeedTangent::SpeedTangent(const Discretization &model,
                             const Bearings       &bearings,
                             TimerOutput          &timer)
    : model(model)
    , bearings(bearings)
    , timer(timer)
    , comm(model.mpi_communicator())
  {}

  void
  SpeedTangent::setup()
  {
    const DynamicSparsityPattern sparsity  = full_pattern(model, bearings);
    DynamicSparsityPattern       component = component_pattern(model);
    matrices.reinit(model.locally_owned_dofs(), sparsity, comm, &component);
    matrices.reinit_like(tangent);
    made_for.reset();
    // C = Omega G + C_b adds the bearing blocks
    bearings.add_sparsity(component);
    damping_matrix.reinit(model.locally_owned_dofs(), model.locally_owned_dofs(), component, comm);
    reinit_bearing_matrices();
  }

  void
  SpeedTangent::reinit_bearing_matrices()
  {
    // the bearing matrices on their stations' blocks alone (a subset of the
    // pattern above): not two more copies of the full pattern, and their
    // products and projections cost next to nothing
    const auto            &dof_handler = model.dofs();
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

  void
  SpeedTangent::assemble_matrices()
  {
    matrices.assemble(model.dofs(), model.mesh().mapping(), model.mesh().cell_quadrature(),
                      model.bodies());
    // K_theta enters only as K_t2 = K_sigma(u_C) - K_theta where every
    // state is affine: it is assembled into K_sigma(u_C) with it, and its
    // own matrix (58 MB on TS's benchmark mesh) is freed after the
    // self-check has taken what it needs of it
    convective_folded = settings.stiffening == StressStiffening::full &&
                        settings.convective_term && !settings.static_spin_softening;
  }

  std::vector<bool>
  SpeedTangent::tied_pairs(const StaticState &state)
  {
    switch (settings.contact_model)
      {
        case ContactModel::bonded:
        case ContactModel::frictionless:
          return state.contact.active;
        case ContactModel::fixed:
          return std::vector<bool>(model.pairs().pairs().size(), true);
        case ContactModel::frozen:
          if (frozen_active.empty())
            frozen_active = state.contact.active;
          return frozen_active;
      }
    return {};
  }

  void
  SpeedTangent::assemble(const StaticState &state, const std::vector<bool> &tied, const bool first_speed)
  {
    TimerOutput::Scope t(timer, "eigen: tangent (K_sigma, ties, bearings)");
    ++tangent_serial;
    const double w = state.w(), omega = SpeedSchedule::rpm_to_rad_per_s(state.rpm);
    const StressStiffening stiffening = settings.stiffening;
    // on the last tangent's contact segment (the same ties, K_sigma parts
    // and bearing coefficients) only the speed's own share changes:
    // K_t += (w - w_t) K_t2, C += (Omega - Omega_t) G, two passes over a
    // pattern instead of six (a fifth of a reduced speed on TS)
    const bool same_segment =
      made_for && tied == made_for->tied && !bearings.speed_dependent() &&
      (stiffening == StressStiffening::off ||
       (state.decomposition().affine && state.decomposition().serial == stiffened_serial));
    if (same_segment)
      {
        if (stiffening == StressStiffening::full)
          {
            add_subset(tangent, w - made_for->w, k_sigma_C);
            if (settings.convective_term && !convective_folded)
              add_subset(tangent, made_for->w - w, matrices.convective);
          }
        add_subset(damping_matrix, omega - made_for->omega, matrices.gyroscopic);
        made_for->w     = w;
        made_for->omega = omega;
        return;
      }
    made_for = MadeFor{tied, w, omega};
    ++segment_serial;
    if (bearings.speed_dependent() || first_speed)
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
        if (settings.convective_term && !convective_folded) // (folded: in k_sigma_C)
          add_subset(tangent, -w, matrices.convective);
      }
    add_contact_ties(state, tied);
    tangent.compress(VectorOperation::add);

    // C = C_b + Omega G
    damping_matrix = 0;
    add_subset(damping_matrix, omega, matrices.gyroscopic);
    add_subset(damping_matrix, 1., bearing_c);
  }

  void
  SpeedTangent::update_stiffness(const StaticState &state)
  {
    // matrices.stiffness holds K + K_sigma(u_s), u_s = stiffened_by (the
    // active set's u_I; with spin softening the whole u of the speed).
    // K_sigma is linear in u: a new static state adds K_sigma(u - u_s),
    // assembled in the tangent's storage (made afresh right after), so
    // K_sigma(u_I) needs no matrix of its own (58 MB on TS's benchmark mesh).
    // The sum collects the rounding of one addition per contact segment.
    const auto &decomposition = state.decomposition();
    if (decomposition.affine && decomposition.serial == stiffened_serial)
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
        stiffened_serial = decomposition.serial;
      }
    else
      {
        // the whole solution at this speed (the tangent is exact there)
        state.displacement(u);
        matrices.assemble_stress_stiffness(dofs, mesh.mapping(), mesh.cell_quadrature(),
                                           model.bodies(), {&u}, {&tangent}, {&before});
        stiffened_serial = 0;
      }
    MatAXPY(matrices.stiffness, 1., tangent, SAME_NONZERO_PATTERN);
    stiffened_by.reinit(dofs.n_dofs());
    for (types::global_dof_index i = 0; i < dofs.n_dofs(); ++i)
      stiffened_by[i] = u[i];
  }

  void
  SpeedTangent::add_contact_ties(const StaticState &state, const std::vector<bool> &tied)
  {
    // on the locally owned rows; bonded: eps (u_h - u_s) in every
    // direction; frictionless: eps n n^T on the radial direction only
    const auto  &list        = model.pairs().pairs();
    const auto   range       = tangent.local_range();
    const bool   normal_only = settings.contact_model == ContactModel::frictionless;
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
  SpeedTangent::affine_segment() const
  {
    // as assemble() moves within a segment
    return made_for && !bearings.speed_dependent() &&
           (settings.stiffening != StressStiffening::full || convective_folded ||
            !settings.convective_term);
  }

  void
  SpeedTangent::speed_share(const std::vector<const Vector<double> *> &x,
                            std::vector<Vector<double>>               &gx,
                            std::vector<Vector<double>>               &k2x) const
  {
    replicated_mmult(matrices.gyroscopic, x, gx);
    if (settings.stiffening == StressStiffening::full)
      replicated_mmult(k_sigma_C, x, k2x);
    else
      k2x.assign(x.size(), Vector<double>(matrices.mass.m()));
  }

  void
  SpeedTangent::stiffening_share(const std::vector<const Vector<double> *> &x,
                                 std::vector<Vector<double>>               &k2) const
  {
    if (!stiffening_moves())
      return;
    replicated_mmult(k_sigma_C, x, k2);
    if (settings.convective_term && !convective_folded) // (folded: in k_sigma_C)
      {
        std::vector<Vector<double>> theta;
        replicated_mmult(matrices.convective, x, theta);
        for (std::size_t i = 0; i < x.size(); ++i)
          k2[i] -= theta[i];
      }
  }
} // namespace rotorfit
