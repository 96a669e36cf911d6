#pragma once

#include <rotorfit/base/input_error.h>

#include <deal.II/base/utilities.h>

#include <cmath>
#include <optional>
#include <sstream>
#include <string>

namespace rotorfit
{
  /**
   * An entry that is 'none' or a number in (0, @p max] (a friction
   * coefficient, an expansion coefficient, a yield strength): nullopt for
   * 'none', else the number; anything else is refused naming @p entry (the
   * "Subsection/Entry" path, with its file and line if known), the value
   * and the @p unit.
   */
  inline std::optional<double>
  optional_number(const std::string &value, const std::string &entry, const double max,
                  const std::string &unit)
  {
    const std::string v = dealii::Utilities::trim(value);
    if (v == "none")
      return std::nullopt;
    std::istringstream in(v);
    double             x = 0;
    in >> x;
    if (in.fail() || !in.eof() || !std::isfinite(x) || !(x > 0) || x > max)
      {
        std::ostringstream m;
        m << entry << " = '" << value << "': give 'none' or a number in (0, " << max << "]"
          << unit << '.';
        throw InputError(m.str());
      }
    return x;
  }
} // namespace rotorfit
