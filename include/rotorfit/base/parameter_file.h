#pragma once

#include <string>

namespace rotorfit
{
  /**
   * The text of a .prm file as deal.II's ParameterHandler should see it.
   * A UTF-8 byte order mark (editors on Windows write one) is dropped. An
   * entry set twice in the same subsection is refused naming both lines:
   * ParameterHandler would silently keep the last one (lines brought in by
   * 'include' are not scanned). Throws InputError.
   */
  std::string
  read_parameter_file(const std::string &filename);
} // namespace rotorfit
