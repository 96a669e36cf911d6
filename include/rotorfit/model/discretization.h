#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/contact/contact_pairs.h>
#include <rotorfit/material/bodies.h>
#include <rotorfit/mesh/assembly_mesh.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/timer.h>

#include <deal.II/dofs/dof_handler.h>

#include <deal.II/fe/fe_system.h>

#include <deal.II/lac/affine_constraints.h>

#include <memory>
#include <string>
#include <vector>

namespace rotorfit
{
  /**
   * What the statics and the dynamics both stand on: the gmsh mesh of the
   * bodies, the vector finite element space on it, the coincident node pairs
   * of every fit interface and the statically determinate cylindrical
   * supports of each body (doc/theory.md, sections 0, 1, 6 and 7.1). Built once by
   * setup(); read-only afterwards, so the two solvers are peers that cannot
   * change what the other sees.
   *
   * Parameters: subsections "Mesh", "Supports", "Resources" (the memory
   * the run may use), the lists "Bodies" and "Interfaces" and their
   * per-name subsections.
   */
  class Discretization
  {
  public:
    Discretization(const MPI_Comm comm, Log &log);

    /// Everything but the per-name body/interface subsections.
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    void
    parse_parameters(dealii::ParameterHandler &prm, const std::string &prm_directory);

    /// Nodes adaptive refinement adds to the section mesh (before setup()).
    void
    set_mesh_refinement(const SectionMesh::Refinement &r)
    {
      assembly_mesh.set_refinement(r);
    }

    /// Mesh (gmsh), DoFs, support points, pairs and supports; refuses an
    /// interference beyond the small-strain model.
    void
    setup(dealii::TimerOutput &timer);

    const AssemblyMesh &
    mesh() const
    {
      return assembly_mesh;
    }
    const dealii::DoFHandler<3> &
    dofs() const
    {
      return dof_handler;
    }
    /// Element order of the displacement (and of the geometry mapping).
    unsigned int
    element_order() const
    {
      return assembly_mesh.element_order();
    }
    const dealii::IndexSet &
    locally_owned_dofs() const
    {
      return owned;
    }
    /// Support point of every DoF through the curved mapping [m].
    const std::vector<dealii::Point<3>> &
    support_points() const
    {
      return points;
    }
    const Bodies &
    bodies() const
    {
      return body_list;
    }
    const ContactInterfaces &
    interfaces() const
    {
      return interface_list;
    }
    const ContactPairs &
    pairs() const
    {
      return contact_pairs;
    }
    /// Cylindrical supports (and axial rollers) of the static problem.
    const dealii::AffineConstraints<double> &
    static_constraints() const
    {
      return constraints;
    }
    const std::vector<std::string> &
    roller_surfaces() const
    {
      return rollers;
    }
    /// Largest distance of a support point from the axis [m].
    double
    outer_radius() const;

    /// Memory this run may use [bytes] (Resources/Memory limit): the
    /// model is refused above 90 % of it.
    double
    memory_limit() const
    {
      return memory_limit_bytes;
    }

    MPI_Comm
    mpi_communicator() const
    {
      return comm;
    }

  private:
    void
    compute_support_points();
    /// Interference against the fit radius (small strain, elastic limit).
    void
    check_interference() const;
    /// Warns of bodies that touch at a fit no Interface uses.
    void
    check_unused_fits() const;

    MPI_Comm comm;
    Log     &log;

    AssemblyMesh             assembly_mesh;
    Bodies                   body_list;
    ContactInterfaces        interface_list;
    std::vector<std::string> rollers;
    double                   memory_limit_bytes = 0;

    std::unique_ptr<dealii::FESystem<3>> fe;
    dealii::DoFHandler<3>                dof_handler;
    dealii::IndexSet                     owned;
    std::vector<dealii::Point<3>>        points;
    ContactPairs                         contact_pairs;
    dealii::AffineConstraints<double>    constraints;
  };
} // namespace rotorfit
