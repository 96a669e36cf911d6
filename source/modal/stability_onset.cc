#include <rotorfit/base/format.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/modal/line_root.h>
#include <rotorfit/modal/stability_onset.h>

#include <cmath>
#include <iomanip>
#include <sstream>

namespace rotorfit
{
  namespace
  {
    /// Damping ratios below this are neutral (no sign to change).
    constexpr double neutral = 1e-8;

    double
    damping_ratio(const std::complex<double> lambda)
    {
      return -lambda.real() / std::abs(lambda);
    }
  } // namespace

  std::vector<StabilityOnset>
  StabilityOnsets::find(const ModalResult       &current,
                        const StaticState       &state,
                        SpeedEigenproblem &eigen)
  {
    std::vector<StabilityOnset> onsets;
    std::vector<const WhirlMode *> changed;
    if (previous_rpm >= 0)
      for (const auto &m : current.modes)
        {
          const auto it = previous.find(m.tracked_id);
          if (it == previous.end())
            continue;
          // an undamped line has |zeta| of round-off (1e-15 .. 1e-12) and
          // either sign: a sign change counts only beyond the noise
          const double z0 = it->second.zeta, z1 = damping_ratio(m.lambda);
          if (std::abs(z0) > neutral && std::abs(z1) > neutral && (z0 > 0) != (z1 > 0))
            changed.push_back(&m);
        }
    for (const WhirlMode *line : changed)
      {
        const StabilityOnset o = root_solve(*line, current.rpm, state, eigen);
        std::ostringstream m;
        m << "Stability onset: line " << o.tracked_id << " (" << o.whirl << ", "
          << std::setprecision(5) << o.frequency_hz << " Hz) is " << o.direction << ' '
          << format_number(o.rpm) << " r/min (damping ratio zero; " << o.evaluations
          << " eigen solves" << (o.converged ? "" : ", NOT converged: the bracket is kept")
          << ")\n";
        log << m.str();
        onsets.push_back(o);
        found.push_back(o);
      }
    previous.clear();
    for (const auto &m : current.modes)
      previous[m.tracked_id] = {damping_ratio(m.lambda), m.frequency_hz(), m.whirl};
    previous_rpm = current.rpm;
    return onsets;
  }

  StabilityOnset
  StabilityOnsets::root_solve(const WhirlMode         &line,
                              const double             rpm_b,
                              const StaticState       &state,
                              SpeedEigenproblem &eigen) const
  {
    StabilityOnset o;
    o.tracked_id    = line.tracked_id;
    o.whirl         = line.whirl;
    const double fa = previous.at(line.tracked_id).zeta;
    o.direction     = fa > 0 ? "unstable above" : "stable above";
    const LineRoot root =
      solve_line_root(line, previous_rpm, fa, rpm_b, damping_ratio(line.lambda),
                      [](const std::complex<double> l, double) { return damping_ratio(l); },
                      1e-10, state, eigen, log,
                      "stability onset of line " + std::to_string(line.tracked_id));
    o.rpm          = root.rpm;
    o.frequency_hz = root.lambda.imag() / (2 * M_PI);
    o.evaluations  = root.evaluations;
    o.converged    = root.converged;
    return o;
  }

  void
  StabilityOnsets::finish(Summary &summary) const
  {
    summary.add("modal.stability_onsets", found.size());
    if (!found.empty())
      summary.add("modal.first_stability_onset_rpm", found.front().rpm);
  }
} // namespace rotorfit
