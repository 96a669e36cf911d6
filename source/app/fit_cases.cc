#include <rotorfit/app/fit_cases.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/model/discretization.h>
#include <rotorfit/output/tables.h>

#include <deal.II/base/utilities.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    constexpr double nan = std::numeric_limits<double>::quiet_NaN();

    double
    number(const std::map<std::string, std::string> &keys, const std::string &key)
    {
      const auto it = keys.find(key);
      if (it == keys.end())
        return nan;
      try
        {
          return std::stod(it->second);
        }
      catch (...)
        {
          return nan;
        }
    }
  } // namespace

  FitCases::FitCases(const Discretization &model)
  {
    const auto &list = model.interfaces();
    std::vector<std::pair<std::string, std::string>> band = {{"", ""}};
    if (list.any_toleranced() && list.interference_cases().size() > 1)
      {
        band.clear();
        for (const auto c : list.interference_cases())
          {
            const std::string name = c == FitSpecification::Case::smallest ? "smallest" : "largest";
            band.emplace_back(name, name);
          }
      }
    const unsigned int n_t = model.bodies().n_temperature_cases();
    for (const auto &[band_name, band_value] : band)
      for (unsigned int t = 1; t <= n_t; ++t)
        {
          Case c;
          c.name = band_name;
          if (!band_value.empty())
            c.sets.emplace_back("Fit design/Interference cases", band_value);
          if (n_t > 1)
            {
              c.name += (c.name.empty() ? "" : "_") + std::string("T") + std::to_string(t);
              c.sets.emplace_back("Fit design/Temperature case", std::to_string(t));
            }
          cases.push_back(c);
        }
    outcomes.resize(cases.size());
    for (const auto &d : list.list())
      interfaces.push_back(d.name);
    for (const auto &b : model.bodies().list())
      bodies.push_back(b.name);
    // each case's temperatures, for the table
    for (unsigned int k = 0; k < cases.size(); ++k)
      {
        const unsigned int t = n_t > 1 ? k % n_t : 0;
        std::ostringstream s;
        for (const auto &b : model.bodies().list())
          s << (s.str().empty() ? "" : "; ") << b.name << ' '
            << (b.temperatures.empty() ? model.interfaces().reference_temperature() :
                                         b.temperatures[b.temperatures.size() == 1 ? 0 : t])
            << " C";
        outcomes[k].keys["temperatures"] = s.str();
      }
  }

  void
  FitCases::record(const unsigned int k, const int exit_code, const std::string &directory)
  {
    Outcome &o = outcomes[k];
    o.code     = exit_code;
    std::ifstream in(directory + "/summary.txt");
    for (std::string line; std::getline(in, line);)
      {
        const auto space = line.find(' ');
        if (space != std::string::npos && line[0] != '#')
          o.keys[line.substr(0, space)] = line.substr(space + 1);
      }
    o.status = o.keys.count("run.status") ? o.keys["run.status"] : "not run";
  }

  void
  FitCases::record_loose(const unsigned int k, const std::string &message)
  {
    Outcome &o = outcomes[k];
    o.code     = 0;
    o.status   = "loose_at_rest";
    o.message  = message;
    // nothing holds the hub: it has lost its fit and slips at rest
    for (const auto &f : interfaces)
      {
        o.keys["interface." + f + ".loss_of_fit_rpm"] = "0";
        o.keys["interface." + f + ".slip_rpm"]        = "0";
        o.keys["interface." + f + ".slip_safety_first_speed"] = "0";
        o.keys["interface." + f + ".torque_capacity_first_speed_Nm"] = "0";
        o.keys["interface." + f + ".mean_pressure_first_speed_Pa"]   = "0";
      }
  }

  int
  FitCases::finish(const std::string &directory, const MPI_Comm comm) const
  {
    int code = exit_code::success;
    for (const auto &o : outcomes)
      if (o.code != exit_code::success && o.code != -1 && code == exit_code::success)
        code = o.code;
    // nothing was solved: the fit holds in no case
    const bool all_loose = std::all_of(outcomes.begin(), outcomes.end(), [](const Outcome &o) {
      return o.status == "loose_at_rest";
    });
    if (all_loose)
      code = exit_code::input_error;
    if (Utilities::MPI::this_mpi_process(comm) != 0)
      return code;
    std::filesystem::create_directories(directory);
    std::ofstream table(directory + "/fit_cases.csv");
    table << "case,status,temperatures,interface,radial_interference_at_reference_m,"
             "thermal_shift_m,mean_pressure_first_speed_Pa,torque_capacity_first_speed_Nm,"
             "slip_safety_first_speed,first_opening_rpm,loss_of_fit_rpm,slip_rpm,"
             "hub_bore_von_mises_first_speed_Pa,shaft_bore_von_mises_first_speed_Pa,"
             "hub_bore_von_mises_max_Pa,shaft_bore_von_mises_max_Pa\n"
          << std::setprecision(8);
    const std::vector<std::string> columns = {"radial_interference_at_reference_m",
                                              "thermal_shift_m",
                                              "mean_pressure_first_speed_Pa",
                                              "torque_capacity_first_speed_Nm",
                                              "slip_safety_first_speed",
                                              "first_opening_rpm",
                                              "loss_of_fit_rpm",
                                              "slip_rpm",
                                              "hub_bore_von_mises_first_speed_Pa",
                                              "shaft_bore_von_mises_first_speed_Pa",
                                              "hub_bore_von_mises_max_Pa",
                                              "shaft_bore_von_mises_max_Pa"};
    for (unsigned int k = 0; k < cases.size(); ++k)
      for (const auto &f : interfaces)
        {
          const Outcome &o = outcomes[k];
          table << csv_field(cases[k].name) << ',' << csv_field(o.status) << ','
                << csv_field(o.keys.at("temperatures")) << ',' << csv_field(f);
          for (const auto &c : columns)
            {
              const auto it = o.keys.find("interface." + f + "." + c);
              table << ',' << (it == o.keys.end() ? "" : it->second);
            }
          table << '\n';
        }

    // the governing case of each check: the least speed or safety, the
    // largest stress; a case that did not run governs nothing
    std::ofstream summary(directory + "/summary.txt");
    summary << std::setprecision(8) << "study.cases " << cases.size() << '\n';
    for (unsigned int k = 0; k < cases.size(); ++k)
      {
        summary << "case." << cases[k].name << ".status " << outcomes[k].status << '\n';
        summary << "case." << cases[k].name << ".temperatures " << outcomes[k].keys.at("temperatures") << '\n';
      }
    const auto govern = [&](const std::string &key, const bool least) {
      double       best = nan;
      unsigned int at   = 0;
      for (unsigned int k = 0; k < cases.size(); ++k)
        {
          const double v = number(outcomes[k].keys, key);
          if (std::isnan(v))
            continue;
          if (std::isnan(best) || (least ? v < best : v > best))
            {
              best = v;
              at   = k;
            }
        }
      if (!std::isnan(best))
        summary << key << ' ' << best << '\n' << key << ".case " << cases[at].name << '\n';
    };
    for (const auto &f : interfaces)
      {
        const std::string p = "interface." + f + ".";
        // at rest: what the fit carries and the stress it puts in while it
        // holds; over the speeds: where it lets go
        for (const char *k : {"mean_pressure_first_speed_Pa", "torque_capacity_first_speed_Nm",
                              "slip_safety_first_speed", "first_opening_rpm", "loss_of_fit_rpm",
                              "slip_rpm"})
          govern(p + k, true);
        for (const char *k : {"hub_bore_von_mises_first_speed_Pa",
                              "shaft_bore_von_mises_first_speed_Pa", "hub_bore_von_mises_max_Pa",
                              "shaft_bore_von_mises_max_Pa"})
          govern(p + k, false);
      }
    for (const auto &b : bodies)
      {
        govern("body." + b + ".max_von_mises_Pa", false);
        govern("body." + b + ".yield_safety_least", true);
      }
    summary << "run.status "
            << (all_loose                    ? "refused" :
                code == exit_code::success ? "completed" :
                                              "failed")
            << '\n';
    if (all_loose)
      summary << "run.message the fit is loose at rest in every case; nothing was solved\n";
    summary << "run.exit_code " << code << '\n';
    return code;
  }
} // namespace rotorfit
