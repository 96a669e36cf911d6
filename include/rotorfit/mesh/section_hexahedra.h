#pragma once

#include <rotorfit/mesh/section_layout.h>

#include <deal.II/base/point.h>

#include <deal.II/grid/tria.h>
#include <deal.II/grid/tria_description.h>

#include <vector>

namespace rotorfit
{
  /**
   * The cells of a SectionLayout: each chain's quadrilaterals in the (r, z)
   * half-plane revolved into n_theta circumferential hexahedra, and in a
   * solid chain an O-grid core (a square of (n_theta/4)^2 cells and one
   * transition ring) so that no cell degenerates on the axis. Ring cells
   * carry a cylindrical chart manifold (exact on cylinders and cones). Each
   * body has its own vertices, so the two sides of a fit are separate
   * meshes with coincident vertices.
   */
  class SectionHexahedra
  {
  public:
    /// The cells of @p layout (referred to, not copied) with @p n_theta
    /// cells around.
    SectionHexahedra(const SectionLayout &layout, const unsigned int n_theta);

    /// Build the coarse mesh into @p tria: material_id = body index,
    /// manifold id 1 (the cylindrical chart) on the ring cells.
    void
    create(dealii::Triangulation<3> &tria) const;

  private:
    /// The hexahedra of body @p b on the layout's axial nodes.
    void
    add_body_cells(const unsigned int                b,
                   std::vector<dealii::Point<3>>    &vertices,
                   std::vector<dealii::CellData<3>> &cells) const;

    const SectionLayout &layout;
    const unsigned int   n_theta;
  };
} // namespace rotorfit
