#pragma once

#include <iomanip>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace rotorfit
{
  /**
   * summary.txt: one "key value" line per scalar result of the run (masses,
   * opening speeds, solver counts, the run's status). The pieces of the run
   * add their entries; the file is written once, at the end of the run
   * (completed, failed or interrupted), so the order of the calls cannot
   * leave it half written.
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

    /// Write every entry to @p filename (call on one MPI rank).
    void
    write(const std::string &filename) const;

  private:
    std::vector<std::pair<std::string, std::string>> entries;
  };
} // namespace rotorfit
