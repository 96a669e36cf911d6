#include <rotorfit/contact/contact_pairs.h>
#include <rotorfit/statics/stress_field.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace rotorfit
{
  using namespace dealii;

  void
  StressField::find_fits(const ContactPairs &pairs)
  {
    const auto &list = pairs.pairs();
    fit_list.clear();
    ring.clear();
    for (unsigned int f = 0; f < pairs.n_interfaces(); ++f)
      {
        Fit fit;
        fit.shaft_body = pairs.bodies(f)[0];
        fit.hub_body   = pairs.bodies(f)[1];
        fit.z_min      = std::numeric_limits<double>::max();
        fit.z_max      = -fit.z_min;
        for (const auto p : pairs.pairs_of(f))
          {
            const Point<3> &x = list[p].position;
            fit.z_min         = std::min(fit.z_min, x[2]);
            fit.z_max         = std::max(fit.z_max, x[2]);
            fit.radius += std::hypot(x[0], x[1]);
          }
        fit.radius /= pairs.pairs_of(f).size();
        const double z = fit.z_mid();
        // the traction of the hub's bore at the mid-plane: the mean pressure
        // of a ring of pairs there (one pair's pressure oscillates between
        // the vertex and edge nodes of quadratic elements), at least the
        // ring nearest to the mid-plane, at most an eighth of the fit's length
        double nearest = std::numeric_limits<double>::max();
        for (const auto p : pairs.pairs_of(f))
          nearest = std::min(nearest, std::abs(list[p].position[2] - z));
        const double band = std::max(0.125 * (fit.z_max - fit.z_min), nearest * (1 + 1e-9) + 1e-12);
        std::vector<unsigned int> ring_pairs;
        for (const auto p : pairs.pairs_of(f))
          if (std::abs(list[p].position[2] - z) <= band)
            ring_pairs.push_back(p);
        ring.push_back(ring_pairs);
        fit_list.push_back(fit);
      }
  }

  double
  StressField::ring_pressure(const unsigned int f, const std::vector<double> &pair_pressure) const
  {
    double p = 0;
    for (const auto i : ring[f])
      p += pair_pressure[i] / ring[f].size();
    return p;
  }

  StressField::BoreStress
  StressField::surface_stress(const double e_tt, const double e_zz, const double e_tz,
                              const double s_r, const double lambda, const double mu)
  {
    const double e_rr = (s_r - lambda * (e_tt + e_zz)) / (lambda + 2 * mu);
    const double tr   = e_rr + e_tt + e_zz;
    BoreStress   b;
    b.sigma_r         = s_r;
    b.sigma_t         = lambda * tr + 2 * mu * e_tt;
    b.sigma_z         = lambda * tr + 2 * mu * e_zz;
    const double t_tz = 2 * mu * e_tz;
    b.von_mises = std::sqrt(b.sigma_r * b.sigma_r + b.sigma_t * b.sigma_t + b.sigma_z * b.sigma_z -
                            b.sigma_r * b.sigma_t - b.sigma_t * b.sigma_z - b.sigma_z * b.sigma_r +
                            3 * t_tz * t_tz);
    return b;
  }

  bool
  StressField::before(const double a, const Point<3> &pa, const double b, const Point<3> &pb)
  {
    if (a != b)
      return a > b;
    return std::lexicographical_compare(pa.begin_raw(), pa.end_raw(), pb.begin_raw(), pb.end_raw());
  }
} // namespace rotorfit
