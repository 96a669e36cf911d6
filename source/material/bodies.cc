#include <rotorfit/base/input_error.h>
#include <rotorfit/base/patterns.h>
#include <rotorfit/material/bodies.h>

#include <deal.II/base/utilities.h>

#include <cmath>
#include <set>

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
                          "E [Pa], > 0. Mandatory.");
        prm.declare_entry("Poisson's ratio",
                          "",
                          patterns::Mandatory(Patterns::Double(-1, 0.5)),
                          "nu [-], in (-1, 0.5) (the ends are singular). Mandatory.");
        prm.declare_entry("Density",
                          "",
                          patterns::Mandatory(patterns::Positive()),
                          "rho [kg/m^3], > 0. Mandatory.");
        prm.leave_subsection();
      }
  }

  void
  Bodies::parse_parameters(ParameterHandler &prm)
  {
    bodies.clear();
    const auto names = Utilities::split_string_list(prm.get("Bodies"), ',');
    check_unique(names, "Bodies");
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
        if (!(b.poissons_ratio > -1. && b.poissons_ratio < 0.5))
          throw InputError("Body " + name + "/Poisson's ratio = " +
                           prm.get("Poisson's ratio") +
                           " must lie in (-1, 0.5).");
        prm.leave_subsection();
        bodies.push_back(b);
      }
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
