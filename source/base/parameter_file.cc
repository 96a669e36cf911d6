#include <rotorfit/base/input_error.h>
#include <rotorfit/base/parameter_file.h>

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
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

    /// "Subsection/Entry" with each part normalised.
    std::string
    entry_key(const std::string &path)
    {
      std::string key;
      std::size_t a = 0;
      for (std::size_t b; (b = path.find('/', a)) != std::string::npos; a = b + 1)
        key += normalise(path.substr(a, b - a)) + "/";
      return key + normalise(path.substr(a));
    }

    /// The case being read (where_set()).
    struct Locations
    {
      std::string                        file;
      std::map<std::string, std::string> where; // entry -> "FILE:LINE: " or "--set '...': "
    } locations;

    bool
    word_byte(const char c)
    {
      return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.';
    }
  } // namespace

  std::string
  unrepresentable_number(const std::string &value)
  {
    // numbers are words of their own: "h_fit: 1e-3", not "mesh2.geo"
    for (std::size_t i = 0; i < value.size();)
      {
        const bool starts = (i == 0 || !word_byte(value[i - 1])) &&
                            (std::isdigit(static_cast<unsigned char>(value[i])) ||
                             (value[i] == '.' && i + 1 < value.size() &&
                              std::isdigit(static_cast<unsigned char>(value[i + 1]))));
        if (!starts)
          {
            ++i;
            continue;
          }
        const char *begin = value.c_str() + i;
        char       *end   = nullptr;
        errno             = 0;
        const double x    = std::strtod(begin, &end);
        const std::size_t n = end - begin;
        if (n == 0 || (i + n < value.size() && word_byte(value[i + n])))
          {
            ++i;
            continue;
          }
        if (errno == ERANGE)
          return "the number " + value.substr(i, n) +
                 (x == 0 || std::abs(x) < 1 ?
                    " lies below the smallest normal double (2.2e-308)" :
                    " lies above the largest double (1.8e308)") +
                 " and cannot be read; give a value of a physical size (0 where 0 is meant).";
        i += n;
      }
    return "";
  }

  void
  record_file(const std::string &filename)
  {
    locations = {filename, {}};
  }

  void
  record_override(const std::string &entry, const std::string &argument)
  {
    locations.where[entry_key(entry)] = "--set '" + argument + "': ";
  }

  std::string
  where_set(const std::string &entry)
  {
    const auto it = locations.where.find(entry_key(entry));
    if (it != locations.where.end())
      return it->second;
    return locations.file.empty() ? "" : locations.file + ": ";
  }

  std::string
  read_parameter_file(const std::string &filename)
  {
    if (!std::filesystem::exists(filename))
      throw InputError("the parameter file '" + filename + "' does not exist.");
    if (!std::filesystem::is_regular_file(filename))
      throw InputError("the parameter file '" + filename +
                       "' is not a regular file (a directory?); give the .prm or .json file.");
    std::ifstream in(filename, std::ios::binary);
    if (!in)
      throw InputError("the parameter file '" + filename + "' cannot be read.");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (text.compare(0, 3, "\xEF\xBB\xBF") == 0)
      text.erase(0, 3);
    record_file(filename);

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
        const std::string at = filename + ":" + std::to_string(start) + ": ";
        std::string where;
        for (const auto &p : path)
          where += p + "/";
        // deal.II's keywords, in lower or upper case
        const auto keyword = [&](const std::string &lower, const std::string &upper) {
          const std::size_t n = lower.size();
          return (statement.compare(0, n, lower) == 0 || statement.compare(0, n, upper) == 0) &&
                 (statement.size() == n || statement[n] == ' ' || statement[n] == '\t');
        };
        const bool set = keyword("set", "SET") && statement.size() > 3;
        const auto eq  = statement.find('=');
        const std::string name =
          set ? normalise(statement.substr(3, eq == std::string::npos ? std::string::npos : eq - 3)) :
                "";
        const std::string value = set && eq != std::string::npos ? trim(statement.substr(eq + 1)) : "";
        // a control byte (tabs aside) ends deal.II's message at a NUL, or
        // hides in a name: refused with the line shown escaped
        for (const char c : statement)
          if ((static_cast<unsigned char>(c) < 0x20 && c != '\t') || c == 0x7f)
            throw InputError(at + (set ? "'" + where + name + "' = '" + value + "'" :
                                         "'" + statement + "'") +
                             " holds the control byte " + printable(std::string(1, c)) +
                             (c == 0 ? " (NUL)" : "") +
                             "; a parameter file is plain text (a file saved as UTF-16 has "
                             "a NUL byte after every letter: save it as UTF-8).");
        if (keyword("subsection", "SUBSECTION"))
          path.push_back(normalise(statement.substr(10)));
        else if ((statement == "end" || statement == "END") && !path.empty())
          path.pop_back();
        else if (set)
          {
            const auto [it, inserted] = first_line.emplace(where + name, start);
            if (!inserted)
              throw InputError(filename + ":" + std::to_string(start) + ": '" + where +
                               name + "' is set again (first set on line " +
                               std::to_string(it->second) +
                               "); keep one of the two lines.");
            // deal.II's patterns pass 1e-310, its conversion then fails
            // without naming the entry
            const std::string problem = unrepresentable_number(value);
            if (!problem.empty())
              throw InputError(at + where + name + " = " + value + ": " + problem);
            locations.where[where + name] = at;
          }
      }
    return text;
  }
} // namespace rotorfit
