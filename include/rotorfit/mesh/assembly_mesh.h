#pragma once

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>

#include <deal.II/distributed/shared_tria.h>

#include <deal.II/dofs/dof_handler.h>

#include <deal.II/grid/tria_description.h>

#include <deal.II/base/quadrature.h>

#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/mapping_fe_field.h>

#include <rotorfit/mesh/gmsh_mesher.h>
#include <rotorfit/mesh/section_mesh.h>

#include <deal.II/lac/vector.h>

#include <array>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace rotorfit
{
  /**
   * The finite element mesh of an assembly of separate bodies that touch.
   *
   * Two meshers (Geometry/Mesher). gmsh: quadratic tetrahedra of a .geo,
   * meshed in-process through the gmsh API, or of a ready .msh, read on
   * rank 0 and broadcast. sections: hexahedra of axisymmetric bodies given
   * as axial sections (SectionMesh), curved by manifolds and a quadratic
   * MappingQ; named surfaces are boundary ids. With gmsh: Every physical volume named
   * by a body becomes one body (material_id = body index); vertices shared by
   * two bodies are duplicated, one copy per body, so that each body is a
   * separate mesh and the contact pairs can be built on the interface.
   * Curved surfaces are represented to second order: gmsh's mid-edge nodes
   * (placed on the CAD surfaces) define a quadratic position field used by a
   * MappingFEField for every integral and support point. gmsh itself is
   * driven by GmshMesher.
   *
   * Parameters: subsection "Geometry".
   */
  class AssemblyMesh
  {
  public:
    explicit AssemblyMesh(const MPI_Comm comm);

    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// @p prm_directory resolves a relative geometry file name; the section
    /// mesher reads the entry "Sections" of every body in @p body_names.
    void
    parse_parameters(dealii::ParameterHandler       &prm,
                     const std::string              &prm_directory,
                     const std::vector<std::string> &body_names);

    /// Memory this run may use [bytes]: a mesh whose factorisation alone
    /// would need more than 90 % of it is refused before it is built.
    void
    set_memory_limit(const double bytes)
    {
      memory_limit = bytes;
    }

    /// Geometry/Model = axisymmetric: the meridian and Fourier harmonics
    /// (harmonic/) instead of this 3D mesh.
    bool
    axisymmetric_model() const
    {
      return axisymmetric;
    }

    /// Whether the cells are hexahedra (section mesher) or tetrahedra (gmsh).
    bool
    hexahedral() const
    {
      return use_sections;
    }

    /// The scalar Lagrange element of the displacement on these cells.
    std::unique_ptr<dealii::FiniteElement<3>>
    scalar_element() const;

    /// The one rule of every volume integral: Gauss with order + 2 points
    /// on tetrahedra, order + 1 per direction on hexahedra (exact for mass,
    /// stiffness and stress stiffening on straight cells).
    dealii::Quadrature<3>
    cell_quadrature() const;

    /// Gauss rule on a face with @p n points per direction (simplex or
    /// tensor, as the cells are).
    dealii::Quadrature<2>
    face_rule(const unsigned int n) const;

    /// Points on a face at n x n sub-cells (equal weights summing to the
    /// reference face's measure): a band station is cut at them.
    dealii::Quadrature<2>
    face_point_grid(const unsigned int n) const;

    /// The section mesher's layout (one line per body), or "" with gmsh.
    std::string
    describe() const
    {
      return use_sections ? section_mesh.describe() : std::string();
    }

    /// The section mesher (its layout and refinement).
    const SectionMesh &
    sections() const
    {
      return section_mesh;
    }

    /// Nodes adaptive refinement adds to the section mesh (before create()).
    void
    set_refinement(const SectionMesh::Refinement &r)
    {
      section_mesh.set_refinement(r);
    }

    /// What to change when the two sides of a fit have no coincident nodes.
    std::string
    coincidence_hint() const
    {
      return use_sections ?
               "give both bodies the same radius there in their Sections (the "
               "interference is set in the Interface, not in the geometry)." :
               "mesh them together (gmsh BooleanFragments) or raise "
               "Geometry/Interface matching tolerance.";
    }

    /// "tetrahedra" or "hexahedra".
    std::string
    cell_name() const
    {
      return use_sections ? "hexahedra" : "tetrahedra";
    }

    /**
     * Mesh the geometry and build the triangulation. @p body_volumes are the
     * physical volume names, body i gets material_id i.
     */
    void
    create(const std::vector<std::string> &body_volumes);

    dealii::parallel::shared::Triangulation<3> &
    triangulation()
    {
      return tria;
    }

    const dealii::parallel::shared::Triangulation<3> &
    triangulation() const
    {
      return tria;
    }

    const dealii::Mapping<3> &
    mapping() const
    {
      return *mapping_ptr;
    }

    /// Polynomial degree of the displacement field (1 or 2).
    unsigned int
    element_order() const
    {
      return order;
    }

    /// Relative tolerance (times the radius) for pairing interface points.
    double
    matching_tolerance() const
    {
      return match_tol;
    }

    /// Whether face @p face_no of @p cell lies on the physical surface @p name.
    bool
    face_on_surface(const std::string                                 &name,
                    const dealii::Triangulation<3>::cell_iterator &cell,
                    const unsigned int face_no) const;

    /// The names of every physical surface (or surface of the sections).
    std::vector<std::string>
    surface_names() const;

    /// Throw an InputError naming @p entry if @p name is no physical surface.
    void
    check_surface_exists(const std::string &name,
                         const std::string &entry) const;

  private:
    /// The vertices of each body, with a body's own copy of the nodes it
    /// shares with another (the two sides of a fit).
    struct BodyCells
    {
      std::vector<dealii::Point<3>>                            vertices;
      std::vector<std::size_t>                                 vertex_to_tag;
      std::vector<dealii::CellData<3>>                         cells;
      std::vector<std::map<std::size_t, unsigned int>>         body_vertex;
      std::map<std::pair<std::size_t, std::size_t>, dealii::Point<3>> mid_nodes;
    };
    BodyCells
    body_cells(GmshMesh &data, const std::vector<std::string> &body_volumes) const;
    /// The physical surfaces, once per body whose copy of the nodes they touch.
    void
    collect_surfaces(const GmshMesh &data, const BodyCells &body);
    void
    build_position_field(
      const std::map<std::pair<std::size_t, std::size_t>, dealii::Point<3>>
                                     &mid_nodes,
      const std::vector<std::size_t> &vertex_to_tag);

    void
    check_jacobians() const;

    void
    create_from_sections();

    MPI_Comm                                   comm;
    dealii::parallel::shared::Triangulation<3> tria;

    bool                                                              use_sections = false;
    bool                                                              axisymmetric = false;
    SectionMesh                                                       section_mesh;
    std::map<dealii::types::boundary_id, std::set<std::string>>       boundary_names;

    std::string                   geometry_filename;
    std::map<std::string, double> geometry_parameters;
    unsigned int                  order     = 2;
    double                        match_tol = 1e-8;
    double                        memory_limit = 0;

    dealii::FESystem<3>    position_fe;
    dealii::DoFHandler<3>  position_dof_handler;
    dealii::Vector<double> positions;
    std::unique_ptr<dealii::Mapping<3>> mapping_ptr;

    std::map<std::string, std::set<std::array<unsigned int, 3>>> surfaces;
  };
} // namespace rotorfit
