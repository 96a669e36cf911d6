#include <rotorfit/base/input_error.h>
#include <rotorfit/base/parameter_file.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

namespace rotorfit
{
  namespace
  {
    std::string
    trim(const std::string &s)
    {
      const auto a = s.find_first_not_of(" \t\r");
      if (a == std::string::npos)
        return "";
      return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
    }

    /// Runs of blanks as one space: deal.II compares names that way.
    std::string
    normalise(const std::string &s)
    {
      std::istringstream words(s);
      std::string        out, w;
      while (words >> w)
        out += (out.empty() ? "" : " ") + w;
      return out;
    }
  } // namespace

  std::string
  read_parameter_file(const std::string &filename)
  {
    if (!std::filesystem::exists(filename))
      throw InputError("the parameter file '" + filename + "' does not exist.");
    std::ifstream in(filename, std::ios::binary);
    if (!in)
      throw InputError("the parameter file '" + filename + "' cannot be read.");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (text.compare(0, 3, "\xEF\xBB\xBF") == 0)
      text.erase(0, 3);

    // duplicate 'set' lines per subsection path (continuation lines joined)
    std::istringstream                 lines(text);
    std::string                        line, logical;
    std::vector<std::string>           path;
    std::map<std::string, unsigned int> first_line;
    unsigned int                       number = 0, start = 0;
    while (std::getline(lines, line))
      {
        ++number;
        if (logical.empty())
          start = number;
        const std::string t = trim(line);
        if (!t.empty() && t.back() == '\\')
          {
            logical += t.substr(0, t.size() - 1) + " ";
            continue;
          }
        logical += t;
        std::string statement = trim(logical.substr(0, logical.find('#')));
        logical.clear();
        // deal.II's keywords, in lower or upper case
        const auto keyword = [&](const std::string &lower, const std::string &upper) {
          const std::size_t n = lower.size();
          return (statement.compare(0, n, lower) == 0 || statement.compare(0, n, upper) == 0) &&
                 (statement.size() == n || statement[n] == ' ' || statement[n] == '\t');
        };
        if (keyword("subsection", "SUBSECTION"))
          path.push_back(normalise(statement.substr(10)));
        else if ((statement == "end" || statement == "END") && !path.empty())
          path.pop_back();
        else if (keyword("set", "SET") && statement.size() > 3)
          {
            const auto        eq   = statement.find('=');
            const std::string name = normalise(statement.substr(3, eq == std::string::npos ? std::string::npos : eq - 3));
            std::string       where;
            for (const auto &p : path)
              where += p + "/";
            const auto [it, inserted] = first_line.emplace(where + name, start);
            if (!inserted)
              throw InputError(filename + ":" + std::to_string(start) + ": '" + where +
                               name + "' is set again (first set on line " +
                               std::to_string(it->second) +
                               "); keep one of the two lines.");
          }
      }
    return text;
  }
} // namespace rotorfit
