#include <rotorfit/contact/contact_solver.h>

#include <rotorfit/statics/speed_schedule.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>

// ContactSolver, part 2: the active-set iteration of a speed and its cycling
// guard. Part 1 (parameters, factorisations, low-rank updates, the load
// cases): contact_solver.cc.

namespace rotorfit
{
  using namespace dealii;

  ContactSolver::State
  ContactSolver::solve(const double w)
  {
    if (path_finished)
      throw std::logic_error("ContactSolver::solve() after finish_path(): every speed's state "
                             "was made ahead");
    const unsigned int n = pairs->pairs().size();
    State              state;
    const unsigned int factorizations_before = solver.n_factorizations();
    const unsigned int updates_before        = low_rank_updates;
    const unsigned int columns_before        = influence_columns;
    uzawa_count                              = 0;

    const bool          on_path = exact_path() && path_started;
    std::vector<double> roots;
    if (exact_path())
      {
        if (!path_started)
          start_path();
        else
          advance_path(w, state);
        for (unsigned int i = 0; on_path && i < n; ++i)
          roots.push_back(event_w(i, path_w));
      }
    const std::vector<bool> before = current.active;
    settle(w, state);
    if (exact_path())
      {
        // changes at w itself: at their roots under the previous law (a
        // pair pulled along by another one: at w)
        for (unsigned int i = 0; on_path && i < n; ++i)
          if (before[i] != current.active[i])
            state.events.push_back({std::min(std::max(roots[i], path_w), w), i, before[i]});
        path_w = w;
        ensure_displacements();
        std::stable_sort(state.events.begin(), state.events.end(),
                         [](const Event &a, const Event &b) { return a.w < b.w; });
      }
    if (!current.uzawa_converged)
      {
        state.converged = false;
        state.reason += std::string(state.reason.empty() ? "" : "; ") +
                        (exact_path() ? "pair-space residual above 1e-8" :
                                        "Uzawa cap reached (Contact/Maximum Uzawa iterations = " +
                                          std::to_string(max_uzawa_iterations) + ")");
      }
    state.active = current.active;
    evaluate(w, state);
    for (unsigned int i = 0; i < n; ++i)
      if (!state.active[i])
        state.force[i] = state.pressure[i] = 0;
    state.uzawa_iterations  = uzawa_count;
    state.factorizations    = solver.n_factorizations() - factorizations_before;
    state.low_rank_updates  = low_rank_updates - updates_before;
    state.influence_columns = influence_columns - columns_before;
    return state;
  }

  void
  ContactSolver::settle(const double w, State &state)
  {
    const unsigned int          n      = pairs->pairs().size();
    std::vector<bool>           active = current.active;
    std::vector<unsigned int>   flips(n, 0);
    std::set<std::vector<bool>> seen;
    unsigned int                iterations = 0;
    bool                        settled    = true;
    while (true)
      {
        const bool reusable = current.valid && current.active == active &&
                              (current.affine || current.w_fixed == w);
        if (!reusable)
          compute_decomposition(active, w);
        ++iterations;
        ++state.active_set_iterations;
        evaluate(w, state);
        const std::vector<bool> next = next_active_set(active, state);
        if (next == active)
          break;
        seen.insert(active);
        std::vector<bool> proposal;
        if (iterations >= max_active_set_iterations ||
            !guard_cycling(active, next, state, flips, seen, proposal))
          {
            // the cap, or every way on leads back to a visited set
            state.flipped_back =
              std::count_if(flips.begin(), flips.end(), [](unsigned int f) { return f >= 2; });
            settled = false;
            break;
          }
        for (unsigned int i = 0; i < n; ++i)
          if (proposal[i] != active[i])
            ++flips[i];
        active = proposal;
      }
    if (!settled && state.reason.find("active set not settled") == std::string::npos)
      {
        std::ostringstream m;
        m << "active set not settled (" << iterations << " iterations; " << state.flipped_back
          << " pairs flipped back"
          << (exact_path() ? ", at " + std::to_string(SpeedSchedule::rad_per_s_to_rpm(std::sqrt(w))) +
                               " r/min on the path" :
                             std::string())
          << ")";
        state.reason += (state.reason.empty() ? "" : "; ") + m.str();
      }
    state.converged &= settled;
  }

  void
  ContactSolver::evaluate(const double w, State &state) const
  {
    const unsigned int n = pairs->pairs().size();
    state.force.resize(n);
    state.gap.resize(n);
    state.pressure.resize(n);
    for (unsigned int i = 0; i < n; ++i)
      {
        state.force[i]    = current.force_I[i] + w * current.force_C[i];
        state.gap[i]      = current.gap_I[i] + w * current.gap_C[i];
        state.pressure[i] = current.pressure_I[i] + w * current.pressure_C[i];
      }
  }

  std::vector<bool>
  ContactSolver::next_active_set(const std::vector<bool> &active, const State &state) const
  {
    // A closed pair opens when both its pressure and its own nodal force
    // are tensile. The force alone is noise on P2 vertex pairs (their
    // weight int psi_i dA is zero: they would open at rest); the smooth
    // pressure alone would open pairs whose own force still holds them,
    // which then penetrate and close again (cycling). An open pair closes
    // when it penetrates.
    std::vector<bool> next(active.size());
    for (unsigned int i = 0; i < active.size(); ++i)
      next[i] = active[i] ? (state.pressure[i] > 0 || state.force[i] > 0) : state.gap[i] < 0;
    return next;
  }

  bool
  ContactSolver::guard_cycling(const std::vector<bool>           &active,
                               const std::vector<bool>           &next,
                               const State                       &state,
                               const std::vector<unsigned int>   &flips,
                               const std::set<std::vector<bool>> &seen,
                               std::vector<bool>                 &proposal) const
  {
    // Flipping many pairs at once can overshoot: opening a group lets one
    // of them penetrate, closing it makes it tensile again. A pair that has
    // flipped back is held while other pairs still change; once only such
    // pairs are left they change one at a time, the worst violation first,
    // a penetrating pair before a tensile one (a single tensile pair that
    // opens cannot penetrate: the flexibility is SPD).
    const auto        &list = pairs->pairs();
    const unsigned int n    = active.size();
    proposal                = active;
    bool fresh              = false;
    for (unsigned int i = 0; i < n; ++i)
      if (next[i] != active[i] && flips[i] < 2)
        {
          proposal[i] = next[i];
          fresh       = true;
        }
    if (!fresh || seen.count(proposal) > 0)
      {
        // candidates by priority: penetrating pairs (deepest first), then
        // tensile ones (most tensile pressure first); the first whose set
        // has not been visited yet
        std::vector<std::tuple<bool, double, unsigned int>> candidates;
        for (unsigned int i = 0; i < n; ++i)
          if (next[i] != active[i])
            candidates.emplace_back(active[i],
                                    active[i] ? state.pressure[i] :
                                                state.gap[i] / list[i].interference,
                                    i);
        std::sort(candidates.begin(), candidates.end());
        for (const auto &candidate : candidates)
          {
            const unsigned int i = std::get<2>(candidate);
            proposal             = active;
            proposal[i]          = !active[i];
            if (seen.count(proposal) == 0)
              break;
          }
      }
    return seen.count(proposal) == 0;
  }
} // namespace rotorfit
