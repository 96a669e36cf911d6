#include <rotorfit/base/format.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/modal/mode_tracker.h>
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
                        PrestressedEigenproblem &eigen)
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
  StabilityOnsets::root_solve(const WhirlMode         &line_at_b,
                              const double             rpm_b,
                              const StaticState       &state,
                              PrestressedEigenproblem &eigen) const
  {
    const WhirlMode *line = &line_at_b;
    StabilityOnset o;
    o.tracked_id = line->tracked_id;
    o.whirl      = line->whirl;
    double a = previous_rpm, fa = previous.at(line->tracked_id).zeta;
    double b = rpm_b, fb = damping_ratio(line->lambda);
    o.direction = fa > 0 ? "unstable above" : "stable above";
    o.rpm          = b;
    o.frequency_hz = line->frequency_hz();
    int side       = 0; // Illinois: halve the weight of an end kept twice
    for (o.evaluations = 0; o.evaluations < 40; ++o.evaluations)
      {
        if (std::abs(b - a) <= 1e-6 * std::abs(b) || fb == 0)
          {
            o.converged = true;
            break;
          }
        const double c = (a * fb - b * fa) / (fb - fa);
        StaticState trial = state; // the later speed's affine law
        trial.rpm         = c;
        EigenSolution s;
        try
          {
            s = eigen.solve(trial);
          }
        catch (const SolverFailure &e)
          {
            log << "Warning: stability onset of line " << o.tracked_id
                << ": the eigensolver failed at " << c << " r/min (" << e.what()
                << "); the bracket is kept.\n";
            break;
          }
        double best = -1, fc = 0, freq = 0;
        for (const auto &p : s.elastic)
          {
            const double mac = ModeTracker::mac(line->phi, line->m_phi, p.phi, p.m_phi);
            if (mac > best)
              best = mac, fc = damping_ratio(p.lambda), freq = p.lambda.imag() / (2 * M_PI);
          }
        o.rpm          = c;
        o.frequency_hz = freq;
        if (std::abs(fc) < 1e-10)
          {
            o.converged = true;
            ++o.evaluations;
            break;
          }
        if ((fc > 0) == (fb > 0))
          {
            b = c, fb = fc;
            if (side == -1)
              fa /= 2;
            side = -1;
          }
        else
          {
            a = c, fa = fc;
            if (side == 1)
              fb /= 2;
            side = 1;
          }
      }
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
