#include <rotorfit/contact/active_set.h>

#include <deal.II/base/numbers.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <tuple>

namespace rotorfit
{
  namespace
  {
    /// Omega [r/min] of @p w = Omega^2 [rad^2/s^2] (as SpeedSchedule
    /// converts, for the failure message only).
    double
    rpm_of(const double w)
    {
      const double omega = std::sqrt(w);
      return omega * 60. / (2. * dealii::numbers::PI);
    }
  } // namespace

  void
  ActiveSetIteration::initialize(const ContactPairs &pairs_,
                                 const unsigned int  max_iterations_,
                                 const bool          on_exact_path)
  {
    pairs          = &pairs_;
    max_iterations = max_iterations_;
    exact          = on_exact_path;
  }

  void
  ActiveSetIteration::settle(const double                w,
                             ContactState               &state,
                             const ContactDecomposition &current,
                             const Decompose            &decompose) const
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
          decompose(active, w);
        ++iterations;
        ++state.active_set_iterations;
        current.evaluate(w, state);
        const std::vector<bool> next = next_active_set(active, state);
        if (next == active)
          break;
        seen.insert(active);
        std::vector<bool> proposal;
        if (iterations >= max_iterations ||
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
      report_unsettled(w, iterations, state);
    state.converged &= settled;
  }

  void
  ActiveSetIteration::report_unsettled(const double       w,
                                       const unsigned int iterations,
                                       ContactState      &state) const
  {
    std::ostringstream m;
    m << "active set not settled (" << iterations << " iterations; " << state.flipped_back
      << " pairs flipped back"
      << (exact ? ", at " + std::to_string(rpm_of(w)) + " r/min on the path" : std::string())
      << ")";
    state.reason += (state.reason.empty() ? "" : "; ") + m.str();
  }

  std::vector<bool>
  ActiveSetIteration::next_active_set(const std::vector<bool> &active,
                                      const ContactState      &state) const
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
  ActiveSetIteration::guard_cycling(const std::vector<bool>           &active,
                                    const std::vector<bool>           &next,
                                    const ContactState                &state,
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
