#pragma once

// Shared by the unit tests: every comparison prints value, reference,
// tolerance and the kind of reference; the test exits non-zero when any fails.

#include <cmath>
#include <cstdio>
#include <string>

namespace rotorfit_unit
{
  class Checks
  {
  public:
    /// |value - reference| <= tolerance (absolute).
    bool
    near(const std::string &what, const double value, const double reference,
         const double tolerance, const std::string &kind)
    {
      const double error = std::abs(value - reference);
      const bool   ok    = error <= tolerance; // false for NaN
      std::printf("%s %s: value %.17g, reference %.17g (%s), |error| %.3e, tolerance %.3e\n",
                  ok ? "PASS" : "FAIL", what.c_str(), value, reference, kind.c_str(), error,
                  tolerance);
      record(ok);
      return ok;
    }

    /// |value - reference| <= tolerance |reference|.
    bool
    relative(const std::string &what, const double value, const double reference,
             const double tolerance, const std::string &kind)
    {
      const double error = std::abs(value - reference) / std::abs(reference);
      const bool   ok    = error <= tolerance;
      std::printf("%s %s: value %.17g, reference %.17g (%s), relative error %.3e, tolerance %.3e\n",
                  ok ? "PASS" : "FAIL", what.c_str(), value, reference, kind.c_str(), error,
                  tolerance);
      record(ok);
      return ok;
    }

    /// A scaled error norm (computed by the caller) against its tolerance.
    bool
    error(const std::string &what, const double error, const double tolerance,
          const std::string &kind)
    {
      const bool ok = error <= tolerance;
      std::printf("%s %s: error %.3e, tolerance %.3e (reference: %s)\n", ok ? "PASS" : "FAIL",
                  what.c_str(), error, tolerance, kind.c_str());
      record(ok);
      return ok;
    }

    /// An exact outcome (a label, an id, a count).
    template <typename T>
    bool
    equal(const std::string &what, const T &value, const T &reference, const std::string &kind)
    {
      const bool ok = (value == reference);
      std::printf("%s %s: value %s, reference %s (%s; compared exactly)\n", ok ? "PASS" : "FAIL",
                  what.c_str(), str(value).c_str(), str(reference).c_str(), kind.c_str());
      record(ok);
      return ok;
    }

    /// Summary line; the exit code of the test.
    int
    finish() const
    {
      std::printf("%u checks, %u failed\n", n_checks, n_failed);
      return n_failed == 0 && n_checks > 0 ? 0 : 1;
    }

  private:
    void
    record(const bool ok)
    {
      ++n_checks;
      if (!ok)
        ++n_failed;
    }

    static std::string
    str(const std::string &s)
    {
      return "'" + s + "'";
    }

    static std::string
    str(const char *s)
    {
      return str(std::string(s));
    }

    static std::string
    str(const bool b)
    {
      return b ? "true" : "false";
    }

    template <typename T>
    static std::string
    str(const T &v)
    {
      return std::to_string(v);
    }

    unsigned int n_checks = 0, n_failed = 0;
  };
} // namespace rotorfit_unit
