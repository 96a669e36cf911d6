#include <rotorfit/contact/exact_path.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    constexpr double infinity = std::numeric_limits<double>::infinity();

    /// Where a + b w <= 0 on the w axis: [lo, hi].
    void
    nonpositive_range(const double a, const double b, double &lo, double &hi)
    {
      if (b > 0)
        hi = std::min(hi, -a / b);
      else if (b < 0)
        lo = std::max(lo, -a / b);
      else if (a > 0)
        hi = -infinity;
    }
  } // namespace

  void
  ExactPath::initialize(const System &system, BaseFactorization &base_)
  {
    ops         = &system.operators;
    constraints = &system.constraints;
    F_c         = &system.unit_centrifugal_load;
    pairs       = &system.pairs;
    owned       = system.owned;
    comm        = system.comm;
    base        = &base_;
    law.initialize(system.parameters, system.pairs, system.operators, system.comm, system.w_max);
    path_started  = false;
    path_finished = false;
    path_w        = 0;
  }

  void
  ExactPath::start(const std::vector<bool> &active)
  {
    const unsigned int n = ops->size();
    base->factorize(active, 0.);
    std::vector<unsigned int> all(n);
    for (unsigned int i = 0; i < n; ++i)
      all[i] = i;
    base->compute_columns(all);
    law.set_flexibility(base->columns(), base->active());
    // the dense copy replaces the cache
    base->clear_update();

    PETScWrappers::MPI::Vector u(owned, comm), rhs(owned, comm);
    rhs = *F_c;
    base->linear_solver().solve(u, rhs);
    law.set_centrifugal_load(ops->project(u));
    path_started = true;
  }

  std::vector<double>
  ExactPath::approach(const double                w,
                      ContactState               &state,
                      const ContactDecomposition &current,
                      const Settle               &settle)
  {
    std::vector<double> roots;
    if (!path_started)
      {
        start(current.active);
        return roots;
      }
    advance(w, state, current, settle);
    for (unsigned int i = 0; i < ops->size(); ++i)
      roots.push_back(event_w(current, i, path_w));
    return roots;
  }

  void
  ExactPath::advance(const double                w,
                     ContactState               &state,
                     const ContactDecomposition &current,
                     const Settle               &settle)
  {
    const unsigned int n     = ops->size();
    const std::size_t  limit = 20 * std::size_t(n) + 100;
    for (std::size_t step = 0;; ++step)
      {
        double w_e = infinity;
        for (unsigned int i = 0; i < n; ++i)
          w_e = std::min(w_e, event_w(current, i, path_w));
        if (!(w_e < w))
          return;
        if (step == limit)
          {
            state.converged = false;
            state.reason += std::string(state.reason.empty() ? "" : "; ") + "more than " +
                            std::to_string(limit) +
                            " contact events before this speed (pairs chattering)";
            return;
          }
        // the new set just past the event: pairs whose roots coincide to
        // rounding (a ring of a symmetric mesh) change together, and pairs
        // pulled along by the change follow in the active-set iteration
        const double w_s = std::min(w_e + 1e-10 * std::max(w_e, w), 0.5 * (w_e + w));
        const std::vector<bool> before = current.active;
        ResultantKink           kink;
        kink.w = w_e;
        resultants(current, w_e, kink.force_before, kink.moment_before);
        settle(w_s, state);
        resultants(current, w_e, kink.force_after, kink.moment_after);
        state.kinks.push_back(std::move(kink));
        for (unsigned int i = 0; i < n; ++i)
          if (before[i] != current.active[i])
            state.events.push_back({w_e, i, before[i]});
        path_w = w_s;
      }
  }

  void
  ExactPath::arrive(const double               w,
                    const std::vector<bool>   &before,
                    const std::vector<double> &roots,
                    ContactState              &state,
                    ContactDecomposition      &current)
  {
    // changes at w itself: at their roots under the previous law (a pair
    // pulled along by another one: at w); the resultants there from the
    // new law (continuous through a change: the pair changing carries no force)
    double first_root = w;
    for (unsigned int i = 0; i < roots.size(); ++i)
      if (before[i] != current.active[i])
        {
          const double w_i = std::min(std::max(roots[i], path_w), w);
          state.events.push_back({w_i, i, before[i]});
          first_root = std::min(first_root, w_i);
        }
    if (first_root < w)
      {
        ResultantKink kink;
        kink.w = first_root;
        resultants(current, first_root, kink.force_after, kink.moment_after);
        kink.force_before  = kink.force_after;
        kink.moment_before = kink.moment_after;
        state.kinks.push_back(std::move(kink));
      }
    path_w = w;
    make_displacements(current);
    std::stable_sort(state.events.begin(), state.events.end(),
                     [](const ContactEvent &a, const ContactEvent &b) { return a.w < b.w; });
  }

  double
  ExactPath::event_w(const ContactDecomposition &d, const unsigned int i, const double w)
  {
    double lo = -infinity, hi = infinity;
    if (d.active[i])
      {
        // opens where both its pressure and its own force are tensile
        nonpositive_range(d.pressure_I[i], d.pressure_C[i], lo, hi);
        nonpositive_range(d.force_I[i], d.force_C[i], lo, hi);
        return (lo > w && lo <= hi) ? lo : infinity;
      }
    // closes where it penetrates
    if (d.gap_C[i] < 0)
      {
        const double root = -d.gap_I[i] / d.gap_C[i];
        if (root > w)
          return root;
      }
    return infinity;
  }

  void
  ExactPath::resultants(const ContactDecomposition &d, const double w, std::vector<double> &force,
                        std::vector<double> &moment) const
  {
    force.assign(pairs->n_interfaces(), 0.);
    moment.assign(pairs->n_interfaces(), 0.);
    const auto &list = pairs->pairs();
    for (unsigned int i = 0; i < list.size(); ++i)
      if (d.active[i])
        {
          const double N = d.force_I[i] + w * d.force_C[i];
          force[list[i].interface] += N;
          moment[list[i].interface] += N * std::hypot(list[i].position[0], list[i].position[1]);
        }
  }

  void
  ExactPath::make_displacements(ContactDecomposition &d)
  {
    // the displacements belong to the law: a new law comes without them
    if (d.has_displacements())
      return;
    PETScWrappers::MPI::Vector rhs(owned, comm);
    d.u_I.reinit(owned, comm);
    ops->add_pair_forces(d.q_I, rhs);
    base->solve(d.u_I, rhs);
    constraints->distribute(d.u_I);
    rhs = *F_c;
    ops->add_pair_forces(d.q_C, rhs);
    d.u_C.reinit(owned, comm);
    base->solve(d.u_C, rhs);
    constraints->distribute(d.u_C);
  }

  void
  ExactPath::finish()
  {
    // every speed's state is made: the pair-space matrices are not needed
    // any more
    law.clear();
    path_finished = true;
  }
} // namespace rotorfit
