#pragma once

#include <rotorfit/mesh/assembly_mesh.h>

#include <deal.II/dofs/dof_handler.h>

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

    /// A share above this marks a body that is not one of revolution
    /// (0.5 %: TS's and CI's meshes measure 0, the bladed impeller's hub
    /// 14 %).
    static constexpr double limit = 5e-3;
  };
} // namespace rotorfit
