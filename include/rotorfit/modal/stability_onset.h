#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/base/summary.h>
#include <rotorfit/eigen/speed_eigenproblem.h>
#include <rotorfit/modal/modal_analysis.h>
#include <rotorfit/statics/static_state.h>

#include <map>
#include <string>
#include <vector>

namespace rotorfit
{
  /// A speed where a tracked line's damping ratio crosses zero.
  struct StabilityOnset
  {
    unsigned int tracked_id = 0;
    std::string  whirl;
    double       rpm = 0, frequency_hz = 0;
    std::string  direction;       ///< "unstable above" or "stable above"
    unsigned int evaluations = 0; ///< eigen solves of the root solve
    bool         converged   = false;
    /// axisymmetric model: the line's harmonic and travel direction (3D: -1)
    int          harmonic = -1;
    std::string  travel;
  };

  /**
   * Stability onsets (doc/theory.md 9.7): when a tracked line's damping
   * ratio changes sign between two speeds (both beyond 1e-8 in magnitude:
   * an undamped line's round-off has either sign), the speed where it is zero is
   * found by a root solve (Illinois regula falsi) on the damped
   * eigenproblem itself, evaluated at states of the later speed's active
   * set (its affine law in Omega^2: exact unless a pair opens inside the
   * bracket). At each trial speed the line is the mode of largest MAC with
   * the line at the later speed. Converged when the bracket is below
   * 1e-6 of the speed or |zeta| < 1e-10.
   */
  class StabilityOnsets
  {
  public:
    explicit StabilityOnsets(Log &log)
      : log(log)
    {}

    /// The onsets between the previous call's speed and @p current's;
    /// solves @p eigen at trial speeds (its matrices are those of the last
    /// trial afterwards).
    std::vector<StabilityOnset>
    find(const ModalResult &current, const StaticState &state, SpeedEigenproblem &eigen);

    void
    finish(Summary &summary) const;

    /// The onsets found so far.
    const std::vector<StabilityOnset> &
    list() const
    {
      return found;
    }

  private:
    /// Illinois regula falsi on the damping ratio of @p line_at_b between
    /// the previous speed and @p rpm_b (doc/theory.md 9.7).
    StabilityOnset
    root_solve(const WhirlMode         &line_at_b,
               const double             rpm_b,
               const StaticState       &state,
               SpeedEigenproblem &eigen) const;

    struct Point
    {
      double      zeta, frequency_hz;
      std::string whirl;
    };

    Log                                &log;
    double                              previous_rpm = -1;
    std::map<unsigned int, Point>       previous;
    std::vector<StabilityOnset>         found;
  };
} // namespace rotorfit
