#include <rotorfit/base/input_error.h>
#include <rotorfit/base/parameter_file.h>
#include <rotorfit/base/patterns.h>
#include <rotorfit/statics/speed_schedule.h>

#include <deal.II/base/utilities.h>

#include <cmath>
#include <deal.II/base/numbers.h>
#include <iomanip>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

  void
  SpeedSchedule::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Speeds");
    prm.declare_entry("Mode",
                      "range",
                      Patterns::Selection("range|list"),
                      "How the spin speeds are given: 'range' uses Start, End "
                      "and Step; 'list' uses List.");
    prm.declare_entry("Start", "0", Patterns::Double(0), "First speed [r/min], >= 0.");
    prm.declare_entry("End", "30000", Patterns::Double(0), "Last speed [r/min], >= Start.");
    prm.declare_entry("Step", "1000", patterns::Positive(), "Speed increment [r/min], > 0.");
    prm.declare_entry("List",
                      "",
                      Patterns::List(Patterns::Double(0), 0),
                      "Explicit speeds [r/min], strictly increasing, >= 0 "
                      "(used when Mode = list).");
    prm.leave_subsection();
  }

  void
  SpeedSchedule::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Speeds");
    speeds.clear();
    input_warnings.clear();
    if (prm.get("Mode") == "range")
      {
        if (!Utilities::trim(prm.get("List")).empty())
          input_warnings.push_back(where_set("Speeds/List") + "Speeds/List = " +
                                   prm.get("List") +
                                   " is ignored: Speeds/Mode = range takes the speeds from "
                                   "Start, End and Step (set Mode = list to use the list, or "
                                   "remove it)");
        const double start = prm.get_double("Start");
        const double end   = prm.get_double("End");
        const double step  = prm.get_double("Step");
        if (end < start)
          throw InputError("Speeds/End = " + prm.get("End") +
                           " r/min is below Speeds/Start = " +
                           prm.get("Start") +
                           " r/min; give End >= Start.");
        // counted in double: a tiny Step must not overflow the count
        const double count = std::floor((end - start) / step + 1e-9);
        if (!(count <= 100000))
          throw InputError("Speeds: Start = " + prm.get("Start") + ", End = " +
                           prm.get("End") + " and Step = " + prm.get("Step") +
                           " r/min give " + [&] {
                             std::ostringstream c;
                             c << std::setprecision(3) << count + 1;
                             return c.str();
                           }() +
                           " speeds (at most 100001); use a larger Step.");
        const unsigned int n = static_cast<unsigned int>(count);
        for (unsigned int i = 0; i <= n; ++i)
          speeds.push_back(start + i * step);
        // include End if the step does not land on it
        if (end - speeds.back() > 1e-9 * std::max(1.0, end))
          speeds.push_back(end);
      }
    else
      {
        const auto items =
          Utilities::split_string_list(prm.get("List"), ',');
        if (items.empty())
          throw InputError("Speeds/List is empty while Speeds/Mode = list; "
                           "give at least one speed.");
        if (items.size() > 100001)
          throw InputError("Speeds/List has " + std::to_string(items.size()) +
                           " speeds (at most 100001).");
        for (const auto &s : items)
          speeds.push_back(Utilities::string_to_double(s));
        for (unsigned int i = 0; i < speeds.size(); ++i)
          {
            if (i > 0 && !(speeds[i] > speeds[i - 1]))
              throw InputError("Speeds/List is not strictly increasing at " +
                               items[i] + " r/min; sort the list.");
          }
      }
    prm.leave_subsection();
  }

  double
  SpeedSchedule::rpm_to_rad_per_s(const double rpm)
  {
    return rpm * 2. * numbers::PI / 60.;
  }

  double
  SpeedSchedule::rad_per_s_to_rpm(const double omega)
  {
    return omega * 60. / (2. * numbers::PI);
  }
} // namespace rotorfit
