#pragma once

#include <iomanip>
#include <sstream>
#include <string>

namespace rotorfit
{
  /// @p x with 8 significant digits, as the result tables print it (a speed
  /// in a message matches the speed in contact.csv).
  inline std::string
  format_number(const double x)
  {
    std::ostringstream s;
    s << std::setprecision(8) << x;
    return s.str();
  }
} // namespace rotorfit
