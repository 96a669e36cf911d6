#pragma once

#include <deal.II/base/parameter_handler.h>

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

  private:
    std::vector<double> speeds;
  };
} // namespace rotorfit
