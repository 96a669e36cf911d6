#include <rotorfit/base/dof_utilities.h>
#include <rotorfit/base/format.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/model/station.h>

#include <deal.II/base/quadrature_lib.h>

#include <deal.II/fe/fe_values.h>

#include <cmath>
#include <iomanip>
#include <map>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;


  void
  Station::declare_parameters(ParameterHandler &prm, const std::string &what)
  {
    prm.declare_entry("Surface",
                      "",
                      Patterns::Anything(),
                      "Physical surface of the .geo " + what +
                        " acts on (a shaft end face, or a band the geometry "
                        "marks). Or leave it empty and give Body, Axial position "
                        "and Width.");
    prm.declare_entry("Body",
                      "",
                      Patterns::Anything(),
                      "With Axial position and Width instead of Surface: the "
                      "body whose outer surface carries the band.");
    prm.declare_entry("Axial position",
                      "",
                      Patterns::Anything(),
                      "z of the band's middle [m] (with Body and Width).");
    prm.declare_entry("Width",
                      "0.005",
                      Patterns::Double(0),
                      "Axial width of the band [m] (with Body and Axial "
                      "position; > 0; the band is cut at the face quadrature "
                      "points, so a width below the surface mesh size is "
                      "resolved coarsely).");
  }

  void
  Station::parse_parameters(ParameterHandler &prm, const std::string &owner_name)
  {
    owner   = owner_name;
    surface = prm.get("Surface");
    body    = prm.get("Body");
    width   = prm.get_double("Width");
    const std::string z_text = prm.get("Axial position");
    if (!surface.empty() && (!body.empty() || !z_text.empty()))
      throw InputError(owner + ": give either Surface or Body with Axial position and "
                               "Width, not both.");
    if (surface.empty() && (body.empty() || z_text.empty()))
      throw InputError(owner + ": no station: set Surface (a physical surface of the "
                               ".geo), or Body, Axial position and Width (a band of the "
                               "body's outer surface).");
    if (!surface.empty())
      return;
    try
      {
        std::size_t used = 0;
        axial_position   = std::stod(z_text, &used);
        if (z_text.find_first_not_of(" \t", used) != std::string::npos ||
            !std::isfinite(axial_position))
          throw std::invalid_argument(z_text);
      }
    catch (const std::exception &)
      {
        throw InputError(owner + "/Axial position = '" + z_text + "' is not a number [m].");
      }
    if (!(width > 0))
      throw InputError(owner + "/Width = " + format_number(width) +
                       ": a band needs a width > 0 [m].");
  }

  std::string
  Station::describe() const
  {
    if (!is_band())
      return "surface '" + surface + "'";
    std::ostringstream s;
    s << "band z = " << format_number(axial_position) << " m, w = " << format_number(width * 1e3)
      << " mm on body '" << body << "'";
    return s.str();
  }

  namespace
  {
    /// The material id of the body a band lies on (refused if unknown).
    types::material_id
    band_body(const Station &s, const Bodies &bodies)
    {
      std::string names;
      for (unsigned int b = 0; b < bodies.size(); ++b)
        {
          if (bodies[b].name == s.body)
            return b;
          names += (names.empty() ? "" : ", ") + bodies[b].name;
        }
      throw InputError(s.owner + "/Body = '" + s.body + "' is not a body (Bodies = " + names +
                       ").");
    }

    /// Whether a face may meet the band (its vertices bound a curved face up
    /// to its sag, far below the margin of half the face's axial extent).
    bool
    near_band(const Station &s, const Triangulation<3>::face_iterator &face)
    {
      double lo = 1e300, hi = -1e300;
      for (const unsigned int v : face->vertex_indices())
        {
          lo = std::min(lo, face->vertex(v)[2]);
          hi = std::max(hi, face->vertex(v)[2]);
        }
      const double margin = 0.5 * (hi - lo);
      return hi + margin >= s.axial_position - s.width / 2 &&
             lo - margin <= s.axial_position + s.width / 2;
    }

    /// The points of a face that belong to the station: all of them on a
    /// surface; on a band those with a radial outward normal inside it.
    std::vector<unsigned int>
    points_in(const Station &s, const FEFaceValues<3> &fe_face)
    {
      std::vector<unsigned int> points;
      for (unsigned int q = 0; q < fe_face.n_quadrature_points; ++q)
        {
          const Point<3> &x = fe_face.quadrature_point(q);
          if (s.is_band())
            {
              const double r = std::hypot(x[0], x[1]);
              const auto  &n = fe_face.normal_vector(q);
              if (r == 0 || (n[0] * x[0] + n[1] * x[1]) / r <= 0.5 ||
                  std::abs(x[2] - s.axial_position) > s.width / 2)
                continue;
            }
          points.push_back(q);
        }
      return points;
    }

    /// Integrals over the station as its faces are visited.
    struct Integrals
    {
      // weight of every scalar node, keyed by its x DoF: (y DoF, int N_i dA)
      std::map<types::global_dof_index, std::pair<types::global_dof_index, double>> w;
      double area = 0, z_area = 0, r_area = 0, z_min = 1e300, z_max = -1e300;

      void
      add(const FEFaceValues<3>                     &fe_face,
          const std::vector<unsigned int>          &points,
          const std::vector<unsigned int>          &on_face,
          const std::vector<types::global_dof_index> &dofs)
      {
        const auto &fe = fe_face.get_fe();
        for (const unsigned int q : points)
          {
            const Point<3> &x = fe_face.quadrature_point(q);
            area += fe_face.JxW(q);
            z_area += x[2] * fe_face.JxW(q);
            r_area += std::hypot(x[0], x[1]) * fe_face.JxW(q);
            z_min = std::min(z_min, x[2]);
            z_max = std::max(z_max, x[2]);
            for (const unsigned int i : on_face)
              if (fe.system_to_component_index(i).first == 0)
                {
                  // the y DoF of the same node: same scalar index
                  const unsigned int iy =
                    fe.component_to_system_index(1, fe.system_to_component_index(i).second);
                  auto &e = w[dofs[i]];
                  e.first = dofs[iy];
                  e.second += fe_face.shape_value(i, q) * fe_face.JxW(q);
                }
          }
      }
    };
  } // namespace

  void
  Station::setup(const Discretization &model, Log &log)
  {
    const auto &mesh = model.mesh();
    const auto &fe   = model.dofs().get_fe();
    const types::material_id body_id =
      is_band() ? band_body(*this, model.bodies()) : numbers::invalid_material_id;
    if (!is_band())
      mesh.check_surface_exists(surface, owner + "/Surface");
    std::vector<std::string> fit_surfaces;
    for (const auto &f : model.interfaces().list())
      fit_surfaces.insert(fit_surfaces.end(), {f.shaft_surface, f.hub_surface});

    // a band is cut at quadrature points: a rich rule keeps its edges sharp
    const Quadrature<2> face_quadrature =
      is_band() ? mesh.face_point_grid(8) : mesh.face_rule(fe.degree + 2);
    FEFaceValues<3> fe_face(mesh.mapping(),
                            fe,
                            face_quadrature,
                            update_values | update_JxW_values | update_quadrature_points |
                              update_normal_vectors);
    std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
    Integrals                            sum;
    std::string                          on_fit;
    for (const auto &cell : model.dofs().active_cell_iterators())
      for (const unsigned int f : cell->face_indices())
        {
          if (!cell->face(f)->at_boundary() ||
              (is_band() ? cell->material_id() != body_id || !near_band(*this, cell->face(f)) :
                           !mesh.face_on_surface(surface, cell, f)))
            continue;
          fe_face.reinit(cell, f);
          const auto points = points_in(*this, fe_face);
          if (points.empty())
            continue;
          if (is_band())
            for (const auto &s : fit_surfaces)
              if (mesh.face_on_surface(s, cell, f))
                on_fit = s;
          cell->get_dof_indices(dofs);
          sum.add(fe_face, points, cell_dofs_on_face(cell, f), dofs);
        }
    if (!on_fit.empty())
      throw InputError(owner + ": the " + describe() + " overlaps the fit surface '" + on_fit +
                       "'; a station acts on a free surface of the shaft (move the band "
                       "or narrow it).");
    if (!(sum.area > 0))
      throw InputError(owner + ": the " + describe() +
                       (is_band() ? " meets no outer surface of the body (is the axial "
                                    "position inside the body's length and outside its fits?)" :
                                    " has no boundary faces in the mesh") +
                       ".");
    area   = sum.area;
    z      = sum.z_area / area;
    radius = sum.r_area / area;
    dof_x.clear();
    dof_y.clear();
    weight.clear();
    for (const auto &[dx, e] : sum.w)
      if (e.second != 0)
        {
          dof_x.push_back(dx);
          dof_y.push_back(e.first);
          weight.push_back(e.second / area);
        }
    if (is_band())
      log_band(log, sum.z_min, sum.z_max);
  }

  void
  Station::log_band(Log &log, const double z_min, const double z_max) const
  {
    const double       nominal = 2 * M_PI * radius * width;
    std::ostringstream m;
    m << std::setprecision(4) << "  " << owner << ": " << describe() << ": r " << radius * 1e3
      << " mm, found z " << z_min * 1e3 << " .. " << z_max * 1e3 << " mm, area " << area * 1e6
      << " mm^2 = " << std::setprecision(3) << area / nominal << " x 2 pi r w, "
      << weight.size() << " nodes\n";
    log << m.str();
    if (area < 0.75 * nominal || area > 1.33 * nominal)
      log << "Warning: " << owner << ": the band's area is " << std::setprecision(3)
          << area / nominal
          << " x 2 pi r w: the surface mesh resolves this width coarsely, or the band "
             "covers an edge or a step; mark the band as a physical surface in the "
             ".geo for an exact one.\n";
  }
} // namespace rotorfit
