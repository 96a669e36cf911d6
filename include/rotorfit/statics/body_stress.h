#pragma once

#include <rotorfit/statics/stress_field.h>

#include <deal.II/base/point.h>

#include <deal.II/dofs/dof_handler.h>

#include <deal.II/lac/petsc_vector.h>

#include <array>
#include <vector>

namespace rotorfit
{
  class Discretization;

  /**
   * The stresses a shrink-fit designer checks (DIN 7190), evaluated from a
   * static displacement: per body the largest von Mises stress, and per fit
   * interface the nominal stresses at the bore of the hub and of the shaft.
   * Stress sigma = lambda tr(eps) I + 2 mu eps with the body's Lame
   * parameters (material_id = body index), as in the ParaView output.
   *
   * Why the nominal values are taken at the fit's axial mid-plane and at the
   * body's innermost radius: DIN 7190 designs a fit with the Lame solution
   * of a long (or thin) cylinder pair, whose stresses are largest at the
   * bore, r = innermost radius of the body (hub: the fit radius; hollow
   * shaft: its bore; solid shaft: the axis, where sigma_r = sigma_theta =
   * -p). The mid-plane is where the 3D state is closest to that solution, as
   * far as it can be from the fit's ends. At a hub edge (the end of the
   * contact) the 3D stress is singular: its maximum grows with refinement,
   * so it is no design value; it is reported separately, by
   * max_von_mises(), and compared with the nominal value to see the edge's
   * concentration.
   *
   * The bore values are means over 8 equally spaced angles, each at a point
   * nudged into the body by 1e-6 of the fit radius and evaluated in a cell
   * of that body only (the two bodies have separate cells on the fit). The
   * cells and their unit points are found once, on construction; every rank
   * holds the whole triangulation, so the search is the same everywhere.
   * Each point is evaluated on the rank that owns its cell and summed over
   * the ranks: the results are identical on every rank and need only the
   * ghosts of the owned cells.
   */
  class BodyStress : public StressField
  {
  public:
    /// Finds the fits' bodies, extents and bore points (all ranks alike).
    explicit BodyStress(const Discretization &model);


    /**
     * Per body, the largest von Mises stress over the cell quadrature points
     * and its location; ties go to the lexicographically smallest point,
     * so that any number of ranks agrees. A body without cells: 0 at the
     * origin. MPI-collective; @p u needs the ghosts of the owned cells.
     */
    std::vector<Peak>
    max_von_mises(const dealii::PETScWrappers::MPI::Vector &u) const override;

    /**
     * Per interface, the nominal hub and shaft bore stresses at the fit's
     * mid-plane (see the class comment). MPI-collective; @p u needs the
     * ghosts of the owned cells; @p pair_pressure: each pair's contact
     * pressure [Pa] (0 when open).
     *
     * On a bore surface the finite element stress normal to it converges
     * slowly (its normal derivative: 3 % off on a coarse hexahedral hub),
     * while the strains along the surface (eps_tt, eps_zz, eps_tz) are as
     * good as the displacement. The stress there is therefore made from
     * those strains and the surface's traction, sigma_r = -p on the fit
     * (p the mean pressure of the pairs of the mid-plane ring; 0 on a free
     * bore), through Hooke's law: eps_rr = (sigma_r -
     * lambda (eps_tt + eps_zz)) / (lambda + 2 mu), and no shear across a
     * frictionless surface. This is exact for the continuum; it brought
     * the hollow shaft's bore from 5.8 % to below 0.5 % on the same mesh.
     */
    std::vector<FitBore>
    bore(const dealii::PETScWrappers::MPI::Vector &u,
         const std::vector<double>                &pair_pressure) const override;

  private:
    /// A point of a bore, located in a cell of its body.
    struct BorePoint
    {
      dealii::DoFHandler<3>::active_cell_iterator cell;
      dealii::Point<3>                            unit;  ///< in the reference cell
      double                                      angle; ///< of the point about z [rad]
      /// on a surface: the stress from the surface's own strains and its
      /// traction (see bore()); false: a point on the axis
      bool surface = false;
      /// 0: on the fit, its traction the mean pressure of the mid-plane
      /// ring; -1: a free surface
      int pair = -1;
    };

    /// The cell of body @p body nearest to @p p in unit coordinates (ties:
    /// lower cell index) and the unit point, moved into the reference cell;
    /// @p distance: how far outside the reference cell p was.
    BorePoint
    locate(const dealii::Point<3> &p, const unsigned int body, double &distance) const;

    /// sigma_r, sigma_t, sigma_z, von Mises at each point of @p points
    /// (zero where the cell is not owned).
    void
    evaluate(const std::vector<BorePoint>             &points,
             const dealii::PETScWrappers::MPI::Vector &u,
             const double                              ring_pressure,
             std::vector<double>                      &values) const;

    const Discretization &model;
    /// per interface: the 8 points of the hub [0] and of the shaft [1]
    std::vector<std::array<std::vector<BorePoint>, 2>> points;
  };
} // namespace rotorfit
