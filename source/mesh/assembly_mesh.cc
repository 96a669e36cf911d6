#include <rotorfit/base/patterns.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/base/resources.h>
#include <rotorfit/mesh/assembly_mesh.h>
#include <rotorfit/mesh/gmsh_mesher.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/utilities.h>

#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q.h>

#include <deal.II/grid/reference_cell.h>
#include <deal.II/grid/tria_description.h>

#include <gmsh.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <unordered_map>
#include <fstream>
#include <iomanip>
#include <regex>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

  AssemblyMesh::AssemblyMesh(const MPI_Comm comm)
    : comm(comm)
    , tria(comm)
    , position_fe(FE_SimplexP<3>(2), 3)
  {}

  void
  AssemblyMesh::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Geometry");
    prm.declare_entry("Mesher",
                      "gmsh",
                      Patterns::Selection("gmsh|sections"),
                      "gmsh: quadratic tetrahedra of the Geometry file. sections: "
                      "hexahedra that rotorfit builds from the axial sections of "
                      "every body (Body <name>/Sections, subsection Sections); no "
                      "Geometry file is needed.");
    prm.declare_entry("Model",
                      "3d",
                      Patterns::Selection("3d|axisymmetric"),
                      "3d: the bodies as solids (Mesher gmsh or sections). "
                      "axisymmetric: the meridian plane (r, z) of the bodies' "
                      "Sections in quadrilaterals and Fourier harmonics around "
                      "the axis (subsection Harmonic model; doc/theory.md 14); "
                      "needs Mesher = sections and a body of revolution.");
    SectionMesh::declare_parameters(prm);
    prm.declare_entry("Geometry file",
                      "",
                      Patterns::FileName(),
                      "gmsh geometry (.geo, meshed here through the gmsh API) "
                      "or ready mesh (.msh). Relative names are taken from "
                      "the directory of the parameter file. Bodies are "
                      "physical volumes, interfaces and supports physical "
                      "surfaces.");
    prm.declare_entry("Geometry parameters",
                      "",
                      Patterns::Map(Patterns::Anything(), Patterns::Double()),
                      "Numbers handed to the .geo file before it is read, as "
                      "'name: value, ...' [SI units, m for sizes]; the .geo "
                      "must declare each with DefineConstant. The shipped "
                      "geometries use h_fit (element size at the fit) and "
                      "h_max (largest element size).");
    prm.declare_entry("Element order",
                      "2",
                      Patterns::Integer(1, 2),
                      "Polynomial degree of the displacement field (1 or 2), on "
                      "tetrahedra or hexahedra. The geometry is always quadratic.");
    prm.declare_entry("Interface matching tolerance",
                      "1e-8",
                      Patterns::Double(0.),
                      "Two interface support points are a pair if they are "
                      "closer than this times their radius [-] (0: exactly "
                      "coincident).");
    prm.leave_subsection();
  }

  void
  AssemblyMesh::parse_parameters(ParameterHandler               &prm,
                                 const std::string              &prm_directory,
                                 const std::vector<std::string> &body_names)
  {
    prm.enter_subsection("Geometry");
    use_sections = (prm.get("Mesher") == "sections");
    axisymmetric = (prm.get("Model") == "axisymmetric");
    if (axisymmetric && !use_sections)
      throw InputError("Geometry/Model = axisymmetric meshes the meridian plane from the "
                       "bodies' Sections, but Geometry/Mesher = gmsh gives a 3D mesh of the "
                       "Geometry file; set Geometry/Mesher = sections (every body needs its "
                       "Sections), or Geometry/Model = 3d for a body that is not of revolution.");
    order        = prm.get_integer("Element order");
    match_tol    = prm.get_double("Interface matching tolerance");
    if (use_sections)
      {
        section_mesh.parse_parameters(prm);
        prm.leave_subsection();
        section_mesh.parse_body_parameters(prm, body_names);
        return;
      }
    geometry_filename = prm.get("Geometry file");
    if (geometry_filename.empty())
      throw InputError("Geometry/Geometry file is not set; give a .geo or "
                       ".msh file.");
    std::filesystem::path p(geometry_filename);
    if (p.is_relative())
      p = std::filesystem::path(prm_directory) / p;
    geometry_filename = p.lexically_normal().string();
    if (!std::filesystem::exists(geometry_filename))
      throw InputError("Geometry/Geometry file: the file '" +
                       geometry_filename +
                       "' does not exist; check the name (relative names are "
                       "taken from the parameter file's directory).");
    const std::string ext = p.extension().string();
    if (ext != ".geo" && ext != ".msh")
      throw InputError("Geometry/Geometry file = '" + geometry_filename +
                       "': the extension must be .geo or .msh.");

    geometry_parameters.clear();
    for (const auto &item :
         Utilities::split_string_list(prm.get("Geometry parameters"), ','))
      {
        const auto kv = Utilities::split_string_list(item, ':');
        geometry_parameters[kv[0]] = Utilities::string_to_double(kv[1]);
        if (!std::regex_match(kv[0], std::regex("[A-Za-z_][A-Za-z0-9_]*")))
          throw InputError("Geometry/Geometry parameters: '" + kv[0] +
                           "' is not a valid gmsh variable name.");
      }
    if (!geometry_parameters.empty())
      {
        if (ext != ".geo")
          throw InputError("Geometry/Geometry parameters are set but '" +
                           geometry_filename +
                           "' is a ready mesh (.msh); remove them or give "
                           "the .geo file.");
        std::ifstream     in(geometry_filename);
        std::stringstream text;
        text << in.rdbuf();
        for (const auto &[name, value] : geometry_parameters)
          if (!std::regex_search(text.str(),
                                 std::regex("\\b" + name + "\\b")))
            throw InputError("Geometry/Geometry parameters: '" + name +
                             "' does not occur in '" + geometry_filename +
                             "'; check the spelling (it must be declared "
                             "there with DefineConstant).");
      }
    prm.leave_subsection();
  }

  void
  AssemblyMesh::create(const std::vector<std::string> &body_volumes)
  {
    if (use_sections)
      {
        create_from_sections();
        return;
      }
    // mesh on rank 0 only, then broadcast: gmsh is serial and every rank
    // must see exactly the same mesh
    GmshMesh    data;
    std::string error;
    if (Utilities::MPI::this_mpi_process(comm) == 0)
      {
        try
          {
            data = GmshMesher(geometry_filename, geometry_parameters, memory_limit).run();
          }
        catch (const InputError &e)
          {
            error = e.what();
          }
      }
    error = Utilities::MPI::broadcast(comm, error, 0);
    if (!error.empty())
      throw InputError(error);
    data.node_tags     = Utilities::MPI::broadcast(comm, data.node_tags, 0);
    data.node_coords   = Utilities::MPI::broadcast(comm, data.node_coords, 0);
    data.volumes       = Utilities::MPI::broadcast(comm, data.volumes, 0);
    data.surfaces      = Utilities::MPI::broadcast(comm, data.surfaces, 0);
    data.nodes_per_tet = Utilities::MPI::broadcast(comm, data.nodes_per_tet, 0);
    data.nodes_per_tri = Utilities::MPI::broadcast(comm, data.nodes_per_tri, 0);

    // unknown physical volumes are errors that list what the file has
    for (const auto &name : body_volumes)
      if (data.volumes.count(name) == 0)
        {
          std::string known;
          for (const auto &v : data.volumes)
            known += (known.empty() ? "" : ", ") + v.first;
          throw InputError("Physical volume '" + name +
                           "' (a body's 'Physical volume') is not in '" +
                           geometry_filename + "'; it has: " + known + ".");
        }

    const BodyCells body = body_cells(data, body_volumes);
    tria.create_triangulation(body.vertices, body.cells, SubCellData());
    collect_surfaces(data, body);
    build_position_field(body.mid_nodes, body.vertex_to_tag);
    check_jacobians();
  }

  AssemblyMesh::BodyCells
  AssemblyMesh::body_cells(GmshMesh &data, const std::vector<std::string> &body_volumes) const
  {
    std::map<std::size_t, Point<3>> node_position;
    for (unsigned int i = 0; i < data.node_tags.size(); ++i)
      node_position[data.node_tags[i]] = Point<3>(data.node_coords[3 * i],
                                                  data.node_coords[3 * i + 1],
                                                  data.node_coords[3 * i + 2]);

    BodyCells                body;
    auto                    &vertices      = body.vertices;
    auto                    &vertex_to_tag = body.vertex_to_tag;
    auto                    &cells         = body.cells;
    auto                    &body_vertex   = body.body_vertex;
    auto                    &mid_nodes     = body.mid_nodes;
    body_vertex.resize(body_volumes.size());

    for (unsigned int b = 0; b < body_volumes.size(); ++b)
      {
        const auto &nodes = data.volumes[body_volumes[b]];
        const unsigned int npe = data.nodes_per_tet;
        for (std::size_t e = 0; e < nodes.size() / npe; ++e)
          {
            std::array<std::size_t, 4> v;
            for (unsigned int i = 0; i < 4; ++i)
              v[i] = nodes[e * npe + i];
            const Tensor<1, 3> a = node_position[v[1]] - node_position[v[0]];
            const Tensor<1, 3> c = node_position[v[2]] - node_position[v[0]];
            const Tensor<1, 3> d = node_position[v[3]] - node_position[v[0]];
            if (cross_product_3d(a, c) * d < 0)
              std::swap(v[1], v[2]);

            CellData<3> cell(4);
            for (unsigned int i = 0; i < 4; ++i)
              {
                auto it = body_vertex[b].find(v[i]);
                if (it == body_vertex[b].end())
                  {
                    it = body_vertex[b].emplace(v[i], vertices.size()).first;
                    vertices.push_back(node_position[v[i]]);
                    vertex_to_tag.push_back(v[i]);
                  }
                cell.vertices[i] = it->second;
              }
            cell.material_id = b;
            cells.push_back(cell);

            // mid-edge nodes: identify the edge of each by proximity (robust
            // against the element's node ordering convention)
            for (unsigned int m = 4; m < npe; ++m)
              {
                const Point<3> &x = node_position[nodes[e * npe + m]];
                double          best = 1e300;
                std::pair<std::size_t, std::size_t> key;
                for (unsigned int i = 0; i < 4; ++i)
                  for (unsigned int j = i + 1; j < 4; ++j)
                    {
                      const double dist =
                        x.distance(0.5 * (node_position[v[i]] +
                                          Tensor<1, 3>(node_position[v[j]])));
                      if (dist < best)
                        {
                          best = dist;
                          key  = {std::min(v[i], v[j]), std::max(v[i], v[j])};
                        }
                    }
                mid_nodes[key] = x;
              }
          }
        if (nodes.empty())
          throw InputError("Physical volume '" + body_volumes[b] +
                           "' has no tetrahedra in '" + geometry_filename +
                           "'.");
      }

    return body;
  }

  void
  AssemblyMesh::collect_surfaces(const GmshMesh &data, const BodyCells &body)
  {
    const auto &body_vertex = body.body_vertex;
    surfaces.clear();
    for (const auto &[name, nodes] : data.surfaces)
      {
        auto &set = surfaces[name];
        for (std::size_t e = 0; e < nodes.size() / data.nodes_per_tri; ++e)
          for (unsigned int b = 0; b < body_vertex.size(); ++b)
            {
              std::array<unsigned int, 3> key;
              bool                        all = true;
              for (unsigned int i = 0; i < 3; ++i)
                {
                  const auto it =
                    body_vertex[b].find(nodes[e * data.nodes_per_tri + i]);
                  if (it == body_vertex[b].end())
                    {
                      all = false;
                      break;
                    }
                  key[i] = it->second;
                }
              if (all)
                {
                  std::sort(key.begin(), key.end());
                  set.insert(key);
                }
            }
      }

  }

  void
  AssemblyMesh::build_position_field(
    const std::map<std::pair<std::size_t, std::size_t>, Point<3>> &mid_nodes,
    const std::vector<std::size_t> &vertex_to_tag)
  {
    position_dof_handler.reinit(tria);
    position_dof_handler.distribute_dofs(position_fe);
    positions.reinit(position_dof_handler.n_dofs());

    const auto &unit_points = position_fe.base_element(0).get_unit_support_points();
    const auto  ref         = ReferenceCells::Tetrahedron;
    std::vector<std::array<int, 2>> node_of(unit_points.size());
    for (unsigned int k = 0; k < unit_points.size(); ++k)
      {
        node_of[k] = {{-1, -1}};
        for (unsigned int i = 0; i < 4; ++i)
          {
            if (unit_points[k].distance(ref.vertex<3>(i)) < 1e-12)
              node_of[k] = {{static_cast<int>(i), -1}};
            for (unsigned int j = i + 1; j < 4; ++j)
              if (unit_points[k].distance(
                    0.5 * (ref.vertex<3>(i) + Tensor<1, 3>(ref.vertex<3>(j)))) <
                  1e-12)
                node_of[k] = {{static_cast<int>(i), static_cast<int>(j)}};
          }
        AssertThrow(node_of[k][0] >= 0, ExcInternalError());
      }

    std::vector<types::global_dof_index> dofs(position_fe.n_dofs_per_cell());
    for (const auto &cell : position_dof_handler.active_cell_iterators())
      {
        cell->get_dof_indices(dofs);
        for (unsigned int i = 0; i < dofs.size(); ++i)
          {
            const auto [c, k] = position_fe.system_to_component_index(i);
            const auto [a, b] = node_of[k];
            Point<3> x;
            if (b < 0)
              x = cell->vertex(a);
            else
              {
                const std::size_t ta = vertex_to_tag[cell->vertex_index(a)];
                const std::size_t tb = vertex_to_tag[cell->vertex_index(b)];
                const auto it = mid_nodes.find({std::min(ta, tb), std::max(ta, tb)});
                x = (it != mid_nodes.end()) ?
                      it->second :
                      0.5 * (cell->vertex(a) + Tensor<1, 3>(cell->vertex(b)));
              }
            positions[dofs[i]] = x[c];
          }
      }
    mapping_ptr =
      std::make_unique<MappingFEField<3, 3, Vector<double>>>(position_dof_handler,
                                                              positions);
  }

  void
  AssemblyMesh::create_from_sections()
  {
    // the same estimate as for gmsh, before anything is built
    const double cells = section_mesh.n_cells();
    const double dofs  = cells * 3 * (order == 2 ? 8 : 1);
    const double bytes = resources::factorization_bytes(dofs, false);
    const double limit = memory_limit;
    if (bytes > 0.9 * limit)
      {
        std::ostringstream m;
        m << std::setprecision(3) << "Geometry/Sections: the mesh would have " << cells
          << " hexahedra, about " << dofs << " DOFs; their factorisation alone needs about "
          << resources::gigabytes(bytes) << " of the " << resources::gigabytes(limit)
          << " this run may use. Coarsen it (Element size, Fit element size, "
             "Circumferential cells) or use a bigger machine.";
        throw InputError(m.str());
      }
    section_mesh.create(tria, boundary_names);
    mapping_ptr = std::make_unique<MappingQ<3>>(2);
    check_jacobians();
  }

  std::unique_ptr<FiniteElement<3>>
  AssemblyMesh::scalar_element() const
  {
    if (use_sections)
      return std::make_unique<FE_Q<3>>(order);
    return std::make_unique<FE_SimplexP<3>>(order);
  }

  Quadrature<3>
  AssemblyMesh::cell_quadrature() const
  {
    if (use_sections)
      return QGauss<3>(order + 1);
    return QGaussSimplex<3>(order + 2);
  }

  Quadrature<2>
  AssemblyMesh::face_rule(const unsigned int n) const
  {
    if (use_sections)
      return QGauss<2>(n);
    return QGaussSimplex<2>(n);
  }

  Quadrature<2>
  AssemblyMesh::face_point_grid(const unsigned int n) const
  {
    if (use_sections)
      return QIterated<2>(QGauss<1>(2), n);
    // n x n sub-triangles, 3 points each
    const QGaussSimplex<2> base(2);
    std::vector<Point<2>>  points;
    std::vector<double>    weights;
    const auto add = [&](const Point<2> &a, const Point<2> &b, const Point<2> &c) {
      for (unsigned int q = 0; q < base.size(); ++q)
        {
          const Point<2> &x = base.point(q);
          points.push_back(a + x[0] * (b - a) + x[1] * (c - a));
          weights.push_back(base.weight(q) / (n * n));
        }
    };
    const double h = 1. / n;
    for (unsigned int i = 0; i < n; ++i)
      for (unsigned int j = 0; i + j < n; ++j)
        {
          const Point<2> p(i * h, j * h);
          add(p, p + Point<2>(h, 0), p + Point<2>(0, h));
          if (i + j + 1 < n)
            add(p + Point<2>(h, 0), p + Point<2>(h, h), p + Point<2>(0, h));
        }
    return Quadrature<2>(points, weights);
  }

  void
  AssemblyMesh::check_jacobians() const
  {
    const auto  fe = scalar_element();
    FEValues<3> fe_values(*mapping_ptr,
                          *fe,
                          use_sections ? Quadrature<3>(QGauss<3>(3)) : Quadrature<3>(QGaussSimplex<3>(3)),
                          update_jacobians | update_quadrature_points);
    const unsigned int n_q = fe_values.n_quadrature_points;
    const std::string source = use_sections ? std::string("Geometry/Sections") :
                                              "Geometry/Geometry file '" + geometry_filename + "'";
    std::string error;
    for (const auto &cell : tria.active_cell_iterators())
      if (cell->is_locally_owned() && error.empty())
        {
          fe_values.reinit(cell);
          for (unsigned int q = 0; q < n_q; ++q)
            if (!(determinant(Tensor<2, 3>(fe_values.jacobian(q))) > 0))
              {
                std::ostringstream s;
                s << source << ": a curved cell of body number "
                  << cell->material_id() << " near point ("
                  << fe_values.quadrature_point(q)
                  << ") is inverted (negative Jacobian); use a smaller "
                     "element size there.";
                error = s.str();
                break;
              }
        }
    // every rank must throw, or the others wait forever
    for (const auto &e : Utilities::MPI::all_gather(comm, error))
      if (!e.empty())
        throw InputError(e);
  }

  bool
  AssemblyMesh::face_on_surface(const std::string                  &name,
                                const Triangulation<3>::cell_iterator &cell,
                                const unsigned int face_no) const
  {
    if (use_sections)
      {
        const auto face = cell->face(face_no);
        return face->at_boundary() && boundary_names.count(face->boundary_id()) &&
               boundary_names.at(face->boundary_id()).count(name) > 0;
      }
    const auto it = surfaces.find(name);
    if (it == surfaces.end())
      return false;
    const auto                  face = cell->face(face_no);
    std::array<unsigned int, 3> key{{face->vertex_index(0),
                                     face->vertex_index(1),
                                     face->vertex_index(2)}};
    std::sort(key.begin(), key.end());
    return it->second.count(key) > 0;
  }

  std::vector<std::string>
  AssemblyMesh::surface_names() const
  {
    std::set<std::string> names;
    if (use_sections)
      for (const auto &[id, n] : boundary_names)
        names.insert(n.begin(), n.end());
    else
      for (const auto &[n, faces] : surfaces)
        if (!faces.empty())
          names.insert(n);
    return {names.begin(), names.end()};
  }

  void
  AssemblyMesh::check_surface_exists(const std::string &name,
                                     const std::string &entry) const
  {
    if (use_sections)
      {
        std::set<std::string> known;
        for (const auto &[id, names] : boundary_names)
          known.insert(names.begin(), names.end());
        if (known.count(name) == 0)
          {
            std::string list;
            for (const auto &s : known)
              list += (list.empty() ? "" : ", ") + s;
            throw InputError(entry + " = '" + name +
                             "' is not a surface of Geometry/Sections/Surfaces; it has: " +
                             list + ".");
          }
        return;
      }
    if (surfaces.count(name) == 0 || surfaces.at(name).empty())
      {
        std::string known;
        for (const auto &s : surfaces)
          known += (known.empty() ? "" : ", ") + s.first;
        throw InputError(entry + " = '" + name +
                         "' is not a physical surface of '" +
                         geometry_filename + "'; it has: " + known + ".");
      }
  }
} // namespace rotorfit
