#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/eigen/speed_eigenproblem.h>
#include <rotorfit/modal/mode_tracker.h>
#include <rotorfit/modal/whirl.h>
#include <rotorfit/statics/static_state.h>

#include <complex>
#include <functional>
#include <string>

namespace rotorfit
{
  /// Where a function of a tracked line's eigenvalue is zero.
  struct LineRoot
  {
    double               rpm = 0;
    std::complex<double> lambda; ///< of the line at rpm
    unsigned int         evaluations = 0; ///< eigen solves (checked)
    unsigned int         trials      = 0; ///< unchecked trials on the reduced model
    bool                 converged   = false;
    /// the checked solve at rpm (empty if none succeeded there)
    EigenSolution        solution;
  };

  /**
   * Illinois regula falsi in the speed on g(lambda, rpm) of one Campbell
   * line (doc/theory.md 9.7, 9.8): the bracket [a, b] with g(a) = @p ga,
   * g(b) = @p gb of opposite signs; at each trial speed the eigenproblem is
   * solved on @p state's affine law (the later speed's active set: exact
   * unless a pair opens inside the bracket) and the line is the mode of
   * largest MAC with @p line_at_b. First on the speed's reduced model
   * without its full-space checks (PrestressedEigenproblem::solve_trial),
   * then with checked solves (reduced where they pass, full otherwise)
   * starting at the root so found. Converged when the bracket is below
   * 1e-6 of the speed or a checked solve gives |g| <= @p g_tolerance. A
   * failed eigen solve keeps the bracket (logged).
   */
  LineRoot
  solve_line_root(const WhirlMode                                                 &line_at_b,
                  double                                                           a,
                  double                                                           ga,
                  double                                                           b,
                  double                                                           gb,
                  const std::function<double(std::complex<double>, double)>       &g,
                  const double                                                     g_tolerance,
                  const StaticState                                               &state,
                  SpeedEigenproblem                                   &eigen,
                  Log                                                             &log,
                  const std::string                                               &what);

  /// Crossing @p c of @p line with its excitation order (its bracket from
  /// ModeTracker::track) solved for its speed by solve_line_root on
  /// f - k rpm / 60 to 1e-9 of the frequency: c's speed, frequency,
  /// damping, solve count and solved flag set, the result logged. Returns
  /// the root (with its checked solution at c.rpm, if any).
  LineRoot
  solve_crossing(CriticalSpeed     &c,
                 const WhirlMode   &line,
                 const StaticState &state,
                 SpeedEigenproblem &eigen,
                 Log               &log);
} // namespace rotorfit
