#pragma once

#include <rotorfit/material/bodies.h>
#include <rotorfit/mesh/assembly_mesh.h>

#include <deal.II/dofs/dof_handler.h>

#include <string>
#include <vector>

namespace rotorfit
{
  /**
   * Whether each body is a body of revolution about z, read off its
   * surface: the share of a body's surface area whose outer normal has a
   * circumferential component |n . e_theta| > 1/2. The surface of a body of
   * revolution has none (its faces are revolved lines: n . e_theta = 0, and
   * the curved P2 faces of a mesh stay far below 1/2); a blade's or a key's
   * sides and a flat have n . e_theta close to 1.
   *
   * The stationary-frame eigenproblem (doc/theory.md 4.1, assumption A1)
   * holds only where every rotating body is one of revolution: its
   * gyroscopic and convective matrices let the material move along circles
   * through a fixed shape.
   */
  class RevolutionCheck
  {
  public:
    /// Share of each body's surface facing the circumferential direction
    /// (index: the cells' material id), summed over the ranks of @p comm.
    static std::vector<double>
    circumferential_share(const AssemblyMesh          &mesh,
                          const dealii::DoFHandler<3> &dofs,
                          const unsigned int           n_bodies,
                          const MPI_Comm               comm);

    /**
     * What decides whether a body that is not one of revolution still whirls
     * as one (doc/theory.md 4.1): its centre and its second moments about the
     * axis. For each body (uniform density, so volumes serve), the
     * centroid's distance from the axis and the transverse anisotropy of
     * the second moments of volume J_xx = int x^2, J_yy = int y^2,
     * J_xy = int x y: sqrt((J_xx - J_yy)^2 + 4 J_xy^2) / (J_xx + J_yy),
     * 0 for a body of revolution and for N >= 3 equal blades, (b^2 - h^2) /
     * (b^2 + h^2) for a b x h rectangular section. An anisotropic rotor
     * (a flat, a keyway, two blades) is parametrically excited in the
     * stationary frame: no mode of it is a mode there.
     */
    struct Inertia
    {
      double volume     = 0; ///< [m^3]
      double offset     = 0; ///< centroid's distance from the axis [m]
      double gyration   = 0; ///< transverse radius of gyration sqrt((J_xx + J_yy) / V) [m]
      double anisotropy = 0; ///< [-]
    };
    static std::vector<Inertia>
    transverse_inertia(const AssemblyMesh          &mesh,
                       const dealii::DoFHandler<3> &dofs,
                       const unsigned int           n_bodies,
                       const MPI_Comm               comm);

    /// An anisotropy above this makes the stationary frame wrong for the
    /// whole body, whirl included (the meshes of TS and CI measure below
    /// 1e-6; an elliptic section of axes 1 : 1.001 measures 1e-3).
    static constexpr double anisotropy_limit = 1e-4;
    /// A centroid further off the axis than this fraction of the radius of
    /// gyration is reported as an unbalance the Unbalances do not hold.
    static constexpr double offset_limit = 1e-4;

    /// The set-up's log lines of the bodies that are not of revolution,
    /// anisotropic or off the axis (none for a body of revolution).
    static std::string
    describe(const std::vector<double>  &share,
             const std::vector<Inertia> &inertia,
             const Bodies               &bodies);

    /// A share above this marks a body that is not one of revolution
    /// (0.5 %: TS's and CI's meshes measure 0, the bladed impeller's hub
    /// 14 %).
    static constexpr double limit = 5e-3;
  };
} // namespace rotorfit
