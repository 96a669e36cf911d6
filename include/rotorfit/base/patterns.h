#pragma once

#include <deal.II/base/patterns.h>

#include <cmath>
#include <memory>
#include <sstream>
#include <string>

namespace rotorfit
{
  /**
   * Patterns that deal.II does not have, so that the ParameterHandler
   * refuses a bad value with the file and line instead of a hand check.
   */
  namespace patterns
  {
    /// A finite number > 0 (deal.II's Double bounds are inclusive).
    class Positive : public dealii::Patterns::PatternBase
    {
    public:
      bool
      match(const std::string &s) const override
      {
        std::istringstream in(s);
        double             x;
        in >> x;
        return !in.fail() && in.eof() && std::isfinite(x) && x > 0;
      }

      std::string
      description(const OutputStyle = Machine) const override
      {
        return "[Double > 0]";
      }

      std::unique_ptr<PatternBase>
      clone() const override
      {
        return std::make_unique<Positive>();
      }
    };

    /**
     * An entry without a default: empty (not set; its class refuses that
     * with a message naming what is missing) or a value matching @p inner.
     */
    class Mandatory : public dealii::Patterns::PatternBase
    {
    public:
      explicit Mandatory(const PatternBase &inner)
        : inner(inner.clone())
      {}

      bool
      match(const std::string &s) const override
      {
        return s.empty() || inner->match(s);
      }

      std::string
      description(const OutputStyle style = Machine) const override
      {
        return inner->description(style) + " (mandatory)";
      }

      std::unique_ptr<PatternBase>
      clone() const override
      {
        return std::make_unique<Mandatory>(*inner);
      }

    private:
      std::unique_ptr<PatternBase> inner;
    };
  } // namespace patterns
} // namespace rotorfit
