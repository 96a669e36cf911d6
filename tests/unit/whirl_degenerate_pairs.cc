// WhirlStations::separate_degenerate_pairs (doc/theory.md 9.3): two modes
// with |lambda_1 - lambda_2| <= 1e-3 |lambda_1| that are complex mixtures of
// a forward and a backward circular orbit (with axial motion as well) come
// out as the pure forward and backward shapes: whirl ratio +1 / -1, parallel
// to the pure shapes, unit norm, m_phi = M phi carried along (M = I); the
// forward one on the slot of the higher frequency (the first on a tie).
// Pairs further apart are left alone.

#include "unit_check.h"
#include "whirl_fixture.h"

using namespace rotorfit_unit;

namespace
{
  const rotorfit::ComplexVector F = circular(+1, profile(), {0.3, -0.2, 0.1, 0.25});
  const rotorfit::ComplexVector B = circular(-1, profile(), {-0.1, 0.4, cplx(0, 0.2)});

  rotorfit::ComplexVector
  mix(const cplx a, const cplx b)
  {
    rotorfit::ComplexVector phi = zero_vector();
    for (unsigned int i = 0; i < phi.re.size(); ++i)
      set(phi, i, a * get(F, i) + b * get(B, i));
    return phi;
  }

  double
  max_difference(const rotorfit::ComplexVector &a, const rotorfit::ComplexVector &b)
  {
    double d = 0;
    for (unsigned int i = 0; i < a.re.size(); ++i)
      {
        const double e = std::abs(get(a, i) - get(b, i));
        if (!(e <= d))
          d = e;
      }
    return d;
  }

  /// Modes 1 and 2 of {other, m1, m2, other} with frequencies f1, f2 [Hz];
  /// @p forward_slot: 1 or 2.
  void
  check_pair(Checks &check, const std::string &name, const double f1, const double f2,
             const unsigned int forward_slot)
  {
    const rotorfit::WhirlStations    ws = stations();
    std::vector<rotorfit::WhirlMode> modes;
    // neighbours at other frequencies (not degenerate with the pair)
    modes.push_back(mode(circular(+1, {0.2, 1., 0.3}), {-1., 2 * M_PI * 50.}));
    modes.push_back(mode(mix({0.6, 0.2}, {-0.5, 0.7}), {-1., 2 * M_PI * f1}));
    modes.push_back(mode(mix({0.3, -0.9}, {0.8, 0.1}), {-1., 2 * M_PI * f2}));
    modes.push_back(mode(circular(-1, {0.2, 1., 0.3}), {-1., 2 * M_PI * 150.}));
    const std::vector<rotorfit::WhirlMode> before = modes;

    // the input is mixed: ratios strictly inside (-1, 1)
    for (unsigned int j = 1; j <= 2; ++j)
      {
        rotorfit::WhirlMode m = modes[j];
        ws.classify(m);
        std::printf("  %s: mode %u before: whirl ratio %.6f\n", name.c_str(), j, m.whirl_ratio);
      }

    ws.separate_degenerate_pairs(modes);

    for (unsigned int j = 1; j <= 2; ++j)
      {
        const bool         forward = (j == forward_slot);
        rotorfit::WhirlMode m       = modes[j];
        ws.classify(m);
        const std::string  what = name + ", slot " + std::to_string(j) + " (" +
                                 std::to_string(m.frequency_hz()) + " Hz): ";
        check.near(what + "whirl ratio", m.whirl_ratio, forward ? 1. : -1., 1e-12,
                   forward ? "closed form +1 (forward circle)" : "closed form -1 (backward circle)");
        check.equal(what + "whirl", m.whirl, std::string(forward ? "forward" : "backward"),
                    "label of that ratio");
        check.near(what + "|phi^H F|^2 / (|phi|^2 |F|^2)" + (forward ? "" : " for B"),
                   parallel(m.phi, forward ? F : B), 1., 1e-12,
                   "exact: the pure shape spans the result");
        check.near(what + "|phi|", std::sqrt(dot(m.phi, m.phi).real()), 1., 1e-14,
                   "documented normalisation");
        check.near(what + "max |m_phi - phi| (M = I)", max_difference(m.m_phi, m.phi), 0., 1e-14,
                   "exact: m_phi combined like phi");
        check.equal(what + "lambda unchanged", m.lambda == before[j].lambda, true, "input lambda");
      }
    for (const unsigned int j : {0u, 3u})
      check.near(name + ": neighbour " + std::to_string(j) + " untouched",
                 max_difference(modes[j].phi, before[j].phi), 0., 0., "input shape");
  }
} // namespace

int
main()
{
  Checks check;
  // frequencies 2e-4 apart (inside the 1e-3 band): forward on the higher
  check_pair(check, "second higher", 100., 100.02, 2);
  check_pair(check, "first higher", 100.02, 100., 1);
  check_pair(check, "equal", 100., 100., 1);

  // 1 % apart: not a degenerate pair, left as it is
  {
    const rotorfit::WhirlStations    ws = stations();
    std::vector<rotorfit::WhirlMode> modes;
    modes.push_back(mode(mix({0.6, 0.2}, {-0.5, 0.7}), {-1., 2 * M_PI * 100.}));
    modes.push_back(mode(mix({0.3, -0.9}, {0.8, 0.1}), {-1., 2 * M_PI * 101.}));
    const auto before = modes;
    ws.separate_degenerate_pairs(modes);
    for (unsigned int j = 0; j < 2; ++j)
      check.near("1 % apart: mode " + std::to_string(j) + " untouched",
                 max_difference(modes[j].phi, before[j].phi), 0., 0., "input shape");
  }
  return check.finish();
}
