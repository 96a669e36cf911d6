#include <rotorfit/base/input_error.h>
#include <rotorfit/base/resources.h>
#include <rotorfit/linear_algebra/matrix_pattern.h>
#include <rotorfit/material/elasticity.h>
#include <rotorfit/statics/body_stress.h>
#include <rotorfit/statics/speed_schedule.h>
#include <rotorfit/statics/static_problem.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/utilities.h>

#include <deal.II/fe/fe_values.h>

#include <deal.II/lac/full_matrix.h>

#include <cmath>
#include <iomanip>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

  StaticProblem::StaticProblem(const Discretization &model, Log &log, TimerOutput &timer)
    : model(model)
    , log(log)
    , timer(timer)
    , comm(model.mpi_communicator())
    , history(model.pairs(), model.interfaces(), log)
    , assessment(model.pairs(), model.interfaces(), model.bodies())
  {}

  void
  StaticProblem::declare_parameters(ParameterHandler &prm)
  {
    ContactSolver::declare_parameters(prm);
    DirectSolver::declare_parameters(prm);
    prm.enter_subsection("Physics");
    prm.declare_entry("Spin softening",
                      "false",
                      Patterns::Bool(),
                      "Centrifugal load on the deformed radius (-Omega^2 M_perp "
                      "in the static stiffness). Off by default: the "
                      "closed-form checks use the undeformed radius, and with "
                      "it on every speed needs its own factorisation.");
    prm.leave_subsection();
  }

  void
  StaticProblem::parse_parameters(ParameterHandler &prm)
  {
    contact.parse_parameters(prm);
    prm.enter_subsection("Physics");
    spin_softening = prm.get_bool("Spin softening");
    prm.leave_subsection();
  }

  void
  StaticProblem::assemble(const double w_max)
  {
    {
      TimerOutput::Scope t(timer, "assembly (K, centrifugal load)");
      setup_system();
      assemble_system();
    }
    ahead.clear();
    assessment.initialize(std::make_unique<BodyStress>(model));
    contact.initialize({model.pairs(),
                        model.static_constraints(),
                        stiffness,
                        unit_centrifugal_load,
                        spin_softening ? &spin_softening_matrix : nullptr,
                        stiffness_diagonal,
                        model.locally_owned_dofs(),
                        comm},
                       w_max);
    log << "Contact: "
        << (contact.method() == ContactSolver::Method::penalty ? "penalty" :
                                                                  "augmented Lagrangian")
        << ", penalty scale " << contact.penalty_scale() << "; linear solver "
        << contact.linear_solver().name() << "; spin softening "
        << (spin_softening ? "on" : "off") << "\n";
  }

  void
  StaticProblem::setup_system()
  {
    const auto &dof_handler = model.dofs();
    const auto &owned       = model.locally_owned_dofs();
    const auto &constraints = model.static_constraints();
    // (the matrices keep the pattern: K is made from it, the others copy K's)
    DynamicSparsityPattern sparsity(dof_handler.n_dofs(), dof_handler.n_dofs(), owned);
    std::vector<types::global_dof_index> dofs(dof_handler.get_fe().n_dofs_per_cell());
    // all cells, not only the owned ones: an owned row may couple to DoFs
    // of cells on other ranks
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        cell->get_dof_indices(dofs);
        constraints.add_entries_local_to_global(dofs, sparsity, false);
      }
    for (const auto &p : model.pairs().pairs())
      {
        std::vector<types::global_dof_index> d = {p.hub_dofs[0], p.hub_dofs[1],
                                                  p.shaft_dofs[0], p.shaft_dofs[1]};
        constraints.add_entries_local_to_global(d, sparsity, false);
      }
    stiffness.reinit(owned, owned, sparsity, comm);
    if (spin_softening)
      reinit_with_pattern_of(spin_softening_matrix, stiffness);
    unit_centrifugal_load.reinit(owned, comm);
    stiffness_diagonal.reinit(dof_handler.n_dofs());
  }

  void
  StaticProblem::assemble_system()
  {
    // one rule for every volume integral (doc/theory.md 0)
    const auto            &fe         = model.dofs().get_fe();
    const auto            &bodies     = model.bodies();
    const auto            &constraints = model.static_constraints();
    const Quadrature<3>    quadrature = model.mesh().cell_quadrature();
    FEValues<3>            fe_values(model.mesh().mapping(),
                          fe,
                          quadrature,
                          update_values | update_gradients |
                            update_quadrature_points | update_JxW_values);
    const FEValuesExtractors::Vector disp(0);
    const unsigned int               n = fe.n_dofs_per_cell();
    FullMatrix<double>               cell_k(n, n), cell_m(n, n);
    Vector<double>                   cell_f(n);
    std::vector<types::global_dof_index> dofs(n);
    std::vector<SymmetricTensor<2, 3>>   eps(n);
    std::vector<Tensor<1, 3>>            phi(n);
    mass.assign(bodies.size(), 0.);
    polar.assign(bodies.size(), 0.);

    for (const auto &cell : model.dofs().active_cell_iterators())
      if (cell->is_locally_owned())
        {
          fe_values.reinit(cell);
          cell->get_dof_indices(dofs);
          const Body  &body   = bodies[cell->material_id()];
          const double lambda = body.lambda(), mu = body.mu(), rho = body.density;
          cell_k = 0;
          cell_m = 0;
          cell_f = 0;
          for (unsigned int q = 0; q < quadrature.size(); ++q)
            {
              const double    JxW = fe_values.JxW(q);
              const Point<3> &x   = fe_values.quadrature_point(q);
              const Tensor<1, 3> r_perp({x[0], x[1], 0.});
              mass[cell->material_id()] += rho * JxW;
              polar[cell->material_id()] += rho * (x[0] * x[0] + x[1] * x[1]) * JxW;
              add_elastic_stiffness(fe_values, q, lambda, mu, cell_k, eps);
              for (unsigned int i = 0; i < n; ++i)
                {
                  phi[i] = fe_values[disp].value(i, q);
                  cell_f(i) += rho * (phi[i] * r_perp) * JxW;
                }
              if (spin_softening)
                for (unsigned int i = 0; i < n; ++i)
                  for (unsigned int j = 0; j < n; ++j)
                    cell_m(i, j) += rho * (phi[i][0] * phi[j][0] + phi[i][1] * phi[j][1]) * JxW;
            }
          for (unsigned int i = 0; i < n; ++i)
            stiffness_diagonal[dofs[i]] += cell_k(i, i);
          constraints.distribute_local_to_global(cell_k, cell_f, dofs, stiffness,
                                                 unit_centrifugal_load);
          if (spin_softening)
            constraints.distribute_local_to_global(cell_m, dofs, spin_softening_matrix);
        }
    stiffness.compress(VectorOperation::add);
    unit_centrifugal_load.compress(VectorOperation::add);
    if (spin_softening)
      spin_softening_matrix.compress(VectorOperation::add);
    Utilities::MPI::sum(stiffness_diagonal, comm, stiffness_diagonal);
    for (unsigned int b = 0; b < bodies.size(); ++b)
      {
        mass[b]  = Utilities::MPI::sum(mass[b], comm);
        polar[b] = Utilities::MPI::sum(polar[b], comm);
      }

    log << "Mass properties (curved geometry):\n";
    for (unsigned int b = 0; b < bodies.size(); ++b)
      log << "  body " << bodies[b].name << ": mass " << mass[b]
          << " kg, polar moment of inertia " << polar[b] << " kg m^2\n";
  }

  const StaticState &
  StaticProblem::solve(const double rpm, const unsigned int index)
  {
    if (index < ahead.size() && ahead[index].failure)
      std::rethrow_exception(ahead[index].failure);
    if (index < ahead.size() && ahead[index].state.rpm == rpm)
      state = std::move(ahead[index].state);
    else
      state = contact_state(rpm, index);
    check_finite(state);
    uzawa_iterations += state.contact.uzawa_iterations;
    contact_events += state.contact.events.size();
    history.record(state, state.decomposition(), contact.constraint_error_limit());
    {
      TimerOutput::Scope         t(timer, "fit assessment (capacity, stresses)");
      PETScWrappers::MPI::Vector u;
      state.displacement(u);
      assessment.record(state, u);
    }
    return state;
  }

  StaticState
  StaticProblem::contact_state(const double rpm, const unsigned int index)
  {
    return StaticState::solve(contact, rpm, index, timer);
  }

  void
  StaticProblem::solve_ahead(const std::vector<double> &rpm)
  {
    ahead.clear();
    if (speed_path() != ContactSolver::Path::exact)
      return;
    // the laws kept must stay well below the factorisation they replace
    const double       n_dofs  = model.dofs().n_dofs();
    const double       limit   = 0.5 * resources::factorization_bytes(n_dofs, true);
    const double       per_law = 2. * 8. * n_dofs; // u_I, u_C
    double             kept    = 0;
    for (unsigned int k = 0; k < rpm.size(); ++k)
      {
        // (no interruption point here: a stop is taken before the first
        // speed's output, where the run's loop checks)
        Ahead a;
        try
          {
            a.state = contact_state(rpm[k], k);
          }
        catch (...)
          {
            // met again, in order, when the run reaches this speed
            a.failure = std::current_exception();
            ahead.push_back(std::move(a));
            return; // the path cannot go on: the factorisation stays
          }
        if (ahead.empty() || ahead.back().state.shared_law() != a.state.shared_law())
          kept += per_law; // a new segment's law
        ahead.push_back(std::move(a));
        if (kept > limit)
          return; // the later speeds follow the path as they come
      }
    contact.finish_path();
    // nothing static is solved any more (assemble() makes them anew)
    stiffness.clear();
    spin_softening_matrix.clear();
  }

  void
  StaticProblem::check_finite(const StaticState &s) const
  {
    // NaN or Inf (a factorisation that lost its digits, an extreme
    // penalty) must never reach a result file
    unsigned int bad = 0;
    for (unsigned int i = 0; i < s.contact.active.size(); ++i)
      bad += !(std::isfinite(s.contact.force[i]) && std::isfinite(s.contact.gap[i]) &&
               std::isfinite(s.contact.pressure[i]));
    if (bad > 0)
      {
        std::ostringstream m;
        m << std::setprecision(8) << "the static contact solve at " << s.rpm
          << " r/min gave non-finite forces, gaps or pressures (NaN or Inf) at " << bad
          << " pairs: the factorisation lost its digits; lower Contact/Penalty scale (now "
          << contact.penalty_scale() << ")";
        throw SolverFailure(s.rpm, m.str());
      }
  }

  void
  StaticProblem::finish(Summary &summary)
  {
    for (unsigned int b = 0; b < model.bodies().size(); ++b)
      {
        const std::string key = "body." + model.bodies()[b].name + ".";
        summary.add(key + "mass_kg", mass.empty() ? 0. : mass[b]);
        summary.add(key + "polar_moment_kgm2", polar.empty() ? 0. : polar[b]);
      }
    history.add_to_summary(summary);
    assessment.add_to_summary(summary);
    summary.add("static.factorizations", contact.n_factorizations());
    summary.add("static.low_rank_updates", contact.n_low_rank_updates());
    summary.add("static.influence_columns", contact.n_influence_columns());
    summary.add("static.uzawa_iterations", uzawa_iterations);
    summary.add("static.speed_path",
                speed_path() == ContactSolver::Path::exact ? "exact" : "sampled");
    summary.add("static.contact_events", contact_events);
    // exact path: the largest relative residual of a pair-space solve (a
    // speed above 1e-8 is flagged converged = 0 in contact.csv)
    summary.add("static.pair_space_residual_max", contact.worst_path_residual());
    summary.add("static.workspace_retries", contact.linear_solver().n_workspace_retries());
    log << "Static sweep: " << history.n_speeds() << " speeds, " << contact.n_factorizations()
        << " factorisations, " << contact.n_low_rank_updates() << " low-rank updates ("
        << contact.n_influence_columns() << " influence columns), "
        << contact.linear_solver().n_solves()
        << " back-substitutions (influence columns included); " << std::fixed
        << std::setprecision(1) << contact.timing().factorize << " s factorising, "
        << contact.timing().columns << " s influence columns, " << contact.timing().solves
        << " s load-case back-substitutions" << std::defaultfloat << std::setprecision(6);
    if (speed_path() == ContactSolver::Path::exact)
      log << "; exact path: " << contact_events << " contact events, largest pair-space residual "
          << contact.worst_path_residual();
    log << '\n';
  }
} // namespace rotorfit

namespace rotorfit
{
  StaticState
  StaticState::solve(ContactSolver &contact, const double rpm, const unsigned int index,
                     TimerOutput &timer)
  {
    StaticState s;
    s.solver = &contact;
    s.rpm    = rpm;
    s.index  = index;
    {
      TimerOutput::Scope t(timer, "contact solve");
      s.contact = contact.solve(std::pow(SpeedSchedule::rpm_to_rad_per_s(rpm), 2));
    }
    // one copy of the law per segment: speeds on it share it
    s.law = contact.law();
    return s;
  }

  double
  StaticState::w() const
  {
    return std::pow(SpeedSchedule::rpm_to_rad_per_s(rpm), 2);
  }
} // namespace rotorfit
