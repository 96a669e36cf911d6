#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/eigen/eigen_solution.h>
#include <rotorfit/harmonic/meridian_model.h>
#include <rotorfit/mesh/section_mesh.h>
#include <rotorfit/model/discretization.h>
#include <rotorfit/statics/static_state.h>

#include <deal.II/base/parameter_handler.h>

#include <deal.II/lac/vector.h>

#include <complex>

#include <string>
#include <vector>

namespace rotorfit
{
  /**
   * Adaptive refinement of the section mesher's hexahedra (doc/theory.md
   * 1.4). A cycle solves the case at the indicator speeds; per active cell
   * it sums Kelly's jump indicator of the static displacement at those
   * speeds and of the real and imaginary parts of the lowest whirl modes
   * (each field normalised to a total of 1); the section mesher then splits
   * the axial layers and radial intervals that hold the largest sums.
   * Refining whole rings keeps the mesh conforming (no hanging nodes, so the
   * contact pairs, the supports and the bearing averages need nothing new)
   * and rotationally symmetric, which a cell-wise refinement driven by the
   * cos(theta) pattern of a bending mode would destroy.
   *
   * Parameters: subsection "Mesh refinement".
   */
  class MeshRefinement
  {
  public:
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// @p hexahedra: the section mesher is on (refinement needs it).
    void
    parse_parameters(dealii::ParameterHandler &prm, const bool hexahedra);

    unsigned int
    cycles() const
    {
      return n_cycles;
    }

    /// The speeds of a cycle [r/min].
    const std::vector<double> &
    speeds() const
    {
      return speeds_rpm;
    }

    /// Stop refining once the mesh has this many DOFs (0: no limit).
    unsigned int
    dof_target() const
    {
      return target;
    }

    bool
    static_indicator() const
    {
      return use_static;
    }

    bool
    modal_indicator() const
    {
      return use_modal;
    }

    /// Start a cycle on @p model's mesh.
    void
    reset(const Discretization &model);

    /// Kelly on the static displacement of @p state.
    void
    add_static(const Discretization &model, const StaticState &state);

    /// Kelly on the real and imaginary parts of the lowest whirl modes.
    void
    add_modes(const Discretization &model, const EigenSolution &solution);

    /// The nodes the next cycle adds, and one line for the log.
    SectionMesh::Refinement
    refine(const Discretization &model, Log &log) const;

    /// The same on the harmonic model's meridian (doc/axisymmetric.md): a
    /// cycle starts with reset_meridian(); the static displacement (harmonic
    /// 0) and the real and imaginary parts of harmonic 1's lowest modes are
    /// fields of the meridian's DoFs; the plan's layers and intervals are
    /// split by the same rule.
    void
    reset_meridian(const MeridianModel &meridian);
    void
    add_meridian_static(const MeridianModel &meridian, const dealii::Vector<double> &u);
    /// Mode @p index (1, 2, ... within harmonic 1) with values @p u.
    void
    add_meridian_mode(const MeridianModel                     &meridian,
                      const unsigned int                       index,
                      const std::vector<std::complex<double>> &u);
    SectionMesh::Refinement
    refine_meridian(const SectionMesh &sections, const MeridianModel &meridian, Log &log) const;

  private:
    template <int dim>
    void
    add_field(const dealii::Mapping<dim>       &mapping,
              const dealii::DoFHandler<dim>    &dofs,
              const dealii::Quadrature<dim - 1> &face_rule,
              const dealii::Vector<double>     &field);
    template <int dim>
    SectionMesh::Refinement
    refine(const SectionMesh &sections, const dealii::Triangulation<dim> &tria, Log &log) const;

    unsigned int          n_cycles   = 0;
    double                fraction   = 0.3;
    unsigned int          target     = 0;
    unsigned int          n_modes    = 4;
    bool                  use_static = true, use_modal = true;
    std::vector<double>   speeds_rpm;
    dealii::Vector<float> eta2; ///< sum of the normalised squared indicators
    unsigned int          n_fields = 0, n_skipped = 0;
  };
} // namespace rotorfit
