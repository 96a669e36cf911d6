#include <rotorfit/base/format.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/base/resources.h>
#include <rotorfit/mesh/gmsh_mesher.h>

#include <gmsh.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <unordered_map>

namespace rotorfit
{
  GmshMesher::GmshMesher(const std::string                   &geometry_filename,
                         const std::map<std::string, double> &geometry_parameters,
                         const double                         memory_limit)
    : geometry_filename(geometry_filename)
    , geometry_parameters(geometry_parameters)
    , memory_limit(memory_limit)
  {}

  namespace
  {
    // gmsh throws from inside its OpenMP regions on some bad input (a mesh
    // size of zero or less), where no catch can reach it and the runtime
    // calls std::terminate: this handler turns the abort into an input
    // error. std::set_terminate takes no context, hence the file-scope text.
    std::string gmsh_context;

    [[noreturn]] void
    gmsh_aborted()
    {
      std::string what = "no message";
      if (const std::exception_ptr e = std::current_exception())
        try
          {
            std::rethrow_exception(e);
          }
        catch (const std::string &s)
          {
            what = s;
          }
        catch (const std::exception &x)
          {
            what = x.what();
          }
        catch (...)
          {
          }
      std::fprintf(stderr,
                   "rotorfit: error: %s: gmsh stopped while meshing (%s); a mesh size of zero "
                   "or less, or a geometry gmsh cannot mesh, does this: check the parameters.\n",
                   gmsh_context.c_str(), printable(what).c_str());
      std::_Exit(1);
    }
  } // namespace

  GmshMesh
  GmshMesher::run() const
  {
    GmshMesh data;
    gmsh_context = "Geometry/Geometry file '" + geometry_filename + "'";
    if (!geometry_parameters.empty())
      {
        std::ostringstream list;
        for (const auto &[name, value] : geometry_parameters)
          list << (list.tellp() > 0 ? ", " : "") << name << ": " << value;
        gmsh_context += " with Geometry/Geometry parameters '" + list.str() + "'";
      }
    struct TerminateGuard // the handler only while gmsh runs
    {
      std::terminate_handler previous = std::set_terminate(gmsh_aborted);
      ~TerminateGuard() { std::set_terminate(previous); }
    } guard;
    gmsh::initialize();
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::option::setNumber("General.Verbosity", 2);
    try
      {
        open_and_mesh();
        read_physical_groups(data);
        data.nodes_per_tet = 10;
        data.nodes_per_tri = 6;
      }
    catch (const InputError &)
      {
        gmsh::finalize();
        throw;
      }
    catch (const std::exception &e)
      {
        gmsh::finalize();
        throw InputError("Geometry/Geometry file '" + geometry_filename +
                         "': gmsh failed: " + e.what());
      }
    catch (...)
      {
        // gmsh's own last error (a .geo's Error() says what is wrong), and
        // the command that repeats the run with the same parameters
        std::string last;
        try
          {
            gmsh::logger::getLastError(last);
          }
        catch (...)
          {
          }
        std::ostringstream command;
        command << std::setprecision(12) << "gmsh -3";
        for (const auto &[name, value] : geometry_parameters)
          command << " -setnumber " << name << ' ' << value;
        gmsh::finalize();
        throw InputError(gmsh_context + ": gmsh failed" +
                         (last.empty() ? std::string() : ": " + last) + "; run '" + command.str() +
                         " " + geometry_filename + "' to see all its messages.");
      }
    gmsh::finalize();
    if (data.volumes.empty())
      throw InputError("Geometry/Geometry file '" + geometry_filename +
                       "' has no meshed physical volumes; declare one "
                       "Physical Volume per body.");
    return data;
  }

  void
  GmshMesher::open_and_mesh() const
  {
    std::string file = geometry_filename;
    std::filesystem::path scratch;
    const bool  is_geo =
      std::filesystem::path(file).extension().string() == ".geo";
    if (is_geo && !geometry_parameters.empty())
      {
        // The .geo's DefineConstant keeps values defined before it. The
        // wrapper goes to a private temporary file (--validate writes
        // nothing into the case's directories).
        scratch = std::filesystem::temp_directory_path() /
                  ("rotorfit-" + std::to_string(::getpid()) + ".geo");
        file = scratch.string();
        std::ofstream out(file);
        out.precision(17);
        for (const auto &[name, value] : geometry_parameters)
          out << name << " = " << value << ";\n";
        out << "Include \""
            << std::filesystem::absolute(geometry_filename).string()
            << "\";\n";
      }
    gmsh::open(file);
    if (!scratch.empty())
      std::filesystem::remove(scratch);
    if (is_geo)
      {
        check_volume_mesh_size(false); // before a huge surface mesh too
        gmsh::model::mesh::generate(2);
        check_volume_mesh_size(true);
        gmsh::model::mesh::generate(3);
      }
    // quadratic geometry always: gmsh puts mid-edge nodes on the CAD
    gmsh::model::mesh::setOrder(2);
  }

  void
  GmshMesher::read_physical_groups(GmshMesh &data) const
  {
    std::vector<double> parametric;
    gmsh::model::mesh::getNodes(data.node_tags,
                                data.node_coords,
                                parametric,
                                -1,
                                -1,
                                false,
                                false);

    gmsh::vectorpair groups;
    gmsh::model::getPhysicalGroups(groups);
    for (const auto &[dim, tag] : groups)
      {
        if (dim != 2 && dim != 3)
          continue;
        std::string name;
        gmsh::model::getPhysicalName(dim, tag, name);
        if (name.empty())
          name = std::to_string(tag);
        std::vector<int> entities;
        gmsh::model::getEntitiesForPhysicalGroup(dim, tag, entities);
        auto &list = (dim == 3 ? data.volumes[name] : data.surfaces[name]);
        for (const int e : entities)
          {
            std::vector<int>                      types;
            std::vector<std::vector<std::size_t>> element_tags, nodes;
            gmsh::model::mesh::getElements(
              types, element_tags, nodes, dim, e);
            for (unsigned int t = 0; t < types.size(); ++t)
              {
                const int expected = (dim == 3 ? 11 : 9); // tet10, tri6
                if (types[t] != expected)
                  throw InputError(
                    "Geometry/Geometry file '" + geometry_filename +
                    "': physical " +
                    std::string(dim == 3 ? "volume" : "surface") + " '" +
                    name +
                    "' holds elements other than tetrahedra/triangles "
                    "(gmsh type " +
                    std::to_string(types[t]) +
                    "); rotorfit reads simplex meshes.");
                list.insert(list.end(), nodes[t].begin(), nodes[t].end());
              }
          }
      }
  }

  void
  GmshMesher::check_volume_mesh_size(const bool surfaces_meshed) const
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
    const double limit = memory_limit;
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
