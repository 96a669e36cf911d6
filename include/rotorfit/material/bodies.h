#pragma once

#include <deal.II/base/parameter_handler.h>

#include <optional>
#include <string>
#include <vector>

namespace rotorfit
{
  /// One body of the assembly: a physical volume with its material.
  struct Body
  {
    std::string name;
    std::string physical_volume;
    double      youngs_modulus; ///< E [Pa]
    double      poissons_ratio; ///< nu [-]
    double      density;        ///< rho [kg/m^3]
    /// operating temperature of this run's temperature case [deg C]
    double      temperature = 20;
    /// every listed operating temperature [deg C] (one per temperature
    /// case; empty: the reference temperature)
    std::vector<double> temperatures;
    /// linear thermal expansion coefficient [1/K], if given
    std::optional<double> expansion;
    /// yield strength Rp0.2 [Pa], if given
    std::optional<double> yield_strength;

    /// Lame's first parameter [Pa].
    double
    lambda() const
    {
      return youngs_modulus * poissons_ratio /
             ((1. + poissons_ratio) * (1. - 2. * poissons_ratio));
    }

    /// Shear modulus [Pa].
    double
    mu() const
    {
      return youngs_modulus / (2. * (1. + poissons_ratio));
    }
  };

  /**
   * The bodies of the assembly, all rotating about z: top-level entry
   * "Bodies" (names) and one subsection "Body <name>" per name. Body i has
   * material_id i in the triangulation.
   */
  class Bodies
  {
  public:
    /// Declare the list entry (first pass).
    static void
    declare_list(dealii::ParameterHandler &prm);

    /// Declare one subsection per name (second pass).
    static void
    declare_parameters(dealii::ParameterHandler       &prm,
                       const std::vector<std::string> &names);

    void
    parse_parameters(dealii::ParameterHandler &prm);

    const std::vector<Body> &
    list() const
    {
      return bodies;
    }

    const Body &
    operator[](const unsigned int i) const
    {
      return bodies[i];
    }

    unsigned int
    size() const
    {
      return bodies.size();
    }

    std::vector<std::string>
    physical_volumes() const;

    /// Number of temperature cases: the longest Temperature list.
    unsigned int
    n_temperature_cases() const;

    /**
     * Free thermal strain alpha (T - T_ref) of each body [-] at
     * @p reference_temperature [deg C]; 0 for a body at it. Throws
     * InputError for a body off the reference without an expansion
     * coefficient.
     */
    std::vector<double>
    free_thermal_strains(const double reference_temperature) const;

    /// Materials accepted but suspect (nu near 0.5, a density in g/cm^3?),
    /// one message each, for the log once it is open.
    const std::vector<std::string> &
    warnings() const
    {
      return input_warnings;
    }

  private:
    std::vector<Body>        bodies;
    std::vector<std::string> input_warnings;
  };
} // namespace rotorfit
