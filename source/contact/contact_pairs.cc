#include <rotorfit/base/dof_utilities.h>
#include <rotorfit/base/format.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/base/patterns.h>
#include <rotorfit/contact/contact_pairs.h>
#include <rotorfit/mesh/assembly_mesh.h>

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/utilities.h>

#include <deal.II/fe/fe_values.h>

#include <deal.II/lac/dynamic_sparsity_pattern.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <iomanip>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

  void
  ContactInterfaces::declare_list(ParameterHandler &prm)
  {
    prm.declare_entry("Interfaces",
                      "",
                      Patterns::List(Patterns::Anything(), 0),
                      "Names of the shrink-fit interfaces. Each needs a "
                      "subsection 'Interface <name>'.");
  }

  void
  ContactInterfaces::declare_parameters(ParameterHandler               &prm,
                                        const std::vector<std::string> &names)
  {
    for (const auto &name : names)
      {
        prm.enter_subsection("Interface " + name);
        prm.declare_entry("Shaft surface",
                          "",
                          Patterns::Anything(),
                          "Physical surface on the shaft (inner) side of the "
                          "fit. Mandatory.");
        prm.declare_entry("Hub surface",
                          "",
                          Patterns::Anything(),
                          "Physical surface on the hub (outer) side; may be the "
                          "same surface as the shaft side when the geometry is "
                          "fragmented. Mandatory.");
        FitSpecification::declare_parameters(prm);
        prm.leave_subsection();
      }
  }

  void
  ContactInterfaces::declare_fit_design(ParameterHandler &prm)
  {
    prm.enter_subsection("Fit design");
    prm.declare_entry("Reference temperature",
                      "20",
                      Patterns::Double(-273.15),
                      "Temperature at which the interferences, the tolerances "
                      "and the mesh are given [deg C] (ISO 1: 20). A body at "
                      "another Temperature expands freely by its Thermal "
                      "expansion coefficient times the difference.");
    prm.declare_entry("Interference cases",
                      "smallest, largest",
                      Patterns::List(Patterns::Selection("smallest|largest"), 1, 2),
                      "Which ends of a toleranced fit's band (ISO fit, Limit "
                      "deviations) are run, one case each: the smallest "
                      "interference governs slip and the loss of fit, the "
                      "largest the stresses. Fits given by a Radial "
                      "interference are the same in every case.");
    prm.leave_subsection();
  }

  void
  ContactInterfaces::parse_parameters(ParameterHandler &prm)
  {
    interfaces.clear();
    for (const auto &name :
         Utilities::split_string_list(prm.get("Interfaces"), ','))
      {
        prm.enter_subsection("Interface " + name);
        InterfaceDefinition d;
        d.name          = name;
        d.shaft_surface = prm.get("Shaft surface");
        d.hub_surface   = prm.get("Hub surface");
        for (const std::string entry : {"Shaft surface", "Hub surface"})
          if (prm.get(entry).empty())
            throw InputError("Interface " + name + "/" + entry +
                             " is not set; every interface needs Shaft "
                             "surface, Hub surface and its interference.");
        d.fit.parse_parameters(prm, "Interface " + name);
        prm.leave_subsection();
        interfaces.push_back(d);
      }
    prm.enter_subsection("Fit design");
    reference_celsius = prm.get_double("Reference temperature");
    cases.clear();
    for (const auto &c : Utilities::split_string_list(prm.get("Interference cases"), ','))
      {
        const auto k = c == "smallest" ? FitSpecification::Case::smallest :
                                         FitSpecification::Case::largest;
        if (std::find(cases.begin(), cases.end(), k) == cases.end())
          cases.push_back(k);
      }
    prm.leave_subsection();
    if (cases.empty())
      throw InputError("Fit design/Interference cases is empty; give smallest, largest or both.");
    band_case = cases.front();
  }

  bool
  ContactInterfaces::any_toleranced() const
  {
    return std::any_of(interfaces.begin(), interfaces.end(), [](const InterfaceDefinition &d) {
      return d.fit.toleranced();
    });
  }

  namespace
  {
    struct SidePoint
    {
      Point<3>                               x;
      std::array<types::global_dof_index, 3> dofs;
      unsigned int                           body; ///< material id of its cell
    };

    double
    radius(const Point<3> &p)
    {
      return std::hypot(p[0], p[1]);
    }
  } // namespace

  struct ContactPairs::InterfaceSides
  {
    /// support points of each side (0 shaft, 1 hub), keyed by their x DoF
    std::map<types::global_dof_index, SidePoint> side[2];
    /// shaft-side faces: their x DoFs, cell and face number
    std::vector<std::vector<types::global_dof_index>>         shaft_faces;
    std::vector<typename DoFHandler<3>::active_cell_iterator> face_cells;
    std::vector<unsigned int>                                 face_numbers;
  };

  namespace
  {
    /// The faces of both sides of an interface; a face belongs to the shaft
    /// side if its cell lies inside it (smaller radius).
    template <typename Sides>
    void
    collect_sides(const AssemblyMesh          &mesh,
                  const DoFHandler<3>         &dof_handler,
                  const std::vector<Point<3>> &support_points,
                  const InterfaceDefinition   &def,
                  Sides                       &sides)
    {
      const auto &fe = dof_handler.get_fe();
      std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
      for (const auto &cell : dof_handler.active_cell_iterators())
        for (const unsigned int face_no : cell->face_indices())
          if (cell->face(face_no)->at_boundary())
            for (unsigned int s = 0; s < 2; ++s)
              {
                const std::string &surface = (s == 0 ? def.shaft_surface : def.hub_surface);
                if (!mesh.face_on_surface(surface, cell, face_no))
                  continue;
                const double r_face = radius(cell->face(face_no)->center());
                const double r_cell = radius(cell->center());
                if ((s == 0) != (r_cell < r_face))
                  continue;
                cell->get_dof_indices(dofs);
                std::vector<types::global_dof_index> face_x_dofs;
                for (const unsigned int i : cell_dofs_on_face(cell, face_no))
                  {
                    const auto [c, k] = fe.system_to_component_index(i);
                    if (c != 0)
                      continue;
                    sides.side[s][dofs[i]] =
                      SidePoint{support_points[dofs[i]],
                                {{dofs[i],
                                  dofs[fe.component_to_system_index(1, k)],
                                  dofs[fe.component_to_system_index(2, k)]}},
                                cell->material_id()};
                    face_x_dofs.push_back(dofs[i]);
                  }
                if (s == 0)
                  {
                    sides.shaft_faces.push_back(face_x_dofs);
                    sides.face_cells.push_back(cell);
                    sides.face_numbers.push_back(face_no);
                  }
              }
      for (unsigned int s = 0; s < 2; ++s)
        if (sides.side[s].empty())
          throw InputError("Interface " + def.name + ": the physical surface '" +
                           (s == 0 ? def.shaft_surface : def.hub_surface) +
                           "' has no faces on the " + (s == 0 ? "shaft" : "hub") + " side (" +
                           (s == 0 ? "body inside the surface" : "body outside the surface") +
                           "); the bodies do not touch there. Check the surface names.");
    }
  } // namespace

  void
  ContactPairs::build(const AssemblyMesh                     &mesh,
                      const DoFHandler<3>                    &dof_handler,
                      const std::vector<Point<3>>            &support_points,
                      const ContactInterfaces                &interface_list,
                      const std::vector<double>              &free_thermal_strain)
  {
    const auto &interfaces = interface_list.list();
    pair_list.clear();
    surfaces.clear();
    surfaces.resize(interfaces.size());
    for (unsigned int f = 0; f < interfaces.size(); ++f)
      {
        const auto &def = interfaces[f];
        mesh.check_surface_exists(def.shaft_surface, "Interface " + def.name + "/Shaft surface");
        mesh.check_surface_exists(def.hub_surface, "Interface " + def.name + "/Hub surface");
        InterfaceSides sides;
        collect_sides(mesh, dof_handler, support_points, def, sides);
        const auto pair_of = match_sides(f, def, sides, mesh.matching_tolerance(), mesh.coincidence_hint());
        std::map<types::global_dof_index, unsigned int> body_of_hub_dof;
        for (const auto &[dof, p] : sides.side[1])
          body_of_hub_dof[p.dofs[0]] = p.body;
        std::vector<unsigned int> shaft_body, hub_body;
        for (const auto i : surfaces[f].pairs)
          {
            shaft_body.push_back(sides.side[0].at(pair_list[i].shaft_dofs[0]).body);
            hub_body.push_back(body_of_hub_dof.at(pair_list[i].hub_dofs[0]));
          }
        set_interference(f, def, interface_list.interference_case(), shaft_body, hub_body,
                         free_thermal_strain);
        assemble_surface(f, sides, pair_of, mesh, dof_handler.get_fe());
      }
  }

  void
  ContactPairs::build_rings(const ContactInterfaces    &interface_list,
                            std::vector<RingInterface> &&rings,
                            const std::vector<double>   &free_thermal_strain)
  {
    const auto &interfaces = interface_list.list();
    pair_list.clear();
    surfaces.clear();
    surfaces.resize(interfaces.size());
    for (unsigned int f = 0; f < interfaces.size(); ++f)
      {
        RingInterface &ring    = rings[f];
        Surface       &surface = surfaces[f];
        const unsigned int n   = ring.pairs.size();
        for (auto &pair : ring.pairs)
          {
            pair.interface = f;
            surface.pairs.push_back(pair_list.size());
            pair_list.push_back(pair);
          }
        set_interference(f, interfaces[f], interface_list.interference_case(), ring.shaft_body,
                         ring.hub_body, free_thermal_strain);
        DynamicSparsityPattern dsp(n, n);
        for (const auto &face : ring.faces)
          for (const auto i : face)
            for (const auto j : face)
              dsp.add(i, j);
        surface.pattern.copy_from(dsp);
        surface.mass.reinit(surface.pattern);
        for (unsigned int k = 0; k < ring.faces.size(); ++k)
          {
            const auto &face = ring.faces[k];
            for (unsigned int i = 0; i < face.size(); ++i)
              for (unsigned int j = 0; j < face.size(); ++j)
                surface.mass.add(face[i], face[j], ring.face_mass[k](i, j));
            surface.area += ring.face_area[k];
          }
        surface.faces     = std::move(ring.faces);
        surface.face_area = std::move(ring.face_area);
        surface.inverse   = std::make_shared<SparseDirectUMFPACK>();
        surface.inverse->initialize(surface.mass);
      }
  }

  std::map<types::global_dof_index, unsigned int>
  ContactPairs::match_sides(const unsigned int         f,
                            const InterfaceDefinition &def,
                            const InterfaceSides      &sides,
                            const double               tolerance,
                            const std::string         &hint)
  {
    // pair by coordinates: sort the hub side by x and search a window
    std::vector<SidePoint> hub;
    for (const auto &[dof, p] : sides.side[1])
      hub.push_back(p);
    std::sort(hub.begin(), hub.end(), [](const SidePoint &a, const SidePoint &b) {
      return a.x[0] < b.x[0];
    });
    std::vector<bool>                               hub_used(hub.size(), false);
    std::map<types::global_dof_index, unsigned int> pair_of_shaft_dof;
    unsigned int                                    n_unmatched = 0;
    Point<3>                                        first_unmatched;
    for (const auto &[dof, p] : sides.side[0])
      {
        const double tol = tolerance * std::max(radius(p.x), 1e-12);
        auto lo = std::lower_bound(hub.begin(), hub.end(), p.x[0] - tol,
                                   [](const SidePoint &a, const double v) { return a.x[0] < v; });
        int match = -1;
        for (auto it = lo; it != hub.end() && it->x[0] <= p.x[0] + tol; ++it)
          if (it->x.distance(p.x) <= tol)
            {
              match = it - hub.begin();
              break;
            }
        if (match < 0)
          {
            if (n_unmatched++ == 0)
              first_unmatched = p.x;
            continue;
          }
        hub_used[match] = true;
        ContactPair pair;
        pair.interface         = f;
        pair.shaft_dofs        = p.dofs;
        pair.hub_dofs          = hub[match].dofs;
        pair.position          = p.x;
        const double r         = radius(p.x);
        pair.normal            = Tensor<1, 3>({p.x[0] / r, p.x[1] / r, 0.});
        pair.interference      = 0; // set_interference()
        pair_of_shaft_dof[dof] = surfaces[f].pairs.size();
        surfaces[f].pairs.push_back(pair_list.size());
        pair_list.push_back(pair);
      }
    for (unsigned int i = 0; i < hub.size(); ++i)
      if (!hub_used[i] && n_unmatched++ == 0)
        first_unmatched = hub[i].x;
    if (n_unmatched > 0)
      {
        std::ostringstream s;
        s << "Interface " << def.name << ": " << n_unmatched << " of "
          << sides.side[0].size() + sides.side[1].size() << " support points on '"
          << def.shaft_surface << "'/'" << def.hub_surface
          << "' have no coincident partner on the other body (first at (" << first_unmatched
          << ") m). Both bodies must carry coincident nodes on the fit: "
          << hint;
        throw InputError(s.str());
      }
    return pair_of_shaft_dof;
  }

  void
  ContactPairs::set_interference(const unsigned int               f,
                                 const InterfaceDefinition       &def,
                                 const FitSpecification::Case     c,
                                 const std::vector<unsigned int> &shaft_body,
                                 const std::vector<unsigned int> &hub_body,
                                 const std::vector<double>       &free_thermal_strain)
  {
    FitGeometry &g = surfaces[f].geometry;
    g.r_min = g.z_min = std::numeric_limits<double>::max();
    g.r_max = g.z_max = std::numeric_limits<double>::lowest();
    double r_sum      = 0;
    for (const auto i : surfaces[f].pairs)
      {
        const Point<3> &x = pair_list[i].position;
        r_sum += radius(x);
        g.r_min = std::min(g.r_min, radius(x));
        g.r_max = std::max(g.r_max, radius(x));
        g.z_min = std::min(g.z_min, x[2]);
        g.z_max = std::max(g.z_max, x[2]);
      }
    const double r_mean = r_sum / surfaces[f].pairs.size();
    // the tables step at whole micrometres: a diameter of 30 mm meshed as
    // 30.000000001 mm is 30 mm
    g.diameter = std::round(2 * r_mean * 1e6) / 1e6;
    if (def.fit.toleranced() && g.r_max - g.r_min > 1e-3 * r_mean)
      {
        std::ostringstream m;
        m << "Interface " << def.name << ": an " << def.fit.describe()
          << " needs a cylindrical fit, but its radius ranges from " << g.r_min * 1e3 << " to "
          << g.r_max * 1e3 << " mm; give Radial interference instead.";
        throw InputError(m.str());
      }
    g.radial_interference = def.fit.effective_radial_interference(g.diameter, c);
    // the body holding most of each side's pairs (ties: the lower id)
    for (unsigned int s = 0; s < 2; ++s)
      {
        std::map<unsigned int, unsigned int> count;
        for (const auto b : (s == 0 ? shaft_body : hub_body))
          ++count[b];
        const unsigned int body =
          std::max_element(count.begin(), count.end(), [](const auto &a, const auto &b) {
            return a.second < b.second;
          })->first;
        (s == 0 ? g.shaft_body : g.hub_body) = body;
      }
    const auto strain     = [&](const unsigned int body) {
      return body < free_thermal_strain.size() ? free_thermal_strain[body] : 0.;
    };
    // a body at uniform temperature between statically determinate
    // supports expands freely and without stress, u_r = eps r: the hub's
    // bore moves out by eps_hub r, the shaft's surface by eps_shaft r
    g.thermal_shift = -r_mean * (strain(g.hub_body) - strain(g.shaft_body));
    double smallest = std::numeric_limits<double>::max();
    for (unsigned int k = 0; k < surfaces[f].pairs.size(); ++k)
      {
        ContactPair &pair = pair_list[surfaces[f].pairs[k]];
        pair.interference = g.radial_interference -
                            radius(pair.position) * (strain(hub_body[k]) - strain(shaft_body[k]));
        smallest          = std::min(smallest, pair.interference);
      }
    if (!(smallest > 0))
      {
        std::ostringstream m;
        m << std::setprecision(4) << "Interface " << def.name
          << ": at the bodies' temperatures the fit is loose at rest (radial interference "
          << g.radial_interference * 1e6 << " um at the reference temperature, "
          << g.thermal_shift * 1e6 << " um by the temperatures, " << smallest * 1e6
          << " um left at the least pair); nothing holds the hub. Check the bodies' Temperature "
             "and Thermal expansion coefficient.";
        throw FitLooseAtRest(m.str());
      }
  }

  void
  ContactPairs::assemble_surface(const unsigned int                                     f,
                                 const InterfaceSides                                  &sides,
                                 const std::map<types::global_dof_index, unsigned int> &pair_of,
                                 const AssemblyMesh                                    &mesh,
                                 const FiniteElement<3>                                &fe)
  {
    // consistent surface mass matrix on the shaft side, pair numbering
    Surface               &surface = surfaces[f];
    const unsigned int     n       = surface.pairs.size();
    DynamicSparsityPattern dsp(n, n);
    for (const auto &face : sides.shaft_faces)
      for (const auto i : face)
        for (const auto j : face)
          dsp.add(pair_of.at(i), pair_of.at(j));
    surface.pattern.copy_from(dsp);
    surface.mass.reinit(surface.pattern);

    const Quadrature<2>                  face_quadrature = mesh.face_rule(3);
    FEFaceValues<3>                      fe_face(mesh.mapping(), fe, face_quadrature,
                            update_values | update_JxW_values);
    std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
    for (unsigned int k = 0; k < sides.shaft_faces.size(); ++k)
      {
        const auto &cell = sides.face_cells[k];
        fe_face.reinit(cell, sides.face_numbers[k]);
        cell->get_dof_indices(dofs);
        std::vector<std::pair<unsigned int, unsigned int>> local; // (cell dof, pair)
        for (const unsigned int i : cell_dofs_on_face(cell, sides.face_numbers[k]))
          if (fe.system_to_component_index(i).first == 0)
            local.emplace_back(i, pair_of.at(dofs[i]));
        double a = 0;
        for (unsigned int q = 0; q < face_quadrature.size(); ++q)
          {
            a += fe_face.JxW(q);
            for (const auto &[i, pi] : local)
              for (const auto &[j, pj] : local)
                surface.mass.add(pi, pj,
                                 fe_face.shape_value(i, q) * fe_face.shape_value(j, q) *
                                   fe_face.JxW(q));
          }
        std::vector<unsigned int> face_pairs;
        for (const auto &l : local)
          face_pairs.push_back(l.second);
        surface.faces.push_back(face_pairs);
        surface.face_area.push_back(a);
        surface.area += a;
      }
    surface.inverse = std::make_shared<SparseDirectUMFPACK>();
    surface.inverse->initialize(surface.mass);
  }

  double
  ContactPairs::closed_area(const unsigned int       i,
                            const std::vector<bool> &closed) const
  {
    const Surface &s = surfaces[i];
    double         a = 0;
    for (unsigned int k = 0; k < s.faces.size(); ++k)
      {
        unsigned int n = 0;
        for (const auto p : s.faces[k])
          n += closed[s.pairs[p]];
        a += s.face_area[k] * n / s.faces[k].size();
      }
    return a;
  }

  double
  ContactPairs::asymmetry(const unsigned int i, const std::vector<bool> &closed) const
  {
    constexpr unsigned int rings = 4, sectors = 8;
    const Surface         &s = surfaces[i];
    double z_min = std::numeric_limits<double>::max(), z_max = -z_min;
    for (const auto p : s.pairs)
      {
        z_min = std::min(z_min, pair_list[p].position[2]);
        z_max = std::max(z_max, pair_list[p].position[2]);
      }
    std::vector<double> area(rings * sectors, 0.), shut(rings * sectors, 0.);
    for (unsigned int k = 0; k < s.faces.size(); ++k)
      {
        Point<3>     c;
        unsigned int n = 0;
        for (const auto p : s.faces[k])
          {
            c += pair_list[s.pairs[p]].position;
            n += closed[s.pairs[p]];
          }
        c /= s.faces[k].size();
        const double       phi = std::atan2(c[1], c[0]) + numbers::PI; // [0, 2 pi]
        const unsigned int a   = std::min<unsigned int>(sectors - 1, phi / (2 * numbers::PI) * sectors);
        const unsigned int r   = z_max > z_min ?
                                   std::min<unsigned int>(rings - 1, (c[2] - z_min) / (z_max - z_min) * rings) :
                                   0;
        area[r * sectors + a] += s.face_area[k];
        shut[r * sectors + a] += s.face_area[k] * n / s.faces[k].size();
      }
    double worst = 0;
    for (unsigned int r = 0; r < rings; ++r)
      {
        double lo = 1, hi = 0;
        for (unsigned int a = 0; a < sectors; ++a)
          if (area[r * sectors + a] > 0)
            {
              const double f = shut[r * sectors + a] / area[r * sectors + a];
              lo             = std::min(lo, f);
              hi             = std::max(hi, f);
            }
        // a ring equally closed in every sector is 0 exactly, not round-off
        if (hi > 0 && hi - lo > 1e-12 * hi)
          worst = std::max(worst, 1 - lo / hi);
      }
    return worst;
  }

  std::vector<double>
  ContactPairs::pressure(const std::vector<double> &force) const
  {
    std::vector<double> p(force.size(), 0.);
    for (const auto &s : surfaces)
      {
        Vector<double> rhs(s.pairs.size()), sol(s.pairs.size());
        for (unsigned int k = 0; k < s.pairs.size(); ++k)
          rhs[k] = force[s.pairs[k]];
        s.inverse->vmult(sol, rhs);
        for (unsigned int k = 0; k < s.pairs.size(); ++k)
          p[s.pairs[k]] = sol[k];
      }
    return p;
  }

  std::string
  describe_interference(const ContactInterfaces &interfaces, const ContactPairs &pairs,
                        const unsigned int i)
  {
    const auto &fit = interfaces.list()[i].fit;
    const auto &g   = pairs.geometry(i);
    return (fit.toleranced() ?
              fit.describe() + " at " + format_number(g.diameter * 1e3) + " mm (" +
                (interfaces.interference_case() == FitSpecification::Case::smallest ? "smallest" :
                                                                                       "largest") +
                " interference, smoothed), " :
              std::string()) +
           "radial interference " + [&] {
             std::ostringstream o; // the stream's default 6 digits, as the log's
             o << g.radial_interference * 1e6;
             return o.str();
           }() + " um" +
           (g.thermal_shift != 0 ? ", " + format_number(g.thermal_shift * 1e6) + " um by the temperatures" :
                                   std::string());
  }
} // namespace rotorfit
