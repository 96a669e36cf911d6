#include <rotorfit/base/input_error.h>
#include <rotorfit/base/optional_number.h>
#include <rotorfit/base/parameter_file.h>
#include <rotorfit/base/patterns.h>
#include <rotorfit/material/bodies.h>

#include <deal.II/base/utilities.h>

#include <cmath>
#include <set>
#include <sstream>
#include <algorithm>

namespace rotorfit
{
  using namespace dealii;

  void
  Bodies::declare_list(ParameterHandler &prm)
  {
    prm.declare_entry("Bodies",
                      "",
                      Patterns::List(Patterns::Anything(), 0),
                      "Names of the bodies, e.g. 'shaft, sleeve'. Each needs a "
                      "subsection 'Body <name>'.");
    prm.enter_subsection("Fit design");
    prm.declare_entry("Temperature case",
                      "1",
                      Patterns::Integer(1),
                      "Which entry of each body's Temperature list this run "
                      "uses (a list of one serves every case). Set by the "
                      "program when it runs the temperature cases one after "
                      "the other.");
    prm.leave_subsection();
  }

  void
  Bodies::declare_parameters(ParameterHandler               &prm,
                             const std::vector<std::string> &names)
  {
    for (const auto &name : names)
      {
        prm.enter_subsection("Body " + name);
        prm.declare_entry("Physical volume",
                          name,
                          Patterns::Anything(),
                          "Name of the gmsh physical volume that is this "
                          "body (default: the body's name).");
        prm.declare_entry("Young's modulus",
                          "",
                          patterns::Mandatory(patterns::Positive()),
                          "E [Pa], 1e6 .. 1e14. Soft rubber has about 1e6 Pa, "
                          "diamond, the stiffest solid, 1.2e12 Pa; up to 1e14 "
                          "admits the rigid stand-ins of verification cases (100 x "
                          "steel). Outside is a units slip (steel: 205e9, not 205 "
                          "or 205e3). Mandatory.");
        prm.declare_entry("Poisson's ratio",
                          "",
                          patterns::Mandatory(Patterns::Double(-1, 0.5)),
                          "nu [-], in (-1, 0.5) (the ends are singular). Above "
                          "0.49 a warning: near incompressibility the displacement "
                          "elements lock (at 0.4999 the test shaft's fit came out "
                          "partly open at rest). Mandatory.");
        prm.declare_entry("Density",
                          "",
                          patterns::Mandatory(patterns::Positive()),
                          "rho [kg/m^3], 1 .. 1e5. Aerogels have a few kg/m^3, "
                          "osmium, the densest element, 22,590. Below 100 (lighter "
                          "than balsa, polymers and metals) a warning: g/cm^3 for "
                          "kg/m^3? Mandatory.");
        prm.declare_entry("Temperature",
                          "",
                          Patterns::List(Patterns::Double(-273.15), 0),
                          "Uniform operating temperature [deg C] (empty: Fit "
                          "design/Reference temperature). A list gives "
                          "temperature cases, run one after the other (each "
                          "body's list has one entry or as many as the longest; "
                          "Fit design/Temperature case picks one).");
        prm.declare_entry("Thermal expansion coefficient",
                          "none",
                          Patterns::Anything(),
                          "Linear expansion coefficient alpha [1/K] ('none': the "
                          "body must stay at the reference temperature). Steel "
                          "11.5e-6, aluminium 23e-6.");
        prm.declare_entry("Yield strength",
                          "none",
                          Patterns::Anything(),
                          "Rp0.2 [Pa] for the safety against yield ('none': not "
                          "reported). S235: 235e6, 6061-T6: 276e6.");
        prm.leave_subsection();
      }
  }


  void
  Bodies::parse_parameters(ParameterHandler &prm)
  {
    bodies.clear();
    input_warnings.clear();
    const auto names = Utilities::split_string_list(prm.get("Bodies"), ',');
    check_unique(names, "Bodies");
    // (also after a --set: no body left nothing to mesh)
    if (names.empty())
      throw InputError(where_set("Bodies") + "Bodies is empty; name at least one body.");
    for (const auto &name : names)
      {
        prm.enter_subsection("Body " + name);
        Body b;
        b.name            = name;
        b.physical_volume = prm.get("Physical volume");
        for (const std::string entry :
             {"Young's modulus", "Poisson's ratio", "Density"})
          if (prm.get(entry).empty())
            throw InputError("Body " + name + "/" + entry +
                             " is not set; every body needs Young's modulus, "
                             "Poisson's ratio and Density.");
        // the patterns have checked the values; only the open ends of
        // Poisson's ratio remain (deal.II's bounds are inclusive)
        b.youngs_modulus = prm.get_double("Young's modulus");
        b.poissons_ratio = prm.get_double("Poisson's ratio");
        b.density        = prm.get_double("Density");
        for (const auto &t : Utilities::split_string_list(prm.get("Temperature"), ','))
          b.temperatures.push_back(std::stod(t));
        const auto optional = [&](const std::string &e, const double max, const std::string &unit) {
          const std::string path = "Body " + name + "/" + e;
          return optional_number(prm.get(e), where_set(path) + path, max, unit);
        };
        b.expansion      = optional("Thermal expansion coefficient", 1e-3, " 1/K");
        b.yield_strength = optional("Yield strength", 1e11, " Pa");
        if (b.yield_strength && *b.yield_strength < 1e6)
          throw InputError(where_set("Body " + name + "/Yield strength") + "Body " + name +
                           "/Yield strength = " + prm.get("Yield strength") +
                           " Pa lies below 1 MPa, weaker than any structural material; it is "
                           "in Pa (S235: 235e6, not 235).");
        // "FILE:LINE: Body NAME/ENTRY = VALUE UNIT"
        const auto entry = [&](const std::string &e, const std::string &unit) {
          const std::string path = "Body " + name + "/" + e;
          return where_set(path) + path + " = " + prm.get(e) + unit;
        };
        if (!(b.poissons_ratio > -1. && b.poissons_ratio < 0.5))
          throw InputError(entry("Poisson's ratio", "") + " must lie in (-1, 0.5).");
        // an absurd magnitude passes the assembly and fails in the solver
        // without naming the body: the bounds of engineering solids
        if (b.youngs_modulus < 1e6)
          throw InputError(entry("Young's modulus", " Pa") +
                           " lies below 1e6 Pa, softer than any engineering solid (soft "
                           "rubber: about 1e6 Pa); E is in Pa (steel: 205e9, not 205 or "
                           "205e3).");
        if (b.youngs_modulus > 1e14)
          throw InputError(entry("Young's modulus", " Pa") +
                           " lies above 1e14 Pa, 80 times diamond, the stiffest solid "
                           "(1.2e12 Pa); E is in Pa (steel: 205e9).");
        if (b.density < 1)
          throw InputError(entry("Density", " kg/m^3") +
                           " lies below 1 kg/m^3, lighter than aerogels, the lightest "
                           "solids; the density is in kg/m^3 (steel: 7850, not 7.85e-9).");
        if (b.density > 1e5)
          throw InputError(entry("Density", " kg/m^3") +
                           " lies above 1e5 kg/m^3, four times osmium, the densest "
                           "element (22,590 kg/m^3); the density is in kg/m^3 (steel: "
                           "7850).");
        if (b.density < 100)
          input_warnings.push_back(entry("Density", " kg/m^3") +
                                   " lies below 100 kg/m^3, lighter than balsa, polymers "
                                   "and metals: is it in g/cm^3? (steel: 7850 kg/m^3 = 7.85 "
                                   "g/cm^3)");
        // P2 elements lock near incompressibility: TS at nu = 0.4999 had
        // 109 of 788 pairs open at rest, the peak pressure 9 x the mean
        if (b.poissons_ratio > 0.49)
          input_warnings.push_back(
            entry("Poisson's ratio", "") +
            " lies above 0.49, near incompressibility, where displacement elements lock "
            "(rotorfit has no mixed formulation): on the test shaft at 0.4999, 109 of 788 "
            "pairs came out open at rest and the peak pressure 9 times the mean. Treat "
            "stresses and the contact state with care, or use nu <= 0.49");
        prm.leave_subsection();
        bodies.push_back(b);
      }
    prm.enter_subsection("Fit design");
    const unsigned int k = prm.get_integer("Temperature case");
    prm.leave_subsection();
    const unsigned int n = n_temperature_cases();
    std::string        longest;
    for (const auto &b : bodies)
      if (b.temperatures.size() == n && longest.empty())
        longest = b.name;
    for (auto &b : bodies)
      {
        if (b.temperatures.empty())
          continue; // at the reference temperature in every case
        if (b.temperatures.size() != 1 && b.temperatures.size() != n)
          throw InputError(where_set("Body " + b.name + "/Temperature") + "Body " + b.name +
                           "/Temperature lists " + std::to_string(b.temperatures.size()) +
                           " temperatures, Body " + longest + " " + std::to_string(n) +
                           "; give one (for every case) or " + std::to_string(n) + ".");
        if (k > n)
          throw InputError("Fit design/Temperature case = " + std::to_string(k) +
                           ", but the bodies list " + std::to_string(n) +
                           " temperature case(s).");
        b.temperature = b.temperatures[b.temperatures.size() == 1 ? 0 : k - 1];
      }
  }

  unsigned int
  Bodies::n_temperature_cases() const
  {
    std::size_t n = 1;
    for (const auto &b : bodies)
      n = std::max(n, b.temperatures.size());
    return n;
  }

  std::vector<double>
  Bodies::free_thermal_strains(const double reference_temperature) const
  {
    std::vector<double> strain;
    for (const auto &b : bodies)
      {
        if (b.temperatures.empty())
          {
            strain.push_back(0.);
            continue;
          }
        if (b.temperature != reference_temperature && !b.expansion)
          {
            std::ostringstream m;
            m << "Body " << b.name << " runs at " << b.temperature
              << " deg C, off the reference temperature " << reference_temperature
              << " deg C, but has no Thermal expansion coefficient; give it (steel 11.5e-6, "
                 "aluminium 23e-6 1/K).";
            throw InputError(m.str());
          }
        strain.push_back(b.expansion ? *b.expansion * (b.temperature - reference_temperature) :
                                       0.);
      }
    return strain;
  }

  std::vector<std::string>
  Bodies::physical_volumes() const
  {
    std::vector<std::string> v;
    for (const auto &b : bodies)
      v.push_back(b.physical_volume);
    return v;
  }
} // namespace rotorfit
