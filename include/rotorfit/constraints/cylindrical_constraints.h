#pragma once

#include <deal.II/base/point.h>

#include <deal.II/dofs/dof_handler.h>

#include <deal.II/lac/affine_constraints.h>

#include <string>
#include <vector>

namespace rotorfit
{
  class AssemblyMesh;

  /**
   * Statically determinate supports of each body for the static
   * (axisymmetric, torsion-free) solve, doc/theory.md 6: u_theta = 0 at five
   * support points (two axial stations, angles near 0, 90, 180 degrees)
   * removes U_x, U_y and the three rotations; u_z = 0 at one point near the
   * body's mid-plane removes U_z. Applied to every body, so a fully loose
   * body stays well posed. The exact solution satisfies them, so their
   * reactions vanish up to mesh asymmetry.
   *
   * Also: u_z = 0 on the faces of the physical surfaces @p roller_surfaces
   * (plane-strain verification set-ups).
   *
   * Returns a description for the log. Throws InputError if a body has no
   * suitable points.
   */
  std::string
  make_cylindrical_constraints(const AssemblyMesh                &mesh,
                               const dealii::DoFHandler<3>        &dof_handler,
                               const std::vector<dealii::Point<3>> &support_points,
                               const std::vector<std::string>      &body_names,
                               const std::vector<std::string>      &roller_surfaces,
                               dealii::AffineConstraints<double>   &constraints);
} // namespace rotorfit
