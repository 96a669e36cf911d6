#pragma once

#include <deal.II/base/parameter_handler.h>

#include <string>
#include <vector>

namespace rotorfit
{
  /**
   * The spin speeds of a sweep, in r/min: either start/end/step or an
   * explicit list (subsection "Speeds").
   */
  class SpeedSchedule
  {
  public:
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Parse and check; throws InputError naming the entry on bad input.
    void
    parse_parameters(dealii::ParameterHandler &prm);

    /// Speeds in r/min, strictly increasing, all >= 0.
    const std::vector<double> &
    speeds_rpm() const
    {
      return speeds;
    }

    /// Conversion r/min -> rad/s.
    static double
    rpm_to_rad_per_s(const double rpm);

    /// Conversion rad/s -> r/min.
    static double
    rad_per_s_to_rpm(const double omega);

    /// Entries given but not used (a List with Mode = range), one message
    /// each, for the log once it is open.
    const std::vector<std::string> &
    warnings() const
    {
      return input_warnings;
    }

  private:
    std::vector<double>      speeds;
    std::vector<std::string> input_warnings;
  };
} // namespace rotorfit
