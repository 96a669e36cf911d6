#pragma once

#include <iomanip>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace rotorfit
{
  /**
   * The scalar results of a run (masses, opening speeds, solver counts, the
   * run's status) as "key value" entries. The pieces of the run add theirs
   * at the end; output/ writes them once into summary.txt, so the order of
   * the calls cannot leave the file half written.
   */
  class Summary
  {
  public:
    /// Add "key value", the value printed with @p precision digits.
    template <typename T>
    void
    add(const std::string &key, const T &value, const int precision = 8)
    {
      std::ostringstream s;
      s << std::setprecision(precision) << value;
      entries.emplace_back(key, s.str());
    }

    /// The entries in the order they were added.
    const std::vector<std::pair<std::string, std::string>> &
    list() const
    {
      return entries;
    }

  private:
    std::vector<std::pair<std::string, std::string>> entries;
  };
} // namespace rotorfit
