#include <rotorfit/base/input_error.h>
#include <rotorfit/base/optional_number.h>
#include <rotorfit/base/patterns.h>
#include <rotorfit/fit/fit_specification.h>
#include <rotorfit/fit/iso286.h>

#include <deal.II/base/utilities.h>

#include <cmath>
#include <iomanip>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;


  void
  FitSpecification::declare_parameters(ParameterHandler &prm)
  {
    prm.declare_entry("Radial interference",
                      "",
                      patterns::Mandatory(patterns::Positive()),
                      "Interference on the radius (half the diametral "
                      "interference) [m], > 0, at the reference temperature "
                      "(subsection Fit design), as measured: Roughness Rz "
                      "smoothing is taken off it. Both bodies are meshed at "
                      "the same nominal radius (numerical interference). Give "
                      "exactly one of this, 'ISO fit' and 'Limit deviations'.");
    prm.declare_entry("ISO fit",
                      "",
                      Patterns::Anything(),
                      "An ISO 286 fit designation, hole class / shaft class "
                      "(e.g. H7/s6), evaluated at the fit's diameter in the "
                      "mesh. Its smallest and largest interference are run as "
                      "two cases (Fit design/Interference cases).");
    prm.declare_entry("Limit deviations",
                      "",
                      Patterns::List(Patterns::Double(), 0, 4),
                      "Explicit limit deviations [m]: hole lower, hole upper, "
                      "shaft lower, shaft upper (ISO 286's EI, ES, ei, es; e.g. "
                      "0, 21e-6, 35e-6, 48e-6 for 20 H7/s6). Run as two cases "
                      "like an ISO fit.");
    prm.declare_entry("Roughness Rz",
                      "0, 0",
                      Patterns::List(Patterns::Double(0., 1e-3), 2, 2),
                      "Mean roughness depth Rz of the shaft and of the hub "
                      "surface [m]. Assembly smooths the peaks: the diametral "
                      "interference loses 0.8 (Rz_shaft + Rz_hub) (DIN 7190).");
    prm.declare_entry("Friction coefficient",
                      "none",
                      Patterns::Anything(),
                      "Static friction coefficient of the joint [-] ('none': "
                      "no friction capacity is reported). DIN 7190 gives "
                      "0.1 .. 0.2 for dry steel/steel after shrinking.");
    prm.declare_entry("Torque",
                      "0",
                      Patterns::Double(0.),
                      "Torque the joint must carry [N m]; with the axial force, "
                      "the load of the safety against slip.");
    prm.declare_entry("Axial force",
                      "0",
                      Patterns::Double(0.),
                      "Axial force the joint must carry [N].");
    prm.declare_entry("Assembly clearance",
                      "0.001",
                      Patterns::Double(0., 0.01),
                      "Diametral clearance wanted to slide the heated hub on, "
                      "as a fraction of the fit diameter [-] (DIN 7190 suggests "
                      "about 0.001): sets the mounting temperature.");
  }

  void
  FitSpecification::parse_parameters(ParameterHandler &prm, const std::string &where_)
  {
    where = where_;
    const bool has_radial     = !prm.get("Radial interference").empty();
    designation               = Utilities::trim(prm.get("ISO fit"));
    const bool has_iso        = !designation.empty();
    const auto dev            = Utilities::split_string_list(prm.get("Limit deviations"), ',');
    const bool has_deviations = !dev.empty();
    const int  n_given        = int(has_radial) + int(has_iso) + int(has_deviations);
    if (n_given != 1)
      throw InputError(where + ": " +
                       (n_given == 0 ? std::string("no interference is given") :
                                       std::string("the interference is given more than once")) +
                       "; set exactly one of Radial interference, ISO fit (e.g. H7/s6) and "
                       "Limit deviations.");
    if (has_radial)
      {
        given  = Given::radial;
        radial = prm.get_double("Radial interference");
      }
    else if (has_iso)
      {
        // checked against the tables once the mesh gives the diameter
        given = Given::iso286;
      }
    else
      {
        given = Given::deviations;
        if (dev.size() != 4)
          throw InputError(where + "/Limit deviations: give four values [m]: hole lower, hole "
                                   "upper, shaft lower, shaft upper.");
        deviation.clear();
        for (const auto &d : dev)
          deviation.push_back(std::stod(d));
        if (deviation[0] > deviation[1] || deviation[2] > deviation[3])
          throw InputError(where + "/Limit deviations: a lower deviation exceeds its upper one "
                                   "(order: hole lower, hole upper, shaft lower, shaft upper).");
      }
    const auto rz = Utilities::split_string_list(prm.get("Roughness Rz"), ',');
    rz_shaft      = std::stod(rz[0]);
    rz_hub        = std::stod(rz[1]);
    friction_coefficient =
      optional_number(prm.get("Friction coefficient"), where + "/Friction coefficient", 1.5, "");
    torque      = prm.get_double("Torque");
    axial_force = prm.get_double("Axial force");
    clearance   = prm.get_double("Assembly clearance");
    if ((torque > 0 || axial_force > 0) && !friction_coefficient)
      throw InputError(where + ": a Torque or Axial force to carry needs a Friction coefficient "
                               "(the capacity is mu times the contact forces).");
  }

  std::string
  FitSpecification::describe() const
  {
    switch (given)
      {
        case Given::radial:
          return "radial interference";
        case Given::iso286:
          return "ISO 286 " + designation;
        case Given::deviations:
          return "limit deviations";
      }
    return "";
  }

  double
  FitSpecification::diametral_interference(const double diameter, const Case c) const
  {
    switch (given)
      {
        case Given::radial:
          return 2 * radial;
        case Given::iso286:
          try
            {
              const auto fit = iso286::fit(designation, diameter);
              return c == Case::smallest ? fit.smallest_interference() :
                                           fit.largest_interference();
            }
          catch (const InputError &e)
            {
              throw InputError(where + "/ISO fit = " + designation + ": " + e.what());
            }
        case Given::deviations:
          // smallest: shaft at its lower, hole at its upper deviation
          return c == Case::smallest ? deviation[2] - deviation[1] : deviation[3] - deviation[0];
      }
    return 0;
  }

  double
  FitSpecification::effective_radial_interference(const double diameter, const Case c) const
  {
    const double U = diametral_interference(diameter, c);
    const double u = U - smoothing();
    if (!(u > 0))
      {
        // a loose end of a band (a transition fit) is a result of a study,
        // recorded there; a single run refuses it
        std::ostringstream m;
        m << std::setprecision(4) << where << ": the " << describe() << " at "
          << diameter * 1e3 << " mm gives a " << (toleranced() && c == Case::smallest ? "smallest " : "")
          << "diametral interference of " << U * 1e6 << " um";
        if (smoothing() > 0)
          m << ", and smoothing by the roughness (0.8 (Rz_shaft + Rz_hub) = " << smoothing() * 1e6
            << " um) leaves no interference: the fit is loose. Choose a tighter fit or smoother "
               "surfaces.";
        else
          m << ": the fit has clearance there (a transition or clearance fit), nothing holds the "
               "hub. Choose an interference fit.";
        throw FitLooseAtRest(m.str());
      }
    return 0.5 * u;
  }

  double
  FitSpecification::mounting_temperature(const double diameter,
                                         const double hub_expansion,
                                         const double reference_temperature) const
  {
    // the unsmoothed largest interference: the peaks are still there
    const double U_max = diametral_interference(diameter, Case::largest);
    return reference_temperature + (U_max + clearance * diameter) / (hub_expansion * diameter);
  }
} // namespace rotorfit
