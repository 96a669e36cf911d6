#include <rotorfit/response/response_peaks.h>
#include <rotorfit/response/unbalance_response.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace rotorfit
{
  namespace
  {
    const double nan = std::numeric_limits<double>::quiet_NaN();

    /// Where the line through (x0, y0), (x1, y1) reaches @p y.
    double
    crossing(const double x0, const double y0, const double x1, const double y1, const double y)
    {
      return x0 + (y - y0) * (x1 - x0) / (y1 - y0);
    }

    /// Separation margin [%] of a peak at @p rpm from [lo, hi] and what the
    /// API 617 (7th ed.) / 684 rule asks for its amplification factor:
    /// none below AF 2.5; below the range min(16, 17 (1 - 1/(AF - 1.5))),
    /// above it min(26, 10 + 17 (1 - 1/(AF - 1.5))). Inside the range the
    /// margin is negative: minus the distance to the nearer end.
    void
    margins(const double rpm, const double af, const bool resolved, const double lo,
            const double hi, double &margin, double &required)
    {
      // an unresolved peak's AF is a lower bound: ask for the cap
      const double below = !resolved ? 16. :
                           std::isfinite(af) && af >= 2.5 ?
                                       std::min(16., 17 * (1 - 1 / (af - 1.5))) : 0.;
      const double above = !resolved ? 26. :
                           std::isfinite(af) && af >= 2.5 ?
                                       std::min(26., 10 + 17 * (1 - 1 / (af - 1.5))) : 0.;
      if (rpm < lo)
        margin = 100 * (lo - rpm) / lo, required = below;
      else if (rpm > hi)
        margin = 100 * (rpm - hi) / hi, required = above;
      else
        margin = -100 * std::min(rpm - lo, hi - rpm) / hi, required = std::max(below, above);
      // a resolved peak without an AF (half power beyond the sweep) has no
      // rule to apply; an unresolved one keeps the cap
      if (!std::isfinite(af) && resolved)
        required = nan;
    }

    /// The peak at the local maximum @p i of the amplitudes @p a at the
    /// speeds @p x; none if it falls to half power on neither side.
    std::optional<ResponsePeak>
    peak_at(const std::vector<double> &x, const std::vector<double> &a, const unsigned int i)
    {
      ResponsePeak peak;
      // the parabola through the three points around the top
      const double x0 = x[i - 1], x1 = x[i], x2 = x[i + 1];
      const double d01 = (a[i] - a[i - 1]) / (x1 - x0), d12 = (a[i + 1] - a[i]) / (x2 - x1);
      const double c2 = (d12 - d01) / (x2 - x0), c1 = d01 - c2 * (x0 + x1);
      peak.rpm       = c2 < 0 ? std::clamp(-c1 / (2 * c2), x0, x2) : x1;
      peak.amplitude = std::max(a[i], a[i - 1] + (peak.rpm - x0) * (d01 + c2 * (peak.rpm - x1)));
      // half-power points: where the amplitude falls to peak / sqrt 2
      const double level = peak.amplitude / std::sqrt(2.);
      unsigned int above = 1;
      for (unsigned int j = i; j > 0 && a[j - 1] >= level; --j)
        ++above;
      for (unsigned int j = i; j + 1 < x.size() && a[j + 1] >= level; ++j)
        ++above;
      peak.resolved = above >= 3;
      peak.low_rpm = peak.high_rpm = nan;
      // the inner end of a crossing is the sample, or the parabola's top
      // when even the highest sample lies below half power (a peak far
      // sharper than the speed step)
      const auto inner = [&](const unsigned int j) {
        return a[j] >= level ? std::make_pair(x[j], a[j]) :
                               std::make_pair(peak.rpm, peak.amplitude);
      };
      for (unsigned int j = i; j > 0; --j)
        if (a[j - 1] < level)
          {
            const auto [xj, aj] = inner(j);
            peak.low_rpm        = crossing(x[j - 1], a[j - 1], xj, aj, level);
            break;
          }
      for (unsigned int j = i; j + 1 < x.size(); ++j)
        if (a[j + 1] < level)
          {
            const auto [xj, aj] = inner(j);
            peak.high_rpm       = crossing(xj, aj, x[j + 1], a[j + 1], level);
            break;
          }
      // a wiggle that falls to half power on neither side is no resonance;
      // one side beyond the sweep: kept with AF = nan
      if (std::isnan(peak.low_rpm) && std::isnan(peak.high_rpm))
        return std::nullopt;
      peak.amplification_factor =
        peak.high_rpm > peak.low_rpm ? peak.rpm / (peak.high_rpm - peak.low_rpm) : nan;
      return peak;
    }
  } // namespace

  std::vector<ResponsePeak>
  find_response_peaks(const std::vector<ResponseAtSpeed> &history,
                      const std::vector<double>          &operating)
  {
    std::vector<ResponsePeak> out;
    if (history.empty())
      return out;
    for (unsigned int p = 0; p < history.front().probes.size(); ++p)
      {
        std::vector<double> x, a;
        for (const auto &h : history)
          {
            x.push_back(h.rpm);
            a.push_back(h.probes[p].forward() + h.probes[p].backward()); // major semi-axis
          }
        // a probe that no longer moves (a loose body carries the unbalance
        // away from it) shows round-off wiggles: not peaks
        const double floor = 1e-6 * *std::max_element(a.begin(), a.end());
        for (unsigned int i = 1; i + 1 < x.size(); ++i)
          {
            if (!(a[i] > a[i - 1] && a[i] >= a[i + 1]) || !(a[i] > floor))
              continue;
            auto peak = peak_at(x, a, i);
            if (!peak)
              continue;
            peak->probe     = history.front().probes[p].probe;
            peak->fit_state = history[i].fit_state;
            peak->separation_margin = peak->required_margin = nan;
            if (operating.size() == 2)
              margins(peak->rpm, peak->amplification_factor, peak->resolved, operating[0],
                      operating[1], peak->separation_margin, peak->required_margin);
            out.push_back(*peak);
          }
      }
    return out;
  }
} // namespace rotorfit
