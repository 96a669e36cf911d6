#include <rotorfit/base/input_error.h>
#include <rotorfit/base/resources.h>
#include <rotorfit/mesh/assembly_mesh.h>

#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <unordered_map>

// AssemblyMesh: the size check before gmsh meshes the volumes (the rest of
// the mesher: assembly_mesh.cc).

namespace rotorfit
{
  using namespace dealii;

  void
  AssemblyMesh::check_volume_mesh_size(const bool surfaces_meshed) const
  {
    // A lower bound on the tetrahedra before gmsh meshes the volumes (which
    // can take hours and more memory than the machine has): the body
    // volumes over the volume of a regular tetrahedron of the largest mesh
    // size, and at least a quarter of the surface triangles.
    double h = 0;
    gmsh::option::getNumber("Mesh.MeshSizeMax", h);
    double longest_edge = 0, triangles = 0;
    std::vector<double>      coords, parametric;
    std::vector<std::size_t> tags;
    if (surfaces_meshed)
      gmsh::model::mesh::getNodes(tags, coords, parametric, -1, -1, false, false);
    std::unordered_map<std::size_t, std::size_t> index;
    for (std::size_t i = 0; i < tags.size(); ++i)
      index[tags[i]] = i;
    std::vector<int>                      types;
    std::vector<std::vector<std::size_t>> element_tags, nodes;
    if (surfaces_meshed)
      gmsh::model::mesh::getElements(types, element_tags, nodes, 2, -1);
    for (unsigned int t = 0; t < types.size(); ++t)
      if (types[t] == 2) // 3-node triangles
        for (std::size_t e = 0; e + 2 < nodes[t].size(); e += 3)
          {
            triangles += 1;
            for (unsigned int a = 0; a < 3; ++a)
              {
                const std::size_t i = index[nodes[t][e + a]], j = index[nodes[t][e + (a + 1) % 3]];
                longest_edge = std::max(longest_edge,
                                        std::hypot(coords[3 * i] - coords[3 * j],
                                                   coords[3 * i + 1] - coords[3 * j + 1],
                                                   coords[3 * i + 2] - coords[3 * j + 2]));
              }
          }
    if (longest_edge > 0)
      h = std::min(h, longest_edge);
    gmsh::vectorpair volumes;
    gmsh::model::getEntities(volumes, 3);
    double volume = 0;
    for (const auto &[dim, tag] : volumes)
      {
        double v = 0;
        try
          {
            gmsh::model::occ::getMass(dim, tag, v);
          }
        catch (...)
          {
            // built-in kernel: the bounding box bounds the volume from above
            double x0, y0, z0, x1, y1, z1;
            gmsh::model::getBoundingBox(dim, tag, x0, y0, z0, x1, y1, z1);
            v = 0.25 * (x1 - x0) * (y1 - y0) * (z1 - z0);
          }
        volume += std::abs(v);
      }
    if (!(h > 0) || !(volume > 0))
      return;
    const double cells = std::max(volume / (resources::regular_tet_volume * h * h * h),
                                  0.25 * triangles);
    const double dofs  = cells * resources::dofs_per_tetrahedron;
    const double bytes = resources::factorization_bytes(dofs, false);
    const double limit = resources::physical_memory_bytes();
    if (bytes > 0.9 * limit)
      {
        std::ostringstream m;
        m << std::setprecision(3) << "Geometry/Geometry file '" << geometry_filename
          << "': the mesh would have at least " << cells << " tetrahedra (bodies "
          << volume * 1e6 << " cm^3, largest element " << h * 1e3 << " mm), about " << dofs
          << " DOFs; their factorisation alone needs about " << resources::gigabytes(bytes)
          << " of the " << resources::gigabytes(limit)
          << " this run may use. Coarsen the mesh (Geometry/Geometry parameters) or use a "
             "bigger machine.";
        throw InputError(m.str());
      }
  }
} // namespace rotorfit
