#pragma once

#include <rotorfit/base/format.h>

#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace rotorfit
{
  /// Process exit codes (README, doc/limits.md).
  namespace exit_code
  {
    constexpr int success     = 0;
    constexpr int input_error = 1; ///< the input was refused before any solve
    constexpr int solver      = 2; ///< a solver failed; finished speeds kept
    constexpr int interrupted = 3; ///< SIGINT/SIGTERM; finished speeds kept
  } // namespace exit_code

  /**
   * An error that bad input can trigger (parameter file, geometry, physical
   * groups, interfaces). main() prints its message once, without a stack
   * trace, and exits with exit_code::input_error. The message names the file
   * or entry, the bad value and the fix. Control bytes in it (a NUL in a
   * value) are escaped, or what() would end the message there.
   */
  class InputError : public std::runtime_error
  {
  public:
    explicit InputError(const std::string &message)
      : std::runtime_error(printable(message))
    {}
  };

  /**
   * A fit with no interference left at rest at the bodies' temperatures:
   * refused like any input, but a temperature case of a study records it
   * (its loss of fit is 0 r/min) and goes on with the next case.
   */
  class FitLooseAtRest : public InputError
  {
  public:
    using InputError::InputError;
  };

  /**
   * A solver outcome that makes the results of a speed wrong (unconverged
   * eigenpairs, NaN or Inf in a result): the run stops with
   * exit_code::solver, keeping the speeds already written.
   */
  class SolverFailure : public std::runtime_error
  {
  public:
    SolverFailure(const double rpm, const std::string &message)
      : std::runtime_error(message)
      , rpm(rpm)
    {}
    double rpm; ///< speed at which it failed [r/min]
  };

  /// The run was asked to stop by a signal (exit_code::interrupted).
  class Interrupted : public std::runtime_error
  {
  public:
    explicit Interrupted(const std::string &message)
      : std::runtime_error(message)
    {}
  };

  /// Refuses a list entry that names the same thing twice (e.g. one bearing
  /// twice would double its stiffness).
  inline void
  check_unique(const std::vector<std::string> &names, const std::string &entry)
  {
    std::set<std::string> seen;
    for (const auto &n : names)
      if (!seen.insert(n).second)
        throw InputError(entry + ": '" + n +
                         "' appears twice; give each name once (a repeated "
                         "name would count its feature twice).");
  }
} // namespace rotorfit
