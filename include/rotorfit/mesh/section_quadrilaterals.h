#pragma once

#include <rotorfit/mesh/section_layout.h>

#include <deal.II/grid/tria.h>

namespace rotorfit
{
  /**
   * The meridian plane of a SectionLayout (doc/theory.md 14.2): each chain's
   * quadrilaterals in the (r, z) half-plane, x = r and y = z, on the same
   * axial nodes and radial fractions the hexahedra are revolved from. A solid
   * chain reaches the axis: its O-grid core becomes a strip of quadrilaterals
   * from r = 0 to the core radius, as wide as the chain's first ring cell.
   * Cylinders and cones are straight lines in this plane, so the cells are
   * exact without a curved mapping. Each body has its own vertices: the two
   * sides of a fit are separate meshes with coincident vertices.
   */
  class SectionQuadrilaterals
  {
  public:
    /// The cells of @p layout (referred to, not copied).
    explicit SectionQuadrilaterals(const SectionLayout &layout);

    /// Build the coarse mesh into @p tria: material_id = body index.
    void
    create(dealii::Triangulation<2> &tria) const;

  private:
    const SectionLayout &layout;
  };
} // namespace rotorfit
