#pragma once

#include <string>

namespace rotorfit
{
  /**
   * The text of a .prm file as deal.II's ParameterHandler should see it.
   * A UTF-8 byte order mark (editors on Windows write one) is dropped. An
   * entry set twice in the same subsection is refused naming both lines:
   * ParameterHandler would silently keep the last one (lines brought in by
   * 'include' are not scanned). So is a control byte (a NUL: a file saved as
   * UTF-16) and a number no double holds (1e-310 passes deal.II's patterns,
   * then fails its conversion). Records where each entry is set
   * (where_set()). An 'include' names a file relative to the including
   * file: the text returned names it so for deal.II, which opens it
   * relative to the working directory (an include inside the included file
   * must then be absolute). Throws InputError.
   */
  std::string
  read_parameter_file(const std::string &filename);

  /// The first number in @p value that a double cannot hold (below the
  /// smallest normal double, or above the largest), with the reason; ""
  /// if there is none.
  std::string
  unrepresentable_number(const std::string &value);

  /**
   * Where the entries of the case got their values, so that a check made
   * after parsing names the file and line as deal.II's pattern refusals do.
   * read_parameter_file() records the 'set' lines of a .prm file;
   * record_file() a file deal.II reads itself (.json, .xml);
   * record_override() a --set of the command line.
   */
  void
  record_file(const std::string &filename);

  /// @p entry ("Subsection/Entry") was set by the command line's --set
  /// @p argument ("Subsection/Entry=value").
  void
  record_override(const std::string &entry, const std::string &argument);

  /// "FILE:LINE: ", "--set 'S/E=V': ", or "FILE: " where the line is not
  /// known (.json, an included file, a default): the start of a message
  /// about @p entry ("Body shaft/Density").
  std::string
  where_set(const std::string &entry);
} // namespace rotorfit
