#include <rotorfit/output/summary.h>

#include <fstream>

namespace rotorfit
{
  void
  Summary::write(const std::string &filename) const
  {
    std::ofstream out(filename);
    for (const auto &[key, value] : entries)
      {
        std::string line = value; // one line per entry: summary.txt is key value
        for (char &c : line)
          if (c == '\n')
            c = ' ';
        out << key << ' ' << line << '\n';
      }
  }
} // namespace rotorfit
