#pragma once

#include <rotorfit/mesh/section_layout.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/types.h>

#include <deal.II/grid/tria.h>
#include <deal.II/grid/tria_description.h>

#include <deal.II/lac/vector.h>

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace rotorfit
{
  /**
   * The hexahedral mesher of axisymmetric bodies given as axial sections
   * (doc/theory.md 1.3): every body is a stack of sections (cylinders,
   * annuli, cones: z from, z to, inner and outer radius at each end) meshed
   * with quadrilaterals in the (r, z) half-plane and revolved into N
   * circumferential cells. A solid section gets an O-grid core (a square of
   * (N/4)^2 cells and one transition ring) so that no cell degenerates on the
   * axis. The ring part of the mesh maps onto itself under a rotation of
   * 2 pi / N; the core under pi / 2.
   *
   * All bodies share the axial nodes (every section end of every body is
   * one) and the angles, so the two sides of a fit carry coincident vertices
   * and support points by construction. Axial and radial sizes grade from
   * the fit element size at the fits to the element size away from them.
   * Ring cells carry a cylindrical chart manifold (exact on cylinders and
   * cones); with a quadratic mapping the geometry is curved.
   *
   * Named surfaces (for interfaces, bearings, probes, rollers) are built from
   * selectors on the bodies' boundaries and set as boundary ids.
   *
   * The plan (fit zones, axial nodes, radial fractions) is a SectionLayout,
   * its cells are built by SectionHexahedra; this class reads the
   * parameters, names the surfaces and picks the next refinement.
   *
   * Parameters: subsection "Geometry/Sections" and the entry "Sections" of
   * every "Body <name>".
   */
  class SectionMesh
  {
  public:
    /// One axial section: a cylinder, annulus or cone (radii linear in z).
    using Section = AxialSection;

    /// Which boundary of a body a selector picks.
    enum class Side
    {
      outer,
      inner,
      start,
      end
    };
    /// One selector of Geometry/Sections/Surfaces: a side of a body, the
    /// outer or inner one within [z_from, z_to] [m].
    struct Selector
    {
      unsigned int body;
      Side         side;
      double       z_from, z_to;
    };

    /// Nodes added by adaptive refinement (whole rings: the mesh stays
    /// conforming and rotationally symmetric).
    using Refinement = SectionRefinement;

    /// Inside subsection "Geometry".
    static void
    declare_parameters(dealii::ParameterHandler &prm);
    /// The "Sections" entry of every "Body <name>".
    static void
    declare_body_parameters(dealii::ParameterHandler       &prm,
                            const std::vector<std::string> &bodies);

    /// Inside subsection "Geometry".
    void
    parse_parameters(dealii::ParameterHandler &prm);
    /// At the top level, after parse_parameters().
    void
    parse_body_parameters(dealii::ParameterHandler       &prm,
                          const std::vector<std::string> &bodies);

    /// Hexahedra before they are built (for the size check).
    double
    n_cells() const;

    /**
     * Build the coarse mesh into @p tria: material_id = body index, manifold
     * id 1 (cylindrical chart) on the ring cells, boundary ids whose names
     * go to @p names (id -> surface names; id 0 has none).
     */
    void
    create(dealii::Triangulation<3>                                   &tria,
           std::map<dealii::types::boundary_id, std::set<std::string>> &names) const;

    /**
     * The meridian plane of the same plan (Geometry/Model = axisymmetric):
     * quadrilaterals in (r, z) (SectionQuadrilaterals), the surfaces named as
     * in create(), their boundary ids on the meridian's boundary lines.
     */
    void
    create_meridian(dealii::Triangulation<2>                                   &tria,
                    std::map<dealii::types::boundary_id, std::set<std::string>> &names) const;

    /// Add these nodes to the next create().
    void
    set_refinement(const Refinement &r)
    {
      refinement = r;
    }

    const Refinement &
    current_refinement() const
    {
      return refinement;
    }

    /**
     * The refinement after this one: the axial layers and the radial
     * intervals holding the largest sums of @p indicator^2 (per active cell
     * of @p tria, the hexahedra or the meridian this object created), a share
     * @p fraction of each, are split in the middle.
     */
    template <int dim>
    Refinement
    refined(const dealii::Triangulation<dim> &tria,
            const dealii::Vector<float>      &indicator,
            const double                      fraction) const;

    /// One line per body for the log; @p meridian: the plan alone (the
    /// harmonic model's meridian has no cells around).
    std::string
    describe(const bool meridian = false) const;

    unsigned int
    circumferential_cells() const
    {
      return n_theta;
    }

  private:
    /// The plan of the current sections and refinement.
    SectionLayout
    plan() const;
    void
    read_sections(const unsigned int b, const std::string &text);
    void
    check_sections(const unsigned int b) const;
    void
    set_core_radii();
    void
    parse_surfaces();
    Selector
    parse_selector(const std::string &selector, const std::string &surface) const;
    /// Which boundary of body @p b a face is on (none: a step); @p zm its
    /// mean axial position.
    template <int dim>
    std::optional<Side>
    face_side(const typename dealii::Triangulation<dim>::face_iterator &face,
              const unsigned int                             b,
              double                                        &zm) const;
    template <int dim>
    void
    name_boundaries(dealii::Triangulation<dim>                                 &tria,
                    std::map<dealii::types::boundary_id, std::set<std::string>> &names) const;

    unsigned int                                  n_theta = 24;
    double                                        h_max   = 8e-3;
    double                                        h_fit   = 4e-3;
    double                                        h_edge  = 4e-3;
    std::vector<std::string>                      body_names;
    std::vector<std::vector<Section>>             sections;
    std::vector<double>                           core_radius;
    std::string                                   surfaces_text;
    Refinement                                    refinement;
    std::map<std::string, std::vector<Selector>> surfaces;
  };
} // namespace rotorfit
