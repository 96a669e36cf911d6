#pragma once

#include <deal.II/base/parameter_handler.h>

#include <optional>
#include <string>
#include <vector>

namespace rotorfit
{
  /**
   * A shrink fit as its designer gives it (subsection "Interface <name>"):
   * the interference, by one of a radial interference, an ISO 286 fit
   * designation or explicit limit deviations; the surface roughness that
   * smooths it on assembly (DIN 7190); the static friction coefficient and
   * the loads the joint must carry; the clearance wanted for mounting.
   * doc/fit_design.md walks through it, doc/theory.md 10f has the formulas.
   */
  class FitSpecification
  {
  public:
    /// How the interference is given.
    enum class Given
    {
      radial,     ///< "Radial interference": one value
      iso286,     ///< "ISO fit": tolerance classes, at the fit's diameter
      deviations, ///< "Limit deviations" of hole and shaft
    };

    /// Which end of a toleranced fit's band a run uses.
    enum class Case
    {
      smallest, ///< governs slip and the loss of fit
      largest,  ///< governs the stresses
    };

    /// Declare the entries (inside the interface's subsection).
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Read them; @p where names the subsection in messages.
    void
    parse_parameters(dealii::ParameterHandler &prm, const std::string &where);

    /// The interference has a band (ISO fit or limit deviations).
    bool
    toleranced() const
    {
      return given != Given::radial;
    }

    /// "radial", "ISO 286 H7/s6", "limit deviations".
    std::string
    describe() const;

    /**
     * Diametral interference [m] before smoothing at nominal diameter
     * @p diameter [m], the end @p c of the band (a radial interference has
     * no band: twice it, whatever @p c). Throws InputError for a designation
     * outside the ISO 286 tables.
     */
    double
    diametral_interference(const double diameter, const Case c) const;

    /// Loss of diametral interference by smoothing, 0.8 (Rz_shaft + Rz_hub) [m].
    double
    smoothing() const
    {
      return 0.8 * (rz_shaft + rz_hub);
    }

    /**
     * Effective radial interference [m] at the reference temperature:
     * (U - smoothing) / 2. Throws InputError, naming @p where, when
     * smoothing leaves no interference.
     */
    double
    effective_radial_interference(const double diameter, const Case c) const;

    /**
     * DIN 7190's mounting temperature of the hub [deg C]: the hub heated
     * from @p reference_temperature until its bore exceeds the shaft by the
     * assembly clearance, (U_max + s) / (alpha_hub D) above it.
     */
    double
    mounting_temperature(const double diameter,
                         const double hub_expansion,
                         const double reference_temperature) const;

    /// Static friction coefficient, if given.
    const std::optional<double> &
    friction() const
    {
      return friction_coefficient;
    }

    /// Torque the joint must carry [N m] (>= 0).
    double
    torque_load() const
    {
      return torque;
    }

    /// Axial force the joint must carry [N] (>= 0).
    double
    axial_load() const
    {
      return axial_force;
    }

    /// Assembly clearance as a fraction of the diameter [-].
    double
    clearance_ratio() const
    {
      return clearance;
    }

  private:
    Given       given = Given::radial;
    double      radial = 0;          ///< "Radial interference" [m]
    std::string designation;         ///< "ISO fit"
    std::vector<double> deviation;   ///< hole lower, upper, shaft lower, upper [m]
    double      rz_shaft = 0, rz_hub = 0;
    std::optional<double> friction_coefficient;
    double      torque = 0, axial_force = 0;
    double      clearance = 1e-3;
    std::string where;
  };
} // namespace rotorfit
