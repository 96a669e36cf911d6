#include <rotorfit/linear_algebra/blas.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/modal/mode_tracker.h>

#include <deal.II/base/utilities.h>

#include <algorithm>
#include <cmath>
#include <tuple>

namespace rotorfit
{
  ModeTracker
  ModeTracker::from_parameters(const dealii::ParameterHandler &prm)
  {
    const auto list = dealii::Utilities::split_string_list(prm.get("Excitation orders"), ',');
    check_unique(list, "Eigenproblem/Excitation orders");
    std::vector<unsigned int> orders;
    for (const auto &o : list)
      orders.push_back(dealii::Utilities::string_to_int(o));
    return ModeTracker(orders, prm.get_double("MAC threshold"));
  }

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

    /// [x_1.re .. x_p.re x_1.im .. x_p.im] (n x 2p, column-major)
    std::vector<double>
    packed(const std::vector<const ComplexVector *> &x)
    {
      const std::size_t   n = x.empty() ? 0 : x[0]->re.size(), p = x.size();
      std::vector<double> out(n * 2 * p);
      for (std::size_t j = 0; j < p; ++j)
        {
          std::copy(x[j]->re.begin(), x[j]->re.end(), out.begin() + j * n);
          std::copy(x[j]->im.begin(), x[j]->im.end(), out.begin() + (p + j) * n);
        }
      return out;
    }

    /// a_i^H b_j for all i, j (p x q, row-major): one dense product over the
    /// packed parts instead of four vector dot products per pair (a sweep's
    /// tracking compared every pair of 12 modes, each pair reading 12 vectors:
    /// a tenth of a reduced speed on TS)
    std::vector<std::complex<double>>
    cross_products(const std::vector<const ComplexVector *> &a,
                   const std::vector<const ComplexVector *> &b)
    {
      const int p = a.size(), q = b.size();
      if (p == 0 || q == 0)
        return {};
      const int n = a[0]->re.size(), rows = 2 * p, cols = 2 * q;
      if (n == 0)
        return std::vector<std::complex<double>>(p * q, 0.);
      for (const auto &list : {a, b})
        for (const ComplexVector *x : list)
          if (static_cast<int>(x->re.size()) != n || static_cast<int>(x->im.size()) != n)
            {
              std::vector<std::complex<double>> out; // (not one length: pair by pair)
              for (const ComplexVector *x_a : a)
                for (const ComplexVector *x_b : b)
                  out.push_back(x_a->re.size() == x_b->re.size() ? dot(*x_a, *x_b) : 0.);
              return out;
            }
      const double        one = 1, zero = 0;
      std::vector<double> A = packed(a), B = packed(b), P(rows * cols);
      dgemm_("T", "N", &rows, &cols, &n, &one, A.data(), &n, B.data(), &n, &zero, P.data(), &rows);
      // P(r, c) = A_r . B_c; re/re at (i, j), im/im at (p+i, q+j), ...
      const auto at = [&](const int r, const int c) { return P[r + c * rows]; };
      std::vector<std::complex<double>> out(p * q);
      for (int i = 0; i < p; ++i)
        for (int j = 0; j < q; ++j)
          out[i * q + j] = {at(i, j) + at(p + i, q + j), at(i, q + j) - at(p + i, j)};
      return out;
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
    std::vector<const ComplexVector *> phi_a, m_phi_b;
    std::vector<double>                aa, bb;
    for (const auto &line : previous)
      {
        phi_a.push_back(&line.phi);
        aa.push_back(line.m_norm);
      }
    for (const auto &mode : modes)
      {
        m_phi_b.push_back(&mode.m_phi);
        bb.push_back(dot(mode.phi, mode.m_phi).real());
      }
    const std::vector<std::complex<double>> ab = cross_products(phi_a, m_phi_b);
    std::vector<std::tuple<double, unsigned int, unsigned int>> candidates;
    for (unsigned int a = 0; a < previous.size(); ++a)
      for (unsigned int b = 0; b < modes.size(); ++b)
        if (compatible(previous[a].whirl, modes[b].whirl))
          {
            const double m = aa[a] > 0 && bb[b] > 0 ?
                               std::norm(ab[a * modes.size() + b]) / (aa[a] * bb[b]) :
                               0.;
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
        current.push_back({m.tracked_id, f, zeta(m), m.whirl, m.phi, bb[b]});
      }
    previous     = std::move(current);
    previous_rpm = rpm;
    return crossings;
  }
} // namespace rotorfit
