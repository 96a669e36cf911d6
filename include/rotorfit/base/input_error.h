#pragma once

#include <stdexcept>
#include <string>

namespace rotorfit
{
  /**
   * An error that bad input can trigger (parameter file, geometry, physical
   * groups, interfaces). main() prints its message once, without a stack
   * trace, and exits with a non-zero code. The message names the file or
   * entry, the bad value and the fix.
   */
  class InputError : public std::runtime_error
  {
  public:
    explicit InputError(const std::string &message)
      : std::runtime_error(message)
    {}
  };
} // namespace rotorfit
