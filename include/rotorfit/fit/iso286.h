#pragma once

#include <string>

/**
 * ISO 286 limits and fits for the interference and transition fits of a
 * shrink-fitted rotor: the standard's tables (ISO 286-1 Tables 1 to 3,
 * ISO 286-2) held as data, for nominal sizes 1 mm to 500 mm.
 *
 * Tabulated: standard tolerance grades IT5 to IT8; holes H, JS, K, M, N, P,
 * R, S, T, U; shafts h, js, k, m, n, p, r, s, t, u. Sizes are assigned to the
 * standard's steps "over a up to and including b": a size exactly on a
 * boundary belongs to the lower step (30 mm to 18..30 mm).
 */
namespace rotorfit::iso286
{
  /// Limit deviations of one tolerance class from the nominal size [m]:
  /// lower <= upper (EI, ES for a hole; ei, es for a shaft).
  struct LimitDeviations
  {
    double lower; ///< lower limit deviation [m]
    double upper; ///< upper limit deviation [m]
  };

  /**
   * Limit deviations of @p tolerance_class ("H7": a hole, capital letters;
   * "s6": a shaft, lower case) at the nominal size @p nominal_size [m].
   * Whitespace around the class is ignored.
   *
   * Throws InputError naming the class and the size when the class is not in
   * the tables (unknown letter, grade outside IT5..IT8), the size is outside
   * 1 mm to 500 mm, or the standard does not define the class at that size
   * (t and T only over 24 mm).
   */
  LimitDeviations
  deviations(const std::string &tolerance_class, double nominal_size);

  /// A fit: a hole class and a shaft class at one nominal size.
  struct Fit
  {
    std::string     hole;      ///< hole class, e.g. "H7"
    std::string     shaft;     ///< shaft class, e.g. "s6"
    LimitDeviations hole_dev;  ///< EI, ES of the hole [m]
    LimitDeviations shaft_dev; ///< ei, es of the shaft [m]

    /// Largest diametral interference es - EI [m] (positive = interference).
    double
    largest_interference() const;

    /// Smallest diametral interference ei - ES [m] (negative = clearance:
    /// a transition fit).
    double
    smallest_interference() const;
  };

  /**
   * The fit @p designation, "hole class/shaft class" such as "H7/s6" (spaces
   * around '/' allowed), at the nominal size @p nominal_size [m]. Throws
   * InputError naming the designation and the size when it is not of that
   * form (the hole comes first) or either class is refused by deviations().
   */
  Fit
  fit(const std::string &designation, double nominal_size);
} // namespace rotorfit::iso286
