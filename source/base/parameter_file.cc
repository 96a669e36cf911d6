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

  namespace
  {
    /// The bytes of @p filename, a UTF-8 byte order mark dropped.
    std::string
    load_text(const std::string &filename)
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
      return text;
    }

    /// Whether @p statement starts with deal.II's keyword @p lower (or in
    /// upper case), followed by a blank or nothing.
    bool
    starts_with_keyword(const std::string &statement,
                        const std::string &lower,
                        const std::string &upper)
    {
      const std::size_t n = lower.size();
      return (statement.compare(0, n, lower) == 0 || statement.compare(0, n, upper) == 0) &&
             (statement.size() == n || statement[n] == ' ' || statement[n] == '\t');
    }

    /// The file an 'include' names, trimmed ("" if the statement is none).
    std::string
    included_name(const std::string &statement)
    {
      if (!starts_with_keyword(statement, "include", "INCLUDE"))
        return "";
      return trim(statement.substr(7));
    }

    /**
     * An 'include' of @p including_file at @p at ("FILE:LINE: ") made
     * relative to the including file: deal.II opens the name it is given
     * relative to the working directory. The included file is opened by
     * deal.II itself, so an 'include' in it with a relative name would
     * resolve against the working directory again: refused.
     */
    std::string
    resolve_include(const std::string &name,
                    const std::string &including_file,
                    const std::string &at)
    {
      namespace fs         = std::filesystem;
      const fs::path given = name;
      const fs::path here  = fs::path(including_file).parent_path();
      const std::string path =
        given.is_absolute() ? name : (here / given).lexically_normal().string();
      if (!fs::is_regular_file(path))
        throw InputError(at + "'include " + name + "': '" + path +
                         "' is no readable file (an include is read relative to the file "
                         "that includes it).");
      std::istringstream lines(load_text(path));
      std::string        line;
      for (unsigned int number = 1; std::getline(lines, line); ++number)
        {
          const std::string nested = included_name(trim(line.substr(0, line.find('#'))));
          if (!nested.empty() && !fs::path(nested).is_absolute())
            throw InputError(path + ":" + std::to_string(number) + ": 'include " + nested +
                             "' inside an included file is not supported with a relative "
                             "name; include it from '" + including_file +
                             "' or give an absolute path.");
        }
      return path;
    }

    /// A control byte (tabs aside) ends deal.II's message at a NUL, or hides
    /// in a name: refused with the line shown escaped.
    void
    check_control_bytes(const std::string &statement,
                        const std::string &at,
                        const std::string &shown)
    {
      for (const char c : statement)
        if ((static_cast<unsigned char>(c) < 0x20 && c != '\t') || c == 0x7f)
          throw InputError(at + shown + " holds the control byte " +
                           printable(std::string(1, c)) + (c == 0 ? " (NUL)" : "") +
                           "; a parameter file is plain text (a file saved as UTF-16 has "
                           "a NUL byte after every letter: save it as UTF-8).");
    }

    /**
     * The checks of read_parameter_file(), one logical line (continuation
     * lines joined) at a time: the subsection path, entries set twice, and
     * where each entry is set.
     */
    class Scanner
    {
    public:
      explicit Scanner(const std::string &filename)
        : filename(filename)
      {}

      /// Check @p statement (comment removed) starting on line @p start;
      /// returns the line deal.II should read instead of an 'include', or "".
      std::string
      scan(const std::string &statement, const unsigned int start)
      {
        const std::string at = filename + ":" + std::to_string(start) + ": ";
        std::string       where;
        for (const auto &p : path)
          where += p + "/";
        const bool set = starts_with_keyword(statement, "set", "SET") && statement.size() > 3;
        const auto eq  = statement.find('=');
        const auto end = eq == std::string::npos ? std::string::npos : eq - 3;
        const std::string name  = set ? normalise(statement.substr(3, end)) : "";
        const std::string value =
          set && eq != std::string::npos ? trim(statement.substr(eq + 1)) : "";
        check_control_bytes(statement,
                            at,
                            set ? "'" + where + name + "' = '" + value + "'" :
                                  "'" + statement + "'");
        if (starts_with_keyword(statement, "subsection", "SUBSECTION"))
          path.push_back(normalise(statement.substr(10)));
        else if ((statement == "end" || statement == "END") && !path.empty())
          path.pop_back();
        else if (set)
          record_set(where + name, value, start, at);
        else if (const std::string included = included_name(statement); !included.empty())
          return "include " + resolve_include(included, filename, at);
        return "";
      }

    private:
      void
      record_set(const std::string  &entry,
                 const std::string  &value,
                 const unsigned int  start,
                 const std::string  &at)
      {
        const auto [it, inserted] = first_line.emplace(entry, start);
        if (!inserted)
          throw InputError(at + "'" + entry + "' is set again (first set on line " +
                           std::to_string(it->second) + "); keep one of the two lines.");
        // deal.II's patterns pass 1e-310, its conversion then fails
        // without naming the entry
        const std::string problem = unrepresentable_number(value);
        if (!problem.empty())
          throw InputError(at + entry + " = " + value + ": " + problem);
        locations.where[entry] = at;
      }

      const std::string                   filename;
      std::vector<std::string>            path;
      std::map<std::string, unsigned int> first_line;
    };
  } // namespace

  std::string
  read_parameter_file(const std::string &filename)
  {
    const std::string text = load_text(filename);
    record_file(filename);
    Scanner            scanner(filename);
    std::istringstream lines(text);
    std::string        line, logical, result;
    unsigned int       number = 0, start = 0;
    bool               rewritten = false;
    while (std::getline(lines, line))
      {
        ++number;
        if (logical.empty())
          start = number;
        const std::string t = trim(line);
        if (!t.empty() && t.back() == '\\')
          {
            logical += t.substr(0, t.size() - 1) + " ";
            result += line + "\n";
            continue;
          }
        logical += t;
        const std::string replacement =
          scanner.scan(trim(logical.substr(0, logical.find('#'))), start);
        logical.clear();
        if (!replacement.empty() && start != number)
          throw InputError(filename + ":" + std::to_string(start) +
                           ": an 'include' continued over lines; write it on one line.");
        rewritten |= !replacement.empty();
        result += (replacement.empty() ? line : replacement) + "\n";
      }
    return rewritten ? result : text;
  }
} // namespace rotorfit
