// ModeTracker (doc/theory.md 9.4, 9.5): the complex MAC (1 for a vector with
// itself or a complex multiple, 0 for M-orthogonal vectors, 1/2 for a known
// pair); k X crossings of lines that are linear between two speeds at the
// line intersection n_c = (f0 - g n0)/(k/60 - g), g = (f1 - f0)/(n1 - n0),
// frequency k n_c/60; tracked ids kept when the modes come in another order;
// forward and backward never continue each other's line (mixed continues
// either); an unlike mode starts a new line.

#include <rotorfit/modal/mode_tracker.h>

#include "unit_check.h"
#include "whirl_fixture.h"

using namespace rotorfit_unit;
using rotorfit::ModeTracker;

namespace
{
  /// Unit vector e_j (M = I), perturbed by @p noise on DoF j + 1.
  rotorfit::ComplexVector
  shape(const unsigned int j, const double noise = 0)
  {
    rotorfit::ComplexVector phi = zero_vector();
    set(phi, j, std::polar(1., 0.3 * j));
    set(phi, j + 1, cplx(0, noise));
    return phi;
  }

  rotorfit::WhirlMode
  line_mode(const unsigned int j, const double f_hz, const std::string &whirl,
            const double noise = 0)
  {
    rotorfit::WhirlMode m = mode(shape(j, noise), {-1., 2 * M_PI * f_hz});
    m.whirl               = whirl;
    return m;
  }
} // namespace

int
main()
{
  Checks check;

  // --- MAC with M = I and with a diagonal M
  {
    const rotorfit::ComplexVector a = circular(+1), b = circular(-1);
    check.near("MAC(a, a)", ModeTracker::mac(a, a, a, a), 1., 1e-14, "exact 1");
    rotorfit::ComplexVector ca = zero_vector();
    for (unsigned int i = 0; i < ca.re.size(); ++i)
      set(ca, i, cplx(-0.3, 2.1) * get(a, i));
    check.near("MAC(a, (-0.3 + 2.1i) a)", ModeTracker::mac(a, a, ca, ca), 1., 1e-14, "exact 1");
    check.near("MAC(forward circle, backward circle)", ModeTracker::mac(a, a, b, b), 0., 1e-30,
               "exact 0 (doc/theory.md 9.4)");

    // M = diag(1, 2): a = (2, 1), b = (1, -1) are M-orthogonal, not orthogonal
    rotorfit::ComplexVector u{dealii::Vector<double>(2), dealii::Vector<double>(2)};
    rotorfit::ComplexVector v = u, mu = u, mv = u;
    u.re[0] = 2, u.re[1] = 1, mu.re[0] = 2, mu.re[1] = 2;
    v.re[0] = 1, v.re[1] = -1, mv.re[0] = 1, mv.re[1] = -2;
    check.near("MAC of M-orthogonal (2, 1), (1, -1), M = diag(1, 2)",
               ModeTracker::mac(u, mu, v, mv), 0., 1e-30, "exact 0");
    // (1, 0) and (1, 1) with M = I: 1/2
    rotorfit::ComplexVector p = u, q = u;
    p.re = 0, q.re = 0;
    p.re[0] = 1, q.re[0] = 1, q.re[1] = 1;
    check.near("MAC((1, 0), (1, 1))", ModeTracker::mac(p, p, q, q), 0.5, 1e-14, "exact 1/2");
  }

  // --- crossings: orders 1 and 2, five lines, speeds 10,000 -> 14,000 r/min
  {
    ModeTracker        tracker({1, 2}, 0.8);
    const double       n0 = 10000, n1 = 14000;
    const double       f0[5] = {200, 190, 340, 120, 100}, f1[5] = {210, 150, 460, 130, 300};
    const char        *whirl[5] = {"forward", "backward", "forward", "backward", "forward"};
    std::vector<rotorfit::WhirlMode> modes;
    for (unsigned int j = 0; j < 5; ++j)
      modes.push_back(line_mode(3 * j, f0[j], whirl[j]));
    const auto none = tracker.track(n0, modes);
    check.equal("crossings at the first speed", none.size(), std::size_t(0), "no previous speed");
    std::vector<unsigned int> id(5);
    for (unsigned int j = 0; j < 5; ++j)
      id[j] = modes[j].tracked_id;

    modes.clear();
    for (unsigned int j = 0; j < 5; ++j)
      modes.push_back(line_mode(3 * j, f1[j], whirl[j], 0.05));
    const auto crossings = tracker.track(n1, modes);
    // lines 0, 1: 1X downwards; line 2: 2X downwards; line 3: none; line 4: 1X upwards
    const unsigned int expected_line[4] = {0, 1, 2, 4}, expected_order[4] = {1, 1, 2, 1};
    check.equal("number of crossings", crossings.size(), std::size_t(4),
                "closed form: sign changes of f - k n/60");
    for (unsigned int c = 0; c < std::min<std::size_t>(4, crossings.size()); ++c)
      {
        const unsigned int j = expected_line[c], k = expected_order[c];
        const double       g = (f1[j] - f0[j]) / (n1 - n0);
        const double       n_c = (f0[j] - g * n0) / (k / 60. - g);
        const std::string  what = "line " + std::to_string(j) + " (" + whirl[j] + ") x " +
                                 std::to_string(k) + "X: ";
        check.equal(what + "tracked id", crossings[c].tracked_id, id[j], "its line");
        check.equal(what + "order", crossings[c].order, k, "the order crossed");
        check.equal(what + "whirl", crossings[c].whirl, std::string(whirl[j]), "its line");
        check.relative(what + "speed [r/min]", crossings[c].rpm, n_c, 1e-12,
                       "closed form: intersection of the line with k n/60");
        check.relative(what + "frequency [Hz]", crossings[c].frequency_hz, k * n_c / 60., 1e-12,
                       "closed form k n_c/60");
      }
    // the same crossing with the formula of doc/theory.md 9.5
    const double h0 = f0[0] - n0 / 60., h1 = f1[0] - n1 / 60.;
    if (!crossings.empty())
      check.relative("line 0 x 1X against n0 + (n1 - n0) h0/(h0 - h1)", crossings[0].rpm,
                     n0 + (n1 - n0) * h0 / (h0 - h1), 1e-12, "closed form (doc/theory.md 9.5)");
  }

  // --- swapped order, whirl compatibility, new lines
  {
    ModeTracker                      tracker({1}, 0.8);
    std::vector<rotorfit::WhirlMode> modes = {line_mode(0, 100, "forward"),
                                              line_mode(3, 110, "forward"),
                                              line_mode(6, 120, "backward"),
                                              line_mode(9, 130, "forward"),
                                              line_mode(12, 140, "mixed")};
    tracker.track(1000, modes);
    std::vector<unsigned int> id;
    for (const auto &m : modes)
      id.push_back(m.tracked_id);
    check.equal("first speed: ids 1..5 in order", id == std::vector<unsigned int>{1, 2, 3, 4, 5},
                true, "new lines numbered from 1");

    // next speed: the two forward lines come in swapped order, perturbed
    // (MAC 0.9975); a backward mode with forward line 4's shape and a
    // forward one with backward line 3's shape (MAC 1, incompatible whirl);
    // a forward mode with the shape of the mixed line 5; an unlike mode
    modes = {line_mode(3, 111, "forward", 0.05),    // line 2
             line_mode(0, 101, "forward", 0.05),    // line 1
             line_mode(9, 131, "backward"),         // shape of forward line 4
             line_mode(6, 121, "forward"),          // shape of backward line 3
             line_mode(12, 141, "forward", 0.05),   // mixed line 5 continues as forward
             line_mode(20, 150, "forward")};        // a shape not seen before
    tracker.track(1100, modes);
    check.equal("forward line 2, now listed first, keeps its id", modes[0].tracked_id, 2u,
                "MAC 0.9975 >= 0.8");
    check.equal("forward line 1, now listed second, keeps its id", modes[1].tracked_id, 1u,
                "MAC 0.9975 >= 0.8");
    check.equal("backward mode with forward line 4's shape: a new line (id > 5)",
                modes[2].tracked_id > 5, true, "forward never continues backward");
    check.equal("forward mode with backward line 3's shape: a new line (id > 5)",
                modes[3].tracked_id > 5, true, "backward never continues forward");
    check.equal("forward mode continues the mixed line 5", modes[4].tracked_id, 5u,
                "mixed matches either direction");
    check.equal("unlike mode: a new line (id > 5)", modes[5].tracked_id > 5, true,
                "MAC 0 < 0.8");
    check.equal("new lines get distinct ids",
                modes[2].tracked_id != modes[3].tracked_id &&
                  modes[3].tracked_id != modes[5].tracked_id &&
                  modes[2].tracked_id != modes[5].tracked_id,
                true, "one id per line");
  }
  return check.finish();
}
