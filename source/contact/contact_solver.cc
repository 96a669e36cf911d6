#include <rotorfit/contact/contact_solver.h>

#include <stdexcept>
#include <string>

namespace rotorfit
{
  using namespace dealii;

  void
  ContactSolver::declare_parameters(ParameterHandler &prm)
  {
    ContactParameters::declare_parameters(prm);
  }

  void
  ContactSolver::parse_parameters(ParameterHandler &prm)
  {
    settings.parse_parameters(prm);
    base.linear_solver().parse_parameters(prm);
  }

  void
  ContactSolver::initialize(const StaticSystem &system, const double w_max)
  {
    pairs    = &system.pairs;
    M_perp   = system.spin_softening_matrix;
    owned    = system.owned;
    comm     = system.comm;
    all_dofs = complete_index_set(owned.size());

    operators.initialize(system.pairs, system.constraints, system.stiffness_diagonal, owned, comm,
                         settings.penalty_scale);
    base.initialize(system.stiffness, M_perp, system.constraints, system.pairs, operators, comm);
    sampled.initialize({settings, system.pairs, operators, system.constraints,
                        system.unit_centrifugal_load, M_perp, owned, comm, w_max},
                       base);
    exact.initialize({settings, system.pairs, operators, system.constraints,
                      system.unit_centrifugal_load, owned, comm, w_max},
                     base);
    active_set.initialize(system.pairs, settings.max_active_set_iterations, exact_path());
    current = Decomposition();
    current.active.assign(pairs->pairs().size(), true); // at rest every pair is closed
    shared_law.reset();
  }

  ContactSolver::State
  ContactSolver::solve(const double w)
  {
    if (exact.finished())
      throw std::logic_error("ContactSolver::solve() after finish_path(): every speed's state "
                             "was made ahead");
    const unsigned int n = pairs->pairs().size();
    State              state;
    const unsigned int factorizations_before = n_factorizations();
    const unsigned int updates_before        = n_low_rank_updates();
    const unsigned int columns_before        = n_influence_columns();
    sampled.reset_uzawa_count();

    // the exact path follows its events up to w first, and records the
    // changes at w after
    std::vector<double> roots;
    if (exact_path())
      roots = exact.approach(w, state, current,
                             [this](const double w_s, State &s) { settle(w_s, s); });
    const std::vector<bool> before = current.active;
    settle(w, state);
    if (exact_path())
      {
        const bool displaced = current.has_displacements();
        exact.arrive(w, before, roots, state, current);
        if (!displaced)
          shared_law.reset(); // the law now has its displacements
      }

    if (!current.uzawa_converged)
      {
        state.converged = false;
        state.reason += std::string(state.reason.empty() ? "" : "; ") +
                        (exact_path() ? "pair-space residual above 1e-8" :
                                        "Uzawa cap reached (Contact/Maximum Uzawa iterations = " +
                                          std::to_string(settings.max_uzawa_iterations) + ")");
      }
    state.active = current.active;
    current.evaluate(w, state);
    for (unsigned int i = 0; i < n; ++i)
      if (!state.active[i])
        state.force[i] = state.pressure[i] = 0;
    state.uzawa_iterations  = sampled.n_uzawa_iterations();
    state.factorizations    = n_factorizations() - factorizations_before;
    state.low_rank_updates  = n_low_rank_updates() - updates_before;
    state.influence_columns = n_influence_columns() - columns_before;
    return state;
  }

  void
  ContactSolver::settle(const double w, State &state)
  {
    active_set.settle(w, state, current, [this](const std::vector<bool> &active, const double w_a) {
      compute_decomposition(active, w_a);
    });
  }

  void
  ContactSolver::compute_decomposition(const std::vector<bool> &active, const double w)
  {
    Decomposition next =
      exact_path() ? exact.decompose(active) : sampled.decompose(active, w, current);
    next.serial = ++decompositions;
    current     = std::move(next);
    shared_law.reset();
  }

  std::shared_ptr<const ContactSolver::Decomposition>
  ContactSolver::law() const
  {
    if (!shared_law)
      shared_law = std::make_shared<const Decomposition>(current);
    return shared_law;
  }

  void
  ContactSolver::release_factorization()
  {
    if (exact_path() && exact.started())
      return; // the path makes its displacements on this factorisation
    base.release();
  }

  void
  ContactSolver::finish_path()
  {
    base.finish();
    exact.finish();
  }

  void
  ContactSolver::displacement(const Decomposition &d, const double w, PETScWrappers::MPI::Vector &u) const
  {
    PETScWrappers::MPI::Vector tmp(owned, comm);
    tmp = d.u_I;
    tmp.add(w, d.u_C);
    u.reinit(owned, all_dofs, comm);
    u = tmp;
  }
} // namespace rotorfit
