#pragma once

#include <string>
#include <vector>

namespace rotorfit
{
  struct ResponseAtSpeed;

  /// A resonance peak of one probe's response (API 684 reading).
  struct ResponsePeak
  {
    std::string probe;
    double      rpm = 0, amplitude = 0; ///< peak speed [r/min], major semi-axis [m]
    double      low_rpm = 0, high_rpm = 0; ///< half-power speeds (nan: beyond the sweep)
    double      amplification_factor = 0;  ///< rpm / (high - low)
    double      separation_margin = 0;     ///< [%] from the operating range (nan: none given)
    double      required_margin   = 0;     ///< [%], API 617 / 684 rule
    /// At least three speeds at or above half power: otherwise the band is
    /// narrower than the speed step, AF is a lower bound and the margin asked
    /// for is taken at its cap.
    bool        resolved = true;
    std::string fit_state;
  };

  /**
   * The resonance peaks of every probe over the speeds of @p history, read
   * as API 684 asks (doc/theory.md 13.3): the top of the parabola through the
   * three samples around a local maximum, its half-power speeds, its
   * amplification factor and, with an operating range @p operating (min,
   * max [r/min]; empty: none), its separation margin and the margin the API
   * 617 / 684 rule asks for.
   */
  std::vector<ResponsePeak>
  find_response_peaks(const std::vector<ResponseAtSpeed> &history,
                      const std::vector<double>          &operating);
} // namespace rotorfit
