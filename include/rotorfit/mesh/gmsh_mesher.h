#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace rotorfit
{
  /// What gmsh gives AssemblyMesh: the nodes and the element nodes of every
  /// physical volume (quadratic tetrahedra) and surface (quadratic triangles).
  struct GmshMesh
  {
    std::vector<std::size_t>                        node_tags;
    std::vector<double>                             node_coords; ///< x, y, z per node [m]
    std::map<std::string, std::vector<std::size_t>> volumes;     ///< name -> element nodes
    std::map<std::string, std::vector<std::size_t>> surfaces;    ///< name -> element nodes
    unsigned int                                    nodes_per_tet = 0;
    unsigned int                                    nodes_per_tri = 0;
  };

  /**
   * The gmsh side of AssemblyMesh (Geometry/Mesher = gmsh): a .geo opened
   * with its Geometry parameters and meshed in-process through the gmsh API,
   * or a ready .msh read, then its physical groups read back. Before gmsh
   * meshes the volumes (which can take hours and more memory than the
   * machine has) the mesh size is checked against the memory limit. gmsh is
   * serial: run() on one rank only.
   */
  class GmshMesher
  {
  public:
    /// @p geometry_filename with the values of @p geometry_parameters
    /// (gmsh DefineConstant names); @p memory_limit [bytes] the run may use.
    GmshMesher(const std::string                   &geometry_filename,
               const std::map<std::string, double> &geometry_parameters,
               const double                         memory_limit);

    /// Mesh (a .geo) or read (a .msh) the geometry. Throws InputError with
    /// gmsh's message, or if the file has no meshed physical volume.
    GmshMesh
    run() const;

  private:
    /// Open the geometry (with the Geometry parameters) and mesh it (.geo).
    void
    open_and_mesh() const;
    /// Nodes and the elements of every physical volume and surface.
    void
    read_physical_groups(GmshMesh &data) const;
    /// Refuses a mesh too big for the memory limit before gmsh meshes it:
    /// from Mesh.MeshSizeMax and the body volumes, then (@p surfaces_meshed)
    /// also from the surface mesh.
    void
    check_volume_mesh_size(const bool surfaces_meshed) const;

    const std::string                   geometry_filename;
    const std::map<std::string, double> geometry_parameters;
    const double                        memory_limit;
  };
} // namespace rotorfit
