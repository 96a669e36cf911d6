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

  /// @p s with its control bytes written as \xNN: a NUL byte would end a
  /// message printed as a C string, an escape sequence would drive the
  /// terminal. Other bytes (UTF-8 text) are kept.
  inline std::string
  printable(const std::string &s)
  {
    std::string out;
    for (const char c : s)
      {
        const auto u = static_cast<unsigned char>(c);
        if (u < 0x20 || u == 0x7f)
          {
            const char *hex = "0123456789abcdef";
            out += std::string("\\x") + hex[u >> 4] + hex[u & 15];
          }
        else
          out += c;
      }
    return out;
  }
} // namespace rotorfit
