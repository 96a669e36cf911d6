// iso286::deviations and iso286::fit against limit deviations read from the
// tables of ISO 286-2 (holes and shafts), exact to 0.01 um: the tables hold
// whole micrometres (halves for js), so any difference is a wrong number.
// Also: the Delta data against its definition IT_n - IT_(n-1) on every main
// step, the boundary convention ("over a up to and including b"), and the
// refusals, whose message must name the class (or fit) and the size.

#include <rotorfit/base/format.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/fit/iso286.h>

#include <string>
#include <vector>

#include "unit_check.h"

using namespace rotorfit;
using namespace rotorfit_unit;

namespace
{
  constexpr double tol_um = 0.01;
  const std::string table = "ISO 286-2 table";

  /// One class at @p d_mm against the table's lower and upper deviation [um].
  void
  check_class(Checks &checks, const std::string &cls, const double d_mm, const double lower_um,
              const double upper_um, const std::string &kind = table)
  {
    const auto dev  = iso286::deviations(cls, d_mm * 1e-3);
    const auto name = format_number(d_mm);
    checks.near(name + " mm " + cls + " lower [um]", dev.lower * 1e6, lower_um, tol_um, kind);
    checks.near(name + " mm " + cls + " upper [um]", dev.upper * 1e6, upper_um, tol_um, kind);
  }

  /// @p call must throw InputError whose message contains every one of @p words.
  template <typename Call>
  void
  check_refused(Checks &checks, const std::string &what, Call call,
                const std::vector<std::string> &words)
  {
    std::string message;
    try
      {
        call();
      }
    catch (const InputError &e)
      {
        message = e.what();
      }
    bool named = !message.empty();
    for (const auto &w : words)
      named = named && message.find(w) != std::string::npos;
    std::printf("  message: %s\n", message.empty() ? "(none thrown)" : message.c_str());
    checks.equal("refused, message names it: " + what, named, true,
                 "InputError naming the class and the size");
  }
} // namespace

int
main()
{
  Checks checks;

  // --- ISO 286-2 limit deviations [um] (lower, upper) ---------------------
  // holes H: 18..30 H7 0/+21; 30..50 H7 0/+25; 120..180 H7 0/+40;
  //          10..18 H8 0/+27; 400..500 H7 0/+63; up to 3 H7 0/+10
  check_class(checks, "H7", 20, 0, 21);
  check_class(checks, "H7", 50, 0, 25);
  check_class(checks, "H7", 150, 0, 40);
  check_class(checks, "H8", 12, 0, 27);
  check_class(checks, "H7", 500, 0, 63);
  check_class(checks, "H7", 2, 0, 10);
  // shafts: 18..24 s6 +35/+48; 30..50 p6 +26/+42; 30..50 k6 +2/+18;
  //         80..100 u6 +124/+146; 80..100 r6 +51/+73; 6..10 n6 +10/+19;
  //         18..30 m6 +8/+21; 140..160 s6 +100/+125; 30..50 h6 -16/0;
  //         30..40 t6 +48/+64; 200..225 r6 +80/+109; 10..14 u6 +33/+44;
  //         400..450 u6 +490/+530; 30..50 js6 +-8; 18..30 js7 +-10.5
  check_class(checks, "s6", 20, 35, 48);
  check_class(checks, "p6", 50, 26, 42);
  check_class(checks, "k6", 50, 2, 18);
  check_class(checks, "u6", 100, 124, 146);
  check_class(checks, "r6", 100, 51, 73);
  check_class(checks, "n6", 10, 10, 19);
  check_class(checks, "m6", 30, 8, 21);
  check_class(checks, "s6", 150, 100, 125);
  check_class(checks, "h6", 40, -16, 0);
  check_class(checks, "t6", 35, 48, 64);
  check_class(checks, "r6", 210, 80, 109);
  check_class(checks, "u6", 12, 33, 44);
  check_class(checks, "u6", 420, 490, 530);
  check_class(checks, "js6", 40, -8, 8);
  check_class(checks, "js7", 20, -10.5, 10.5);
  // k above IT7 has ei = 0 (ISO 286-1 Table 2): 18..30 k8 0/+33
  check_class(checks, "k8", 20, 0, 33, "ISO 286-1 Table 2 (k: ei = 0 above IT7)");
  // holes K..U (ES = -ei + Delta): 30..50 N7 -33/-8; 18..30 P7 -35/-14;
  // 18..30 S7 -48/-27; 50..65 R7 -60/-30; 65..80 S7 -78/-48;
  // 18..30 K7 -15/+6; 18..30 K8 -23/+10; 18..30 M6 -17/-4;
  // 80..100 U7 -146/-111; up to 3 S7 -24/-14
  check_class(checks, "N7", 40, -33, -8);
  check_class(checks, "P7", 25, -35, -14);
  check_class(checks, "S7", 25, -48, -27);
  check_class(checks, "R7", 60, -60, -30);
  check_class(checks, "S7", 70, -78, -48);
  check_class(checks, "K7", 25, -15, 6);
  check_class(checks, "K8", 25, -23, 10);
  check_class(checks, "M6", 25, -17, -4);
  check_class(checks, "U7", 90, -146, -111);
  check_class(checks, "S7", 2, -24, -14);
  // M6 over 250 up to 315: ES = -9 (ISO 286-1 Table 3 special case, not
  // -20 + 9 = -11), EI = -9 - 32 = -41; its neighbour 180..250 M6 -37/-8
  check_class(checks, "M6", 280, -41, -9, "ISO 286-1 Table 3 special case M6 250..315");
  check_class(checks, "M6", 250, -37, -8);
  // P above IT7 takes no Delta: 30..50 P8 ES = -26, EI = -26 - 39 = -65
  check_class(checks, "P8", 40, -65, -26, "ISO 286-1 Table 3 (P..ZC above IT7: ES = -ei)");

  // --- Delta data against its definition Delta = IT_n - IT_(n-1) ---------
  // (ISO 286-1 Table 3; from 3 mm on, where Delta is not set to 0): N_g's
  // ES + n's ei is Delta_g, h_g's width is IT_g, for g = 6, 7, 8 on every
  // main step
  {
    const double sizes_mm[] = {5, 8, 15, 25, 40, 70, 100, 150, 200, 300, 350, 450};
    for (const double d : sizes_mm)
      for (unsigned int g = 6; g <= 8; ++g)
        {
          const std::string G      = std::to_string(g);
          const double      ES     = iso286::deviations("N" + G, d * 1e-3).upper;
          const double      ei     = iso286::deviations("n" + G, d * 1e-3).lower;
          const double      it_g   = -iso286::deviations("h" + G, d * 1e-3).lower;
          const double      it_g_1 =
            -iso286::deviations("h" + std::to_string(g - 1), d * 1e-3).lower;
          checks.near(std::to_string(int(d)) + " mm Delta" + G + " = ES(N" + G + ") + ei(n" + G +
                        ") [um]",
                      (ES + ei) * 1e6, (it_g - it_g_1) * 1e6, tol_um,
                      "IT" + G + " - IT" + std::to_string(g - 1) + " from the IT table");
        }
  }

  // --- fits: interference = es - EI (largest), ei - ES (smallest) [um] ---
  // 20 H7/s6: 48 - 0 = 48, 35 - 21 = 14; 50 H7/p6: 42, 26 - 25 = 1;
  // 100 H7/u6: 146, 124 - 35 = 89; 150 H7/s6: 125, 100 - 40 = 60;
  // 50 H7/k6 (transition): 18, 2 - 25 = -23
  {
    struct Case
    {
      const char *designation;
      double      d_mm, largest_um, smallest_um;
    };
    const Case cases[] = {{"H7/s6", 20, 48, 14},
                          {" H7 / p6 ", 50, 42, 1},
                          {"H7/u6", 100, 146, 89},
                          {"H7/s6", 150, 125, 60},
                          {"H7/k6", 50, 18, -23}};
    for (const auto &c : cases)
      {
        const auto f = iso286::fit(c.designation, c.d_mm * 1e-3);
        const std::string name = std::to_string(int(c.d_mm)) + " mm '" + c.designation + "'";
        checks.near(name + " largest interference [um]", f.largest_interference() * 1e6,
                    c.largest_um, tol_um, "ISO 286-2 tables, es - EI");
        checks.near(name + " smallest interference [um]", f.smallest_interference() * 1e6,
                    c.smallest_um, tol_um, "ISO 286-2 tables, ei - ES");
      }
    const auto f = iso286::fit(" H7 / p6 ", 50e-3);
    checks.equal("' H7 / p6 ' hole class", f.hole, std::string("H7"), "designation");
    checks.equal("' H7 / p6 ' shaft class", f.shaft, std::string("p6"), "designation");
  }

  // --- boundary convention: "over a up to and including b" ---------------
  // 30 mm is in 18..30 (H7 +21, s6 +35/+48), 30.0001 mm in 30..50 (H7 +25,
  // s6 +43/+59); 18 mm in 10..18 (s6 +28/+39); 65 mm in 50..65 (r6
  // +41/+60), 65.0001 mm in 65..80 (r6 +43/+62); 24.001 mm t6 +41/+54
  check_class(checks, "H7", 30, 0, 21, "ISO 286-2 table, 30 mm in 18..30");
  check_class(checks, "s6", 30, 35, 48, "ISO 286-2 table, 30 mm in 18..30");
  check_class(checks, "H7", 30.0001, 0, 25, "ISO 286-2 table, 30.0001 mm in 30..50");
  check_class(checks, "s6", 30.0001, 43, 59, "ISO 286-2 table, 30.0001 mm in 30..50");
  check_class(checks, "s6", 18, 28, 39, "ISO 286-2 table, 18 mm in 10..18");
  check_class(checks, "r6", 65, 41, 60, "ISO 286-2 table, 65 mm in 50..65");
  check_class(checks, "r6", 65.0001, 43, 62, "ISO 286-2 table, 65.0001 mm in 65..80");
  check_class(checks, "t6", 24.001, 41, 54, "ISO 286-2 table, 24.001 mm in 24..30");

  // --- refusals -----------------------------------------------------------
  const double d20 = 20e-3;
  check_refused(checks, "H7/s6x", [&] { iso286::fit("H7/s6x", d20); }, {"'s6x'", "20 mm"});
  check_refused(checks, "Q7/s6", [&] { iso286::fit("Q7/s6", d20); }, {"'Q7'", "20 mm"});
  check_refused(checks, "H7/s", [&] { iso286::fit("H7/s", d20); }, {"'s'", "20 mm"});
  check_refused(checks, "s6/H7", [&] { iso286::fit("s6/H7", d20); },
                {"'s6/H7'", "20 mm", "hole first"});
  check_refused(checks, "H3/s6", [&] { iso286::fit("H3/s6", d20); }, {"'H3'", "20 mm", "IT3"});
  check_refused(checks, "H9", [&] { iso286::deviations("H9", d20); }, {"'H9'", "20 mm", "IT9"});
  check_refused(checks, "Js7 (mixed case)", [&] { iso286::deviations("Js7", d20); },
                {"'Js7'", "20 mm"});
  check_refused(checks, "H7s6 (no '/')", [&] { iso286::fit("H7s6", d20); }, {"'H7s6'", "20 mm"});
  check_refused(checks, "H7/s6/u6", [&] { iso286::fit("H7/s6/u6", d20); }, {"'H7/s6/u6'", "20 mm"});
  check_refused(checks, "H7/s6 at 600 mm", [&] { iso286::fit("H7/s6", 0.6); }, {"'H7'", "600 mm"});
  check_refused(checks, "s6 at 0.5 mm", [&] { iso286::deviations("s6", 0.5e-3); },
                {"'s6'", "0.5 mm"});
  check_refused(checks, "t6 at 20 mm (t only over 24 mm)",
                [&] { iso286::deviations("t6", d20); }, {"'t6'", "20 mm"});
  check_refused(checks, "H7/T7 at 24 mm (T only over 24 mm)",
                [&] { iso286::fit("H7/T7", 24e-3); }, {"'H7/T7'", "24 mm"});
  check_refused(checks, "T7 at 24 mm", [&] { iso286::deviations("T7", 24e-3); }, {"'T7'", "24 mm"});

  return checks.finish();
}
