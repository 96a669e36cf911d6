#include <rotorfit/modal/mode_tracker.h>

#include <algorithm>
#include <cmath>
#include <tuple>

namespace rotorfit
{
  namespace
  {
    std::complex<double>
    dot(const ComplexVector &a, const ComplexVector &b) // a^H b
    {
      return {a.re * b.re + a.im * b.im, a.re * b.im - a.im * b.re};
    }

    double
    zeta(const WhirlMode &m)
    {
      return -m.lambda.real() / std::abs(m.lambda);
    }

    bool
    compatible(const std::string &a, const std::string &b)
    {
      const auto directional = [](const std::string &w) {
        return w == "forward" || w == "backward";
      };
      return !(directional(a) && directional(b)) || a == b;
    }
  } // namespace

  double
  ModeTracker::mac(const ComplexVector &a, const ComplexVector &m_a,
                   const ComplexVector &b, const ComplexVector &m_b)
  {
    const double ab = std::norm(dot(a, m_b));
    const double aa = dot(a, m_a).real(), bb = dot(b, m_b).real();
    return aa > 0 && bb > 0 ? ab / (aa * bb) : 0.;
  }

  std::vector<CriticalSpeed>
  ModeTracker::track(const double rpm, std::vector<WhirlMode> &modes)
  {
    // greedy assignment on MAC, best first; whirl directions must agree
    std::vector<std::tuple<double, unsigned int, unsigned int>> candidates;
    for (unsigned int a = 0; a < previous.size(); ++a)
      for (unsigned int b = 0; b < modes.size(); ++b)
        if (compatible(previous[a].whirl, modes[b].whirl))
          {
            const double m = mac(previous[a].phi, previous[a].m_phi, modes[b].phi, modes[b].m_phi);
            if (m >= threshold)
              candidates.emplace_back(m, a, b);
          }
    std::sort(candidates.rbegin(), candidates.rend());
    std::vector<bool> used_a(previous.size(), false), used_b(modes.size(), false);
    std::vector<int>  match(modes.size(), -1);
    for (const auto &[m, a, b] : candidates)
      if (!used_a[a] && !used_b[b])
        {
          used_a[a] = used_b[b] = true;
          match[b]              = a;
          modes[b].tracked_id   = previous[a].id;
        }
    for (auto &mode : modes)
      if (mode.tracked_id == 0)
        mode.tracked_id = next_id++;

    std::vector<CriticalSpeed> crossings;
    std::vector<Line>          current;
    for (unsigned int b = 0; b < modes.size(); ++b)
      {
        const WhirlMode &m = modes[b];
        const double     f = m.frequency_hz();
        // k X crossings between the previous speed and this one
        if (match[b] >= 0)
          for (const unsigned int k : orders)
            {
              const double h0 = previous[match[b]].frequency_hz - k * previous_rpm / 60.;
              const double h1 = f - k * rpm / 60.;
              if ((h0 > 0 && h1 <= 0) || (h0 < 0 && h1 >= 0))
                {
                  const double t = h0 / (h0 - h1);
                  const double s = previous_rpm + (rpm - previous_rpm) * t;
                  const double z0 = previous[match[b]].damping_ratio;
                  CriticalSpeed c;
                  c.tracked_id    = m.tracked_id;
                  c.whirl         = m.whirl;
                  c.order         = k;
                  c.rpm           = s;
                  c.frequency_hz  = k * s / 60.;
                  c.damping_ratio = z0 + t * (zeta(m) - z0);
                  c.from_rpm      = previous_rpm;
                  c.from_value    = h0;
                  c.to_rpm        = rpm;
                  c.to_value      = h1;
                  crossings.push_back(c);
                }
            }
        current.push_back({m.tracked_id, f, zeta(m), m.whirl, m.phi, m.m_phi});
      }
    previous     = std::move(current);
    previous_rpm = rpm;
    return crossings;
  }
} // namespace rotorfit
