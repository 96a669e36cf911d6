#include <rotorfit/base/format.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/fit/iso286.h>

#include <array>
#include <cctype>
#include <cmath>
#include <limits>

namespace rotorfit::iso286
{
  namespace
  {
    // All numbers below are ISO 286's, in micrometres, transcribed from the
    // standard's tables (not from its rounding formulae).

    /// Tabulated grades IT5..IT8.
    constexpr unsigned int first_grade = 5, last_grade = 8;
    /// Range of nominal sizes [mm] (the first step is "up to 3 mm").
    constexpr double smallest_size = 1., largest_size = 500.;

    /// Main diameter steps of ISO 286-1 Tables 1 and 3: "over the previous
    /// bound up to and including this one" [mm].
    constexpr std::array<double, 13> main_steps = {
      {3, 6, 10, 18, 30, 50, 80, 120, 180, 250, 315, 400, 500}};

    /// ISO 286-1 Table 1: standard tolerances IT5..IT8 by main step [um].
    constexpr double it[4][13] = {
      {4, 5, 6, 8, 9, 11, 13, 15, 18, 20, 23, 25, 27},        // IT5
      {6, 8, 9, 11, 13, 16, 19, 22, 25, 29, 32, 36, 40},      // IT6
      {10, 12, 15, 18, 21, 25, 30, 35, 40, 46, 52, 57, 63},   // IT7
      {14, 18, 22, 27, 33, 39, 46, 54, 63, 72, 81, 89, 97}};  // IT8

    /// ISO 286-1 Table 3, the Delta columns for grades 5..8 by main step
    /// [um] (Delta = IT_n - IT_(n-1), but 0 up to 3 mm, where the hole
    /// deviations are tabulated directly).
    constexpr double delta[4][13] = {
      {0, 1, 2, 3, 3, 4, 5, 5, 6, 6, 7, 7, 7},            // grade 5
      {0, 3, 3, 3, 4, 5, 6, 7, 7, 9, 9, 11, 13},          // grade 6
      {0, 4, 6, 7, 8, 9, 11, 13, 15, 17, 20, 21, 23},     // grade 7
      {0, 6, 7, 9, 12, 14, 16, 19, 23, 26, 29, 32, 34}};  // grade 8

    /// ISO 286-1 Table 2: lower deviations ei of the shafts that change only
    /// with the main step [um]. k is the column for grades IT4..IT7 (above
    /// IT7, and for grades <= IT3, ei = 0).
    struct MainRow
    {
      double k, m, n, p;
    };
    constexpr MainRow main_rows[13] = {
      {0, 2, 4, 6},     // up to 3
      {1, 4, 8, 12},    // 3..6
      {1, 6, 10, 15},   // 6..10
      {1, 7, 12, 18},   // 10..18
      {2, 8, 15, 22},   // 18..30
      {2, 9, 17, 26},   // 30..50
      {2, 11, 20, 32},  // 50..80
      {3, 13, 23, 37},  // 80..120
      {3, 15, 27, 43},  // 120..180
      {4, 17, 31, 50},  // 180..250
      {4, 20, 34, 56},  // 250..315
      {4, 21, 37, 62},  // 315..400
      {5, 23, 40, 68}}; // 400..500

    /// "Not defined by the standard at this size" (t up to 24 mm).
    constexpr double undefined = std::numeric_limits<double>::quiet_NaN();

    /// ISO 286-1 Table 2 on the intermediate steps: lower deviations ei of
    /// r, s, t, u [um], which change inside the main steps above 18 mm.
    struct FineRow
    {
      double upper; ///< step "over the previous bound up to this" [mm]
      double r, s, t, u;
    };
    constexpr FineRow fine_rows[] = {
      {3, 10, 14, undefined, 18},     {6, 15, 19, undefined, 23},
      {10, 19, 23, undefined, 28},    {14, 23, 28, undefined, 33},
      {18, 23, 28, undefined, 33},    {24, 28, 35, undefined, 41},
      {30, 28, 35, 41, 48},           {40, 34, 43, 48, 60},
      {50, 34, 43, 54, 70},           {65, 41, 53, 66, 87},
      {80, 43, 59, 75, 102},          {100, 51, 71, 91, 124},
      {120, 54, 79, 104, 144},        {140, 63, 92, 122, 170},
      {160, 65, 100, 134, 190},       {180, 68, 108, 146, 210},
      {200, 77, 122, 166, 236},       {225, 80, 130, 180, 258},
      {250, 84, 140, 196, 284},       {280, 94, 158, 218, 315},
      {315, 98, 170, 240, 350},       {355, 108, 190, 268, 390},
      {400, 114, 208, 294, 435},      {450, 126, 232, 330, 490},
      {500, 132, 252, 360, 540}};

    /// ISO 286-1 Table 3, special case: M6 over 250 up to 315 mm has
    /// ES = -9 um instead of -m + Delta = -11 um.
    constexpr double m6_250_315_upper = -9;

    const std::string tables_text =
      "holes: H, JS, K, M, N, P, R, S, T, U; shafts: h, js, k, m, n, p, r, s, t, u; "
      "grades IT5..IT8";

    /// Whether @p d [mm] lies in the step ending at @p upper [mm]. A size
    /// within 1e-9 relative of the bound counts as on it: 0.03 m * 1000 need
    /// not be 30 exactly, and 30 mm belongs to the lower step.
    bool
    in_step(const double d, const double upper)
    {
      return d <= upper * (1. + 1e-9);
    }

    std::string
    trim(const std::string &s)
    {
      const auto first = s.find_first_not_of(" \t");
      if (first == std::string::npos)
        return "";
      const auto last = s.find_last_not_of(" \t");
      return s.substr(first, last - first + 1);
    }

    std::string
    size_text(const double nominal_size)
    {
      return format_number(nominal_size * 1e3) + " mm";
    }

    /// A tolerance class split into its parts.
    struct Class
    {
      bool         hole;
      std::string  letter; ///< as written ("JS", "s")
      unsigned int grade;
    };

    [[noreturn]] void
    refuse_class(const std::string &cls, const double nominal_size, const std::string &why)
    {
      throw InputError("ISO 286: tolerance class '" + cls + "' is not in rotorfit's tables (" +
                       tables_text + ") at " + size_text(nominal_size) + ": " + why + ".");
    }

    Class
    parse(const std::string &cls, const double nominal_size)
    {
      std::size_t i = 0;
      while (i < cls.size() && std::isalpha(static_cast<unsigned char>(cls[i])))
        ++i;
      const std::string letter = cls.substr(0, i), digits = cls.substr(i);
      static const std::array<std::string, 10> holes = {
        {"H", "JS", "K", "M", "N", "P", "R", "S", "T", "U"}};
      static const std::array<std::string, 10> shafts = {
        {"h", "js", "k", "m", "n", "p", "r", "s", "t", "u"}};
      Class c{false, letter, 0};
      bool  known = false;
      for (const auto &h : holes)
        if (letter == h)
          known = c.hole = true;
      for (const auto &s : shafts)
        if (letter == s)
          known = true;
      if (!known)
        refuse_class(cls, nominal_size,
                     letter.empty() ? "it does not start with a deviation letter"
                                    : "the deviation '" + letter + "' is none of these");
      if (digits.empty())
        refuse_class(cls, nominal_size, "it has no tolerance grade (write e.g. '" + letter + "7')");
      for (const char ch : digits)
        if (!std::isdigit(static_cast<unsigned char>(ch)))
          refuse_class(cls, nominal_size,
                       "'" + digits + "' after the letter is not a tolerance grade");
      if (digits.size() > 2 || std::stoul(digits) < first_grade || std::stoul(digits) > last_grade)
        refuse_class(cls, nominal_size, "grade IT" + digits + " is not tabulated");
      c.grade = static_cast<unsigned int>(std::stoul(digits));
      return c;
    }

    /// Limit deviations [um] of @p c at @p d [mm] (d within the tables).
    LimitDeviations
    deviations_um(const Class &c, const double d, const std::string &cls, const double nominal_size)
    {
      unsigned int s = 0; // main step
      while (!in_step(d, main_steps[s]))
        ++s;
      unsigned int f = 0; // intermediate step
      while (!in_step(d, fine_rows[f].upper))
        ++f;
      const unsigned int g    = c.grade - first_grade;
      const double       tol  = it[g][s];
      const MainRow     &main = main_rows[s];
      const FineRow     &fine = fine_rows[f];

      // the shaft deviation ei of k..u; a hole K..U mirrors the shaft's
      std::string letter = c.letter;
      for (char &ch : letter)
        ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
      double ei = undefined;
      if (letter == "k")
        ei = main.k;
      else if (letter == "m")
        ei = main.m;
      else if (letter == "n")
        ei = main.n;
      else if (letter == "p")
        ei = main.p;
      else if (letter == "r")
        ei = fine.r;
      else if (letter == "s")
        ei = fine.s;
      else if (letter == "t")
        ei = fine.t;
      else if (letter == "u")
        ei = fine.u;
      if (letter == "t" && std::isnan(ei))
        throw InputError("ISO 286: tolerance class '" + cls +
                         "' is not defined by the standard at " + size_text(nominal_size) +
                         ": ISO 286-1 gives the deviations t and T only over 24 mm; choose s/S "
                         "or u/U there.");

      if (!c.hole)
        {
          if (letter == "h")
            return {-tol, 0.};
          // +-IT/2 exactly, as ISO 286-2 tabulates it (ISO 286-1 allows,
          // not requires, rounding odd IT7..IT11 values down to even)
          if (letter == "js")
            return {-tol / 2., tol / 2.};
          if (letter == "k" && c.grade > 7)
            ei = 0.;
          return {ei, ei + tol};
        }

      if (letter == "h")
        return {0., tol};
      if (letter == "js")
        return {-tol / 2., tol / 2.};
      // K, M, N up to IT8 and P..U up to IT7: ES = -ei + Delta; P..U above
      // IT7: ES = -ei (ISO 286-1 Table 3)
      double ES = -ei;
      if (letter == "k" || letter == "m" || letter == "n" || c.grade <= 7)
        ES += delta[g][s];
      if (letter == "m" && c.grade == 6 && d > 250. * (1. + 1e-9) && in_step(d, 315.))
        ES = m6_250_315_upper;
      return {ES - tol, ES};
    }
  } // namespace

  LimitDeviations
  deviations(const std::string &tolerance_class, const double nominal_size)
  {
    const std::string cls = trim(tolerance_class);
    const Class       c   = parse(cls, nominal_size);
    const double      d   = nominal_size * 1e3;
    if (!(d >= smallest_size * (1. - 1e-9) && in_step(d, largest_size)))
      throw InputError("ISO 286: nominal size " + size_text(nominal_size) +
                       " of tolerance class '" + cls + "' is outside rotorfit's tables (" +
                       format_number(smallest_size) + " mm to " + format_number(largest_size) +
                       " mm); give the size in metres, within that range.");
    const LimitDeviations um = deviations_um(c, d, cls, nominal_size);
    return {um.lower * 1e-6, um.upper * 1e-6};
  }

  double
  Fit::largest_interference() const
  {
    return shaft_dev.upper - hole_dev.lower;
  }

  double
  Fit::smallest_interference() const
  {
    return shaft_dev.lower - hole_dev.upper;
  }

  Fit
  fit(const std::string &designation, const double nominal_size)
  {
    const auto refuse = [&](const std::string &why) {
      throw InputError("ISO 286: fit '" + designation + "' at " + size_text(nominal_size) + ": " +
                       why + ".");
    };
    const auto slash = designation.find('/');
    if (slash == std::string::npos || designation.find('/', slash + 1) != std::string::npos)
      refuse("write one hole class and one shaft class separated by '/', e.g. 'H7/s6'");
    Fit f;
    f.hole  = trim(designation.substr(0, slash));
    f.shaft = trim(designation.substr(slash + 1));
    const auto starts_lower = [](const std::string &s) {
      return !s.empty() && std::islower(static_cast<unsigned char>(s[0]));
    };
    const auto starts_upper = [](const std::string &s) {
      return !s.empty() && std::isupper(static_cast<unsigned char>(s[0]));
    };
    if (starts_lower(f.hole) && starts_upper(f.shaft))
      refuse("'" + f.hole + "' is a shaft class (lower case) and '" + f.shaft +
             "' a hole class; a fit names the hole first: write '" + f.shaft + "/" + f.hole + "'");
    if (starts_lower(f.hole))
      refuse("'" + f.hole + "' is a shaft class (lower case), but the first class of a fit is "
                            "the hole's (capital letters, e.g. 'H7')");
    if (starts_upper(f.shaft))
      refuse("'" + f.shaft + "' is a hole class (capital letters), but the second class of a "
                             "fit is the shaft's (lower case, e.g. 's6')");
    f.hole_dev  = deviations(f.hole, nominal_size);
    f.shaft_dev = deviations(f.shaft, nominal_size);
    return f;
  }
} // namespace rotorfit::iso286
