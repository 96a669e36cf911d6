#include <rotorfit/contact/contact_solver.h>

#include <deal.II/base/mpi.h>

#include <deal.II/lac/full_matrix.h>

#include <cmath>
#include <limits>
#include <map>
#include <set>

namespace rotorfit
{
  using namespace dealii;

  void
  ContactSolver::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Contact");
    prm.declare_entry("Method",
                      "augmented Lagrangian",
                      Patterns::Selection("augmented Lagrangian|penalty"),
                      "Enforcement of the node-to-node contact constraints: "
                      "'penalty' leaves a penetration of about 1/(1 + Penalty "
                      "scale) of the interference; 'augmented Lagrangian' "
                      "(Uzawa) drives it to Uzawa tolerance on the same "
                      "factorisation.");
    prm.declare_entry("Penalty scale",
                      "10",
                      Patterns::Double(0.),
                      "alpha [-]: each pair's penalty is alpha times the mean "
                      "radial diagonal stiffness of its two nodes. 10..100 for "
                      "the augmented Lagrangian, 1e3..1e4 for pure penalty.");
    prm.declare_entry("Maximum active set iterations",
                      "30",
                      Patterns::Integer(1),
                      "Cap on active-set updates per speed.");
    prm.declare_entry("Maximum Uzawa iterations",
                      "100",
                      Patterns::Integer(1),
                      "Cap on multiplier updates per active set and load case "
                      "(augmented Lagrangian only).");
    prm.declare_entry("Uzawa tolerance",
                      "1e-8",
                      Patterns::Double(0.),
                      "Uzawa stops when max |gap| of the closed pairs is below "
                      "this times the interference [-].");
    prm.leave_subsection();
  }

  void
  ContactSolver::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Contact");
    contact_method = (prm.get("Method") == "penalty" ?
                        Method::penalty :
                        Method::augmented_lagrangian);
    alpha = prm.get_double("Penalty scale");
    max_active_set_iterations =
      prm.get_integer("Maximum active set iterations");
    max_uzawa_iterations = prm.get_integer("Maximum Uzawa iterations");
    uzawa_tolerance      = prm.get_double("Uzawa tolerance");
    prm.leave_subsection();
    solver.parse_parameters(prm);
  }

  void
  ContactSolver::initialize(const ContactPairs                     &pairs_,
                            const AffineConstraints<double>        &constraints_,
                            const DynamicSparsityPattern           &sparsity,
                            const PETScWrappers::MPI::SparseMatrix &stiffness,
                            const PETScWrappers::MPI::Vector       &unit_load,
                            const PETScWrappers::MPI::SparseMatrix *m_perp,
                            const Vector<double>                   &diagonal,
                            const IndexSet                         &owned_,
                            const MPI_Comm                          comm_,
                            const double                            w_max_)
  {
    pairs       = &pairs_;
    constraints = &constraints_;
    K           = &stiffness;
    F_c         = &unit_load;
    M_perp      = m_perp;
    owned       = owned_;
    comm        = comm_;
    w_max       = w_max_;
    this_rank   = Utilities::MPI::this_mpi_process(comm);
    all_dofs    = complete_index_set(owned.size());

    const auto &list = pairs->pairs();
    epsilon.resize(list.size());
    owner_adds.resize(list.size());
    for (unsigned int i = 0; i < list.size(); ++i)
      {
        const auto &p = list[i];
        const double nx2 = p.normal[0] * p.normal[0], ny2 = p.normal[1] * p.normal[1];
        const double k_s = nx2 * diagonal[p.shaft_dofs[0]] + ny2 * diagonal[p.shaft_dofs[1]];
        const double k_h = nx2 * diagonal[p.hub_dofs[0]] + ny2 * diagonal[p.hub_dofs[1]];
        epsilon[i]    = alpha * 0.5 * (k_s + k_h);
        owner_adds[i] = owned.is_element(p.shaft_dofs[0]);
      }
    system_matrix.reinit(owned, owned, sparsity, comm);
    current = Decomposition();
    current.active.assign(list.size(), true); // at rest every pair is closed
  }

  unsigned int
  ContactSolver::solve_load_case(const PETScWrappers::MPI::Vector *base_load,
                                 const double                      load_factor,
                                 const bool                        with_interference,
                                 const double                      gap_scale,
                                 const std::vector<bool>          &active,
                                 std::vector<double>              &force,
                                 std::vector<double>              &gap,
                                 PETScWrappers::MPI::Vector       &u)
  {
    const auto  &list = pairs->pairs();
    const bool   penalty = (contact_method == Method::penalty);
    if (penalty)
      std::fill(force.begin(), force.end(), 0.);
    for (unsigned int i = 0; i < list.size(); ++i)
      if (!active[i])
        force[i] = 0;

    PETScWrappers::MPI::Vector rhs(owned, comm);
    PETScWrappers::MPI::Vector u_ghosted(owned, all_dofs, comm);
    u.reinit(owned, comm);
    unsigned int iterations = 0;
    for (unsigned int k = 0; k < (penalty ? 1 : max_uzawa_iterations); ++k)
      {
        if (base_load != nullptr)
          {
            rhs = *base_load;
            rhs *= load_factor;
          }
        else
          rhs = 0;
        Vector<double>                       local(4);
        std::vector<types::global_dof_index> dofs(4);
        for (unsigned int i = 0; i < list.size(); ++i)
          if (active[i] && owner_adds[i])
            {
              const auto  &p = list[i];
              const double delta = with_interference ? p.interference : 0.;
              const double f     = force[i] + epsilon[i] * delta;
              // B: +n on the hub node, -n on the shaft node
              dofs  = {p.hub_dofs[0], p.hub_dofs[1], p.shaft_dofs[0], p.shaft_dofs[1]};
              local[0] = f * p.normal[0];
              local[1] = f * p.normal[1];
              local[2] = -f * p.normal[0];
              local[3] = -f * p.normal[1];
              constraints->distribute_local_to_global(local, dofs, rhs);
            }
        rhs.compress(VectorOperation::add);
        solver.solve(u, rhs);
        constraints->distribute(u);
        u_ghosted = u;

        double worst = 0;
        for (unsigned int i = 0; i < list.size(); ++i)
          {
            const auto  &p = list[i];
            const double delta = with_interference ? p.interference : 0.;
            gap[i] = p.normal[0] * (u_ghosted(p.hub_dofs[0]) - u_ghosted(p.shaft_dofs[0])) +
                     p.normal[1] * (u_ghosted(p.hub_dofs[1]) - u_ghosted(p.shaft_dofs[1])) -
                     delta;
            if (active[i])
              {
                force[i] -= epsilon[i] * gap[i];
                worst = std::max(worst, gap_scale * std::abs(gap[i]) / p.interference);
              }
          }
        if (!penalty)
          ++iterations;
        if (penalty || worst <= uzawa_tolerance)
          break;
      }
    return iterations;
  }

  void
  ContactSolver::compute_decomposition(const std::vector<bool> &active,
                                       const double             w)
  {
    const auto &list = pairs->pairs();
    // K + sum_A eps B B^T (- w M_perp): symmetric
    MatCopy(*K, system_matrix, SAME_NONZERO_PATTERN);
    FullMatrix<double>                   local(4, 4);
    std::vector<types::global_dof_index> dofs(4);
    for (unsigned int i = 0; i < list.size(); ++i)
      if (active[i] && owner_adds[i])
        {
          const auto &p = list[i];
          dofs = {p.hub_dofs[0], p.hub_dofs[1], p.shaft_dofs[0], p.shaft_dofs[1]};
          const double b[4] = {p.normal[0], p.normal[1], -p.normal[0], -p.normal[1]};
          for (unsigned int a = 0; a < 4; ++a)
            for (unsigned int c = 0; c < 4; ++c)
              local(a, c) = epsilon[i] * b[a] * b[c];
          constraints->distribute_local_to_global(local, dofs, system_matrix);
        }
    system_matrix.compress(VectorOperation::add);
    const bool affine = (M_perp == nullptr);
    if (!affine)
      {
        MatAXPY(system_matrix, -w, *M_perp, SAME_NONZERO_PATTERN);
        system_matrix.compress(VectorOperation::insert);
      }
    solver.factorize(system_matrix);

    // continue from the previous multipliers (augmented Lagrangian)
    Decomposition next;
    next.active  = active;
    next.affine  = affine;
    next.w_fixed = w;
    const unsigned int n = list.size();
    next.force_I.assign(n, 0.);
    next.force_C.assign(n, 0.);
    next.gap_I.assign(n, 0.);
    next.gap_C.assign(n, 0.);
    if (current.valid)
      for (unsigned int i = 0; i < n; ++i)
        {
          next.force_I[i] = current.force_I[i] + (affine ? 0. : w * current.force_C[i]);
          next.force_C[i] = affine ? current.force_C[i] : 0.;
        }
    if (affine)
      {
        uzawa_count += solve_load_case(nullptr, 0., true, 1., active, next.force_I, next.gap_I, next.u_I);
        if (w_max > 0)
          uzawa_count += solve_load_case(F_c, 1., false, w_max, active, next.force_C, next.gap_C, next.u_C);
        else
          next.u_C.reinit(owned, comm);
      }
    else
      {
        uzawa_count += solve_load_case(F_c, w, true, 1., active, next.force_I, next.gap_I, next.u_I);
        next.u_C.reinit(owned, comm);
      }
    // P2 vertex pairs carry almost no force (int psi_i dA = 0), so the sign
    // of their multiplier is noise; the pressure field p = M^-1 N is smooth
    // and decides which pairs are open
    // the decomposition holds everything later speeds need: a new active set
    // gets a new factorisation anyway, so this one is freed now (it would sit
    // next to the eigenproblem's LU)
    solver.release();
    next.pressure_I = pairs->pressure(next.force_I);
    next.pressure_C = pairs->pressure(next.force_C);
    next.valid      = true;
    next.serial     = ++decompositions;
    current         = std::move(next);
  }

  ContactSolver::State
  ContactSolver::solve(const double w)
  {
    const unsigned int n = pairs->pairs().size();
    State              state;
    const unsigned int factorizations_before = solver.n_factorizations();
    uzawa_count                              = 0;

    std::vector<bool>         active = current.active;
    std::vector<unsigned int> flips(n, 0);
    std::set<std::vector<bool>> seen;
    while (true)
      {
        const bool reusable = current.valid && current.active == active &&
                              (current.affine || current.w_fixed == w);
        if (!reusable)
          compute_decomposition(active, w);
        ++state.active_set_iterations;

        state.force.resize(n);
        state.gap.resize(n);
        state.pressure.resize(n);
        for (unsigned int i = 0; i < n; ++i)
          {
            const double wc   = current.affine ? w : 0.;
            state.force[i]    = current.force_I[i] + wc * current.force_C[i];
            state.gap[i]      = current.gap_I[i] + wc * current.gap_C[i];
            state.pressure[i] = current.pressure_I[i] + wc * current.pressure_C[i];
          }
        // A closed pair opens when both its pressure and its own nodal force
        // are tensile. The force alone is noise on P2 vertex pairs (their
        // weight int psi_i dA is zero: they would open at rest); the smooth
        // pressure alone would open pairs whose own force still holds them,
        // which then penetrate and close again (cycling). An open pair
        // closes when it penetrates.
        std::vector<bool> next(n);
        for (unsigned int i = 0; i < n; ++i)
          next[i] = active[i] ? (state.pressure[i] > 0 || state.force[i] > 0) :
                                state.gap[i] < 0;
        if (next == active)
          break;
        if (state.active_set_iterations >= max_active_set_iterations)
          {
            state.converged = false;
            break;
          }
        // cycling guard: a pair that flips twice is kept closed
        seen.insert(active);
        for (unsigned int i = 0; i < n; ++i)
          if (next[i] != active[i] && ++flips[i] >= 2)
            next[i] = true;
        if (next == active || seen.count(next) > 0)
          {
            // pairs held closed may carry tension: the row is flagged, not
            // passed off as a clean contact state
            state.held_closed = std::count_if(flips.begin(), flips.end(),
                                              [](unsigned int f) { return f >= 2; });
            state.converged = false;
            break;
          }
        active = next;
      }
    state.active = current.active;
    for (unsigned int i = 0; i < n; ++i)
      if (!state.active[i])
        state.force[i] = state.pressure[i] = 0;
    state.uzawa_iterations = uzawa_count;
    state.factorizations   = solver.n_factorizations() - factorizations_before;
    return state;
  }

  void
  ContactSolver::displacement(const double w, PETScWrappers::MPI::Vector &u) const
  {
    PETScWrappers::MPI::Vector tmp(owned, comm);
    tmp = current.u_I;
    if (current.affine)
      tmp.add(w, current.u_C);
    u.reinit(owned, all_dofs, comm);
    u = tmp;
  }
} // namespace rotorfit
