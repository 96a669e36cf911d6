#pragma once

#include <deal.II/base/point.h>

#include <deal.II/lac/petsc_vector.h>

#include <vector>

namespace rotorfit
{
  class ContactPairs;

  /**
   * What the fit assessment reads of a static displacement, whatever model
   * made it (a 3D mesh: BodyStress; the axisymmetric meridian:
   * MeridianStress): per body the largest von Mises stress, and per fit
   * interface the nominal stresses at the bores of hub and shaft at the
   * fit's axial mid-plane (doc/fit_design.md). The parts both models share
   * are here: where a fit lies and which pairs make its mid-plane ring (from
   * the pairs alone), the stress on a bore from the strains along it and its
   * traction, and the order of equal peaks.
   */
  class StressField
  {
  public:
    /// The largest von Mises stress of a body and where it is.
    struct Peak
    {
      double           von_mises = 0; ///< [Pa]
      dealii::Point<3> location;      ///< quadrature point [m]
    };

    /// Nominal stress at a bore, at @p radius.
    struct BoreStress
    {
      double radius    = 0; ///< [m]; 0: the axis of a solid shaft
      double sigma_r   = 0; ///< radial [Pa]
      double sigma_t   = 0; ///< hoop (circumferential) [Pa]
      double sigma_z   = 0; ///< axial [Pa]
      double von_mises = 0; ///< [Pa]
    };

    /// Both bores of one fit interface.
    struct FitBore
    {
      BoreStress hub, shaft;
    };

    /// One fit interface as the bore evaluation sees it.
    struct Fit
    {
      unsigned int hub_body = 0, shaft_body = 0; ///< body indices
      double       z_min = 0, z_max = 0;         ///< axial extent of the pairs [m]
      double       radius = 0;                   ///< mean radius of the pairs [m]
      double       shaft_bore = 0;               ///< shaft's innermost radius at z_mid, 0: solid [m]

      /// Axial mid-plane [m].
      double
      z_mid() const
      {
        return 0.5 * (z_min + z_max);
      }
    };

    virtual ~StressField() = default;

    /// Per body, the largest von Mises stress over the cells' quadrature
    /// points and where; ties go to the lexicographically smallest point.
    virtual std::vector<Peak>
    max_von_mises(const dealii::PETScWrappers::MPI::Vector &u) const = 0;

    /// Per interface, the nominal hub and shaft bore stresses at the fit's
    /// mid-plane; @p pair_pressure: each pair's contact pressure [Pa] (0
    /// when open).
    virtual std::vector<FitBore>
    bore(const dealii::PETScWrappers::MPI::Vector &u,
         const std::vector<double>                &pair_pressure) const = 0;

    /// One per interface.
    const std::vector<Fit> &
    fits() const
    {
      return fit_list;
    }

  protected:
    /// Points nudged into a body: 1e-6 of the fit radius (far below any
    /// cell, far above round-off).
    static constexpr double nudge = 1e-6;

    /// The fits' bodies, extents and mean radii (shaft_bore left 0) and
    /// their mid-plane rings, from the pairs.
    void
    find_fits(const ContactPairs &pairs);

    /// Mean pressure of interface @p f's mid-plane ring.
    double
    ring_pressure(const unsigned int f, const std::vector<double> &pair_pressure) const;

    /**
     * The stress on a bore from the strains along it (@p e_tt, @p e_zz,
     * @p e_tz) and its radial traction @p s_r (minus the fit's pressure; 0
     * on a free bore): the finite element stress normal to a surface
     * converges slowly (its normal derivative), the strains along it as the
     * displacement does. Hooke's law gives eps_rr = (s_r - lambda (e_tt +
     * e_zz)) / (lambda + 2 mu), and a frictionless surface carries no shear.
     */
    static BoreStress
    surface_stress(const double e_tt, const double e_zz, const double e_tz, const double s_r,
                   const double lambda, const double mu);

    /// a before b: larger stress, then the lexicographically smaller point
    static bool
    before(const double a, const dealii::Point<3> &pa, const double b, const dealii::Point<3> &pb);

    std::vector<Fit> fit_list;
    /// per interface: the pairs of the mid-plane ring
    std::vector<std::vector<unsigned int>> ring;
  };
} // namespace rotorfit
