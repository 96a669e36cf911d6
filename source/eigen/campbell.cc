#include <rotorfit/eigen/campbell.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
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
  Campbell::mac(const ComplexVector &a, const ComplexVector &m_a,
                const ComplexVector &b, const ComplexVector &m_b)
  {
    const double ab = std::norm(dot(a, m_b));
    const double aa = dot(a, m_a).real(), bb = dot(b, m_b).real();
    return aa > 0 && bb > 0 ? ab / (aa * bb) : 0.;
  }

  void
  Campbell::open(const std::string               &directory,
                 const bool                       root_,
                 const std::vector<unsigned int> &orders_,
                 const double                     mac_threshold)
  {
    root      = root_;
    orders    = orders_;
    threshold = mac_threshold;
    if (!root)
      return;
    campbell_csv.open(directory + "/campbell.csv");
    campbell_csv << "speed_rpm,mode,tracked_id,whirl,frequency_hz,damping_ratio,"
                    "log_dec,stable,backward_error,fit_state,static_converged,contact_asymmetry\n"
                 << std::setprecision(10) << std::flush;
    critical_csv.open(directory + "/critical_speeds.csv");
    critical_csv << "tracked_id,whirl,order,speed_rpm,frequency_hz\n"
                 << std::setprecision(10) << std::flush;
  }

  void
  Campbell::add_speed(const double            rpm,
                      std::vector<WhirlMode> &modes,
                      const std::string      &fit_state,
                      const bool              static_converged,
                      const double            asymmetry)
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

    std::vector<Track> current;
    for (unsigned int b = 0; b < modes.size(); ++b)
      {
        const WhirlMode &m      = modes[b];
        const double     f      = m.frequency_hz();
        const double     zeta   = -m.lambda.real() / std::abs(m.lambda);
        const double     logdec = -2 * M_PI * m.lambda.real() / m.lambda.imag();
        if (root)
          campbell_csv << rpm << ',' << b + 1 << ',' << m.tracked_id << ','
                       << m.whirl << ',' << f << ',' << zeta << ',' << logdec << ','
                       // undamped modes (Re = 0 up to round-off) count as stable
                       << (m.lambda.real() <= 1e-8 * std::abs(m.lambda) ? 1 : 0)
                       << ',' << m.backward_error
                       << ',' << fit_state << ',' << (static_converged ? 1 : 0) << ','
                       << asymmetry << '\n';
        // k X crossings between the previous speed and this one
        if (match[b] >= 0)
          for (const unsigned int k : orders)
            {
              const double h0 = previous[match[b]].frequency_hz - k * previous_rpm / 60.;
              const double h1 = f - k * rpm / 60.;
              if ((h0 > 0 && h1 <= 0) || (h0 < 0 && h1 >= 0))
                {
                  const double s = previous_rpm + (rpm - previous_rpm) * h0 / (h0 - h1);
                  ++n_critical;
                  if (root)
                    critical_csv << m.tracked_id << ',' << m.whirl << ',' << k << ','
                                 << s << ',' << k * s / 60. << '\n';
                }
            }
        current.push_back({m.tracked_id, f, m.whirl, m.phi, m.m_phi});
      }
    if (root)
      {
        campbell_csv << std::flush;
        critical_csv << std::flush;
      }
    previous     = std::move(current);
    previous_rpm = rpm;
  }
} // namespace rotorfit
