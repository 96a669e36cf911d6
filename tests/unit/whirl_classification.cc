// WhirlStations::classify on hand-made mode shapes (doc/theory.md 9.2):
// circular orbits give the whirl ratio +1 / -1, planar ones 0 (mixed),
// ellipses 2ab/(a^2 + b^2) from their semi-axes and, built from forward and
// backward circles, sum(|a_f|^2 - |a_b|^2) / sum(|a_f|^2 + |a_b|^2); modes
// whose stations do not move laterally are non-lateral.

#include "unit_check.h"
#include "whirl_fixture.h"

using namespace rotorfit_unit;

namespace
{
  void
  expect(Checks &check, const rotorfit::WhirlStations &ws, const std::string &name,
         const rotorfit::ComplexVector &phi, const double ratio, const std::string &whirl,
         const std::string &kind)
  {
    rotorfit::WhirlMode m = mode(phi);
    ws.classify(m);
    check.near(name + ": whirl ratio", m.whirl_ratio, ratio, 1e-14, kind);
    check.equal(name + ": whirl", m.whirl, whirl, "label of that ratio (|ratio| >= 0.1)");
  }

  /// Ellipse with semi-axes a (along the tilt psi) and b, phase phi, at each
  /// station scaled by @p scale: x + iy = e^{i psi} (a cos tau + i b sin tau),
  /// tau = beta t + phi; counter-clockwise (forward) for b > 0.
  rotorfit::ComplexVector
  ellipse(const double a, const double b, const double psi, const double phase)
  {
    const std::vector<double> scale = {1.0, 0.5, 0.8};
    std::vector<cplx>         X(n_stations), Y(n_stations);
    for (unsigned int k = 0; k < n_stations; ++k)
      {
        // local axes: u = Re(U e^{i beta t}), v = Re(V e^{i beta t})
        const cplx U = scale[k] * a * std::polar(1., phase);
        const cplx V = scale[k] * b * cplx(0, -1) * std::polar(1., phase);
        X[k]         = std::cos(psi) * U - std::sin(psi) * V;
        Y[k]         = std::sin(psi) * U + std::cos(psi) * V;
      }
    return orbits(X, Y);
  }
} // namespace

int
main()
{
  Checks                        check;
  const rotorfit::WhirlStations ws = stations();
  const std::vector<cplx>       s  = profile();

  // x = cos(beta t), y = sin(beta t): X = 1, Y = -i (doc/theory.md 9.2)
  expect(check, ws, "forward circle (X = s, Y = -i s)", circular(+1), 1., "forward",
         "closed form +1");
  expect(check, ws, "backward circle (X = s, Y = +i s)", circular(-1), -1., "backward",
         "closed form -1");
  expect(check, ws, "forward circle with axial motion", circular(+1, s, {0.3, -0.2, 0.1}), 1.,
         "forward", "closed form +1 (z does not count)");
  expect(check, ws, "planar (Y = 0)", orbits(s, {0., 0., 0.}), 0., "mixed", "closed form 0");
  {
    std::vector<cplx> X(n_stations), Y(n_stations);
    for (unsigned int k = 0; k < n_stations; ++k)
      {
        X[k] = std::cos(0.7) * s[k];
        Y[k] = std::sin(0.7) * s[k];
      }
    expect(check, ws, "planar, tilted 0.7 rad", orbits(X, Y), 0., "mixed", "closed form 0");
  }

  // ellipses by their semi-axes: 2ab/(a^2 + b^2)
  expect(check, ws, "ellipse a = 2, b = 1", ellipse(2, 1, 0.4, 0.7), 0.8, "forward",
         "closed form 2ab/(a^2+b^2)");
  expect(check, ws, "ellipse a = 2, b = -1", ellipse(2, -1, -1.1, 2.5), -0.8, "backward",
         "closed form 2ab/(a^2+b^2)");
  expect(check, ws, "ellipse a = 1, b = 0.025", ellipse(1, 0.025, 0.3, -0.4),
         2 * 0.025 / (1 + 0.025 * 0.025), "mixed", "closed form 2ab/(a^2+b^2)");

  // forward and backward circles a_f, a_b per station: X = a_f + a_b,
  // Y = -i (a_f - a_b), i.e. x + iy = a_f e^{i beta t} + conj(a_b) e^{-i beta t}
  {
    const std::vector<cplx> af = {std::polar(0.8, 0.3), std::polar(0.5, -1.1), std::polar(0.2, 2.)};
    const std::vector<cplx> ab = {std::polar(0.3, -0.7), std::polar(0.45, 0.2), std::polar(0.6, 0.9)};
    std::vector<cplx>       X(n_stations), Y(n_stations);
    double                  num = 0, den = 0;
    for (unsigned int k = 0; k < n_stations; ++k)
      {
        X[k] = af[k] + ab[k];
        Y[k] = cplx(0, -1) * (af[k] - ab[k]);
        num += std::norm(af[k]) - std::norm(ab[k]);
        den += std::norm(af[k]) + std::norm(ab[k]);
      }
    expect(check, ws, "elliptic orbits from a_f, a_b", orbits(X, Y), num / den, "forward",
           "closed form sum(|a_f|^2-|a_b|^2)/sum(|a_f|^2+|a_b|^2) = 0.2775/1.5825");
  }

  // no lateral station motion
  {
    rotorfit::ComplexVector phi = zero_vector();
    for (unsigned int i = 0; i < n_nodes; ++i)
      set(phi, 3 * i + 2, std::polar(1. + i, 0.3 * i));
    expect(check, ws, "axial motion only", phi, 0., "non-lateral", "closed form 0");
  }
  {
    // the two nodes of each station move against each other: 0.25 a + 0.75 (-a/3) = 0
    rotorfit::ComplexVector phi = zero_vector();
    for (unsigned int k = 0; k < n_stations; ++k)
      {
        set(phi, 3 * (2 * k), s[k]);
        set(phi, 3 * (2 * k) + 1, cplx(0, -1) * s[k]);
        set(phi, 3 * (2 * k + 1), -s[k] / 3.);
        set(phi, 3 * (2 * k + 1) + 1, cplx(0, 1) * s[k] / 3.);
      }
    rotorfit::WhirlMode m = mode(phi);
    ws.classify(m);
    check.equal("lateral node motion cancelling in every station: whirl", m.whirl,
                std::string("non-lateral"), "station amplitude 0 < 1 % of the largest node");
  }
  // the 1 % limit: circular orbits of station amplitude sqrt(2) 0.005 and
  // sqrt(2) 0.02 beside an axial node amplitude 1
  for (const double a : {0.005, 0.02})
    {
      std::vector<cplx> z(n_nodes, 0.);
      z[n_nodes - 1] = 1.;
      expect(check, ws, "circle of amplitude " + std::to_string(a) + " beside axial 1",
             circular(+1, {a, a, a}, z), 1., a < 0.01 ? "non-lateral" : "forward",
             "closed form +1");
    }
  return check.finish();
}
