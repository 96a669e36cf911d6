#include <rotorfit/base/input_error.h>
#include <rotorfit/base/patterns.h>
#include <rotorfit/mesh/section_hexahedra.h>
#include <rotorfit/mesh/section_quadrilaterals.h>
#include <rotorfit/mesh/section_mesh.h>

#include <deal.II/base/utilities.h>

#include <deal.II/grid/manifold.h>
#include <deal.II/grid/tria_description.h>

#include <algorithm>
#include <array>
#include <optional>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    std::string
    side_name(const SectionMesh::Side s)
    {
      switch (s)
        {
          case SectionMesh::Side::outer:
            return "outer";
          case SectionMesh::Side::inner:
            return "inner";
          case SectionMesh::Side::start:
            return "start";
          default:
            return "end";
        }
    }
  } // namespace

  void
  SectionMesh::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Sections");
    prm.declare_entry("Circumferential cells",
                      "24",
                      Patterns::Integer(8, 512),
                      "Cells around the circumference, a multiple of 4 (the O-grid "
                      "core of a solid section has N/4 cells a side). The ring part "
                      "of the mesh maps onto itself under a rotation of 2 pi / N.");
    prm.declare_entry("Element size",
                      "8e-3",
                      patterns::Positive(),
                      "Axial and radial element size away from the fits [m].");
    prm.declare_entry("Fit element size",
                      "4e-3",
                      patterns::Positive(),
                      "Axial and radial element size at the fits [m]; sizes grow "
                      "from it by half the distance to the fit, up to Element size.");
    prm.declare_entry("Fit edge element size",
                      "0",
                      Patterns::Double(0),
                      "Element size at the fits' edges [m], where the bonded joint's "
                      "corner makes the stress singular; sizes grow from it by half "
                      "the distance to the edge (axially; radially by half the "
                      "distance to the fit, the layout being a tensor product); the "
                      "cells are whole numbers of that size function, so the first "
                      "one is up to about 1.3 x it. At least 1/1000 of Element size; "
                      "0 or at least Fit element size: no grading of its own.");
    prm.declare_entry("Surfaces",
                      "",
                      Patterns::Anything(),
                      "Named surfaces for interfaces, bearings, probes and rollers: "
                      "'name: selector + selector, name: ...'. A selector is "
                      "'<body> outer|inner [z from] [z to]' (the radial boundary, "
                      "optionally between two axial positions [m]) or "
                      "'<body> start|end' (the end face at the body's lowest or "
                      "highest z). Example: 'fit: shaft outer 0.11 0.15 + sleeve "
                      "inner, bearing_left: shaft start'.");
    prm.leave_subsection();
  }

  void
  SectionMesh::declare_body_parameters(ParameterHandler               &prm,
                                       const std::vector<std::string> &bodies)
  {
    for (const auto &name : bodies)
      {
        prm.enter_subsection("Body " + name);
        prm.declare_entry("Sections",
                          "",
                          Patterns::Anything(),
                          "With Geometry/Mesher = sections: the body as axial "
                          "sections 'z from, z to, inner radius, outer radius at z "
                          "from, inner radius, outer radius at z to; ...' [m], "
                          "following each other in z. Inner radius 0 at both ends: "
                          "a solid section. Cylinders, annuli and cones.");
        prm.leave_subsection();
      }
  }

  void
  SectionMesh::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Sections");
    n_theta = prm.get_integer("Circumferential cells");
    if (n_theta % 4 != 0)
      throw InputError("Geometry/Sections/Circumferential cells = " +
                       std::to_string(n_theta) +
                       " must be a multiple of 4 (the O-grid core of a solid "
                       "section has N/4 cells a side).");
    h_max         = prm.get_double("Element size");
    h_fit         = std::min(h_max, prm.get_double("Fit element size"));
    h_edge        = prm.get_double("Fit edge element size");
    if (h_edge > 0 && h_edge < 1e-3 * h_max)
      {
        std::ostringstream m;
        m << "Geometry/Sections/Fit edge element size = " << h_edge
          << " m is below a thousandth of Element size (" << h_max
          << " m): the plan's layers would reach aspect ratios above 1,000 and its size "
             "integration cannot place such cells; set at least "
          << 1e-3 * h_max << " m, or 0 for no grading at the fits' edges.";
        throw InputError(m.str());
      }
    h_edge        = h_edge > 0 ? std::min(h_fit, h_edge) : h_fit;
    surfaces_text = prm.get("Surfaces");
    prm.leave_subsection();
  }

  void
  SectionMesh::parse_body_parameters(ParameterHandler               &prm,
                                     const std::vector<std::string> &bodies)
  {
    body_names = bodies;
    sections.assign(bodies.size(), {});
    for (unsigned int b = 0; b < bodies.size(); ++b)
      {
        prm.enter_subsection("Body " + bodies[b]);
        const std::string text = prm.get("Sections");
        prm.leave_subsection();
        read_sections(b, text);
        check_sections(b);
      }
    set_core_radii();
    parse_surfaces();
  }

  void
  SectionMesh::read_sections(const unsigned int b, const std::string &text)
  {
    const std::string entry = "Body " + body_names[b] + "/Sections";
    if (Utilities::trim(text).empty())
      throw InputError(entry + " is not set; with Geometry/Mesher = sections every "
                               "body is given as axial sections.");
    unsigned int k = 0;
    for (const auto &item : Utilities::split_string_list(text, ';'))
      {
        ++k;
        std::vector<double> v;
        try
          {
            for (const auto &word : Utilities::split_string_list(item, ','))
              v.push_back(Utilities::string_to_double(word));
          }
        catch (...)
          {
            v.clear();
          }
        if (v.size() != 6 ||
            !std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); }))
          throw InputError(entry + ": section " + std::to_string(k) + " '" + item +
                           "' needs six numbers: z from, z to, inner and outer "
                           "radius at z from, inner and outer radius at z to [m].");
        sections[b].push_back({v[0], v[1], v[2], v[3], v[4], v[5]});
      }
  }

  void
  SectionMesh::set_core_radii()
  {
    // the core radius of each body: inside every solid section and inside
    // every bore of the body (a bore's radii must be nodes of the core's rings)
    core_radius.assign(sections.size(), 0.);
    for (unsigned int b = 0; b < sections.size(); ++b)
      {
        double rc    = std::numeric_limits<double>::max();
        bool   solid = false;
        for (const auto &s : sections[b])
          if (s.solid())
            {
              solid = true;
              rc    = std::min(rc, 0.5 * std::min(s.ro0, s.ro1));
            }
        for (const auto &s : sections[b])
          if (!s.solid())
            rc = std::min(rc, 0.8 * std::min(s.ri0, s.ri1));
        core_radius[b] = solid ? rc : 0.;
      }
  }

  void
  SectionMesh::parse_surfaces()
  {
    surfaces.clear();
    const std::string entry = "Geometry/Sections/Surfaces";
    for (const auto &item : Utilities::split_string_list(surfaces_text, ','))
      {
        const auto colon = item.find(':');
        if (colon == std::string::npos)
          throw InputError(entry + ": '" + item + "' is not 'name: selector + ...'.");
        const std::string name = Utilities::trim(item.substr(0, colon));
        if (name.empty() || surfaces.count(name))
          throw InputError(entry + ": the surface name '" + name +
                           "' is empty or given twice.");
        for (const auto &sel : Utilities::split_string_list(item.substr(colon + 1), '+'))
          surfaces[name].push_back(parse_selector(sel, name));
      }
  }

  SectionMesh::Selector
  SectionMesh::parse_selector(const std::string &sel, const std::string &name) const
  {
    const std::string entry = "Geometry/Sections/Surfaces";
    std::vector<std::string> w;
    for (const auto &x : Utilities::split_string_list(sel, ' '))
      if (!x.empty())
        w.push_back(x);
    const auto body = std::find(body_names.begin(), body_names.end(), w.empty() ? "" : w[0]);
    const std::string usage =
      "; a selector is '<body> outer|inner [z from z to]' or '<body> start|end'.";
    if (w.size() < 2 || body == body_names.end())
      throw InputError(entry + ": '" + sel + "' of surface '" + name +
                       "' does not start with a body of Bodies" + usage);
    Selector s{static_cast<unsigned int>(body - body_names.begin()),
               Side::outer,
               -std::numeric_limits<double>::max(),
               std::numeric_limits<double>::max()};
    if (w[1] == "outer" || w[1] == "inner")
      s.side = (w[1] == "outer" ? Side::outer : Side::inner);
    else if (w[1] == "start" || w[1] == "end")
      s.side = (w[1] == "start" ? Side::start : Side::end);
    else
      throw InputError(entry + ": '" + sel + "' of surface '" + name + "': '" + w[1] +
                       "' is no side" + usage);
    const bool radial = (s.side == Side::outer || s.side == Side::inner);
    if (w.size() == 4 && radial)
      try
        {
          s.z_from = Utilities::string_to_double(w[2]);
          s.z_to   = Utilities::string_to_double(w[3]);
        }
      catch (...)
        {
          throw InputError(entry + ": '" + sel + "': the axial range is not two numbers" + usage);
        }
    else if (w.size() != 2)
      throw InputError(entry + ": '" + sel + "' of surface '" + name +
                       "' has the wrong number of words" + usage);
    if (!(s.z_to > s.z_from))
      throw InputError(entry + ": '" + sel + "': z to must exceed z from.");
    return s;
  }

  void
  SectionMesh::check_sections(const unsigned int b) const
  {
    const std::string entry = "Body " + body_names[b] + "/Sections";
    const auto       &list  = sections[b];
    for (unsigned int k = 0; k < list.size(); ++k)
      {
        const auto        &s = list[k];
        std::ostringstream where;
        where << entry << ": section " << k + 1 << " (z " << s.z0 << " .. " << s.z1 << ")";
        if (!(s.z1 > s.z0))
          throw InputError(where.str() + ": z to must exceed z from.");
        if (!(s.ri0 >= 0 && s.ri1 >= 0 && s.ro0 > s.ri0 && s.ro1 > s.ri1))
          throw InputError(where.str() + ": the radii need 0 <= inner < outer at both ends.");
        if ((s.ri0 == 0) != (s.ri1 == 0))
          throw InputError(where.str() +
                           ": the inner radius is 0 at one end only; a bore that closes "
                           "onto the axis cannot be meshed without degenerate cells. "
                           "Split the section or give the bore a radius at both ends.");
        if (k > 0)
          {
            const double gap = s.z0 - list[k - 1].z1;
            if (std::abs(gap) > 1e-12 * std::max(1., std::abs(s.z0)))
              {
                where << " does not start where section " << k << " ends (z "
                      << list[k - 1].z1
                      << "): sections follow each other in increasing z without gaps "
                         "or overlaps.";
                throw InputError(where.str());
              }
          }
      }
  }

  double
  SectionMesh::n_cells() const
  {
    const SectionLayout layout = plan();
    const auto         &z      = layout.axial_nodes();
    const auto         &chains = layout.chains();
    const double k      = n_theta / 4;
    double       n      = 0;
    for (unsigned int l = 0; l + 1 < z.size(); ++l)
      {
        const double zm = 0.5 * (z[l] + z[l + 1]);
        for (const auto &c : chains)
          if (zm > sections[c.body][c.first].z0 && zm < sections[c.body][c.last].z1)
            n += n_theta * (c.fractions.size() - 1) + (c.solid ? k * k + n_theta : 0);
      }
    return n;
  }

  std::string
  SectionMesh::describe(const bool meridian) const
  {
    const SectionLayout layout = plan();
    const auto         &zones  = layout.fit_zones();
    const auto         &z      = layout.axial_nodes();
    const auto         &chains = layout.chains();
    std::ostringstream s;
    s << std::setprecision(3);
    if (meridian)
      s << "Meridian plan: ";
    else
      s << "Section mesh: " << n_theta << " cells around, ";
    s << z.size() - 1 << " axial layers, element size " << h_max * 1e3 << " mm, "
      << h_fit * 1e3 << " mm at the " << zones.size() << " fit zone(s)";
    if (h_edge < h_fit)
      s << ", " << h_edge * 1e3 << " mm at their edges";
    s << "\n";
    for (unsigned int b = 0; b < sections.size(); ++b)
      {
        s << "  " << body_names[b] << ": " << sections[b].size() << " section(s), radial cells";
        for (const auto &c : chains)
          if (c.body == b)
            s << " " << c.fractions.size() - 1;
        if (core_radius[b] > 0)
          s << ", O-grid core r " << core_radius[b] * 1e3 << " mm";
        s << "\n";
      }
    return s.str();
  }
  SectionLayout
  SectionMesh::plan() const
  {
    return SectionLayout(sections, core_radius, body_names, h_fit, h_edge, h_max, refinement);
  }

  void
  SectionMesh::create(Triangulation<3>                                   &tria,
                      std::map<types::boundary_id, std::set<std::string>> &names) const
  {
    const SectionLayout layout = plan();
    SectionHexahedra(layout, n_theta).create(tria);
    name_boundaries(tria, names);
  }

  void
  SectionMesh::create_meridian(Triangulation<2>                                   &tria,
                               std::map<types::boundary_id, std::set<std::string>> &names) const
  {
    const SectionLayout layout = plan();
    SectionQuadrilaterals(layout).create(tria);
    name_boundaries(tria, names);
  }

  template <int dim>
  std::optional<SectionMesh::Side>
  SectionMesh::face_side(const typename Triangulation<dim>::face_iterator &face,
                         const unsigned int                                b,
                         double                                           &zm) const
  {
    double             z_lo = std::numeric_limits<double>::max(), z_hi = -z_lo, r = 0;
    const unsigned int n    = face->n_vertices();
    for (const unsigned int v : face->vertex_indices())
      {
        const Point<dim> &x = face->vertex(v);
        // 3D: Cartesian; the meridian: x = r, y = z
        const double radius = dim == 3 ? std::hypot(x[0], x[1]) : x[0];
        z_lo = std::min(z_lo, x[dim - 1]);
        z_hi = std::max(z_hi, x[dim - 1]);
        r += radius / n;
      }
    zm               = 0.5 * (z_lo + z_hi);
    const double tol = 1e-9 * std::max(1., std::abs(zm));
    if (z_hi - z_lo <= tol) // an axial face: an end of the body, or a step (unnamed)
      {
        if (std::abs(zm - sections[b].front().z0) <= tol)
          return Side::start;
        if (std::abs(zm - sections[b].back().z1) <= tol)
          return Side::end;
        return std::nullopt;
      }
    const AxialSection &s = section_at(sections[b], zm);
    return std::abs(r - s.ro(zm)) < std::abs(r - s.ri(zm)) ? Side::outer : Side::inner;
  }

  template <int dim>
  void
  SectionMesh::name_boundaries(Triangulation<dim>                                 &tria,
                               std::map<types::boundary_id, std::set<std::string>> &names) const
  {
    // boundary ids: one per distinct set of surface names
    std::map<std::set<std::string>, types::boundary_id> id_of{{{}, 0}};
    std::map<std::pair<std::string, unsigned int>, unsigned int> faces_of; // (surface, selector)
    for (const auto &cell : tria.active_cell_iterators())
      for (const unsigned int f : cell->face_indices())
        if (cell->face(f)->at_boundary())
          {
            const auto   face = cell->face(f);
            const auto   b    = cell->material_id();
            double       zm   = 0;
            const auto   side = face_side<dim>(face, b, zm);
            const double tol  = 1e-9 * std::max(1., std::abs(zm));
            std::set<std::string> set;
            for (const auto &[name, selectors] : surfaces)
              for (unsigned int i = 0; i < selectors.size(); ++i)
                {
                  const auto &sel = selectors[i];
                  if (side && sel.body == b && sel.side == *side && zm >= sel.z_from - tol &&
                      zm <= sel.z_to + tol)
                    {
                      set.insert(name);
                      ++faces_of[{name, i}];
                    }
                }
            const auto it = id_of.emplace(set, id_of.size()).first;
            face->set_boundary_id(it->second);
          }
    names.clear();
    for (const auto &[set, id] : id_of)
      names[id] = set;
    for (const auto &[name, selectors] : surfaces)
      for (unsigned int i = 0; i < selectors.size(); ++i)
        if (faces_of[{name, i}] == 0)
          {
            const auto        &sel = selectors[i];
            std::ostringstream m;
            m << "Geometry/Sections/Surfaces: the selector '" << body_names[sel.body] << " "
              << side_name(sel.side);
            if (sel.z_from > -std::numeric_limits<double>::max())
              m << " " << sel.z_from << " " << sel.z_to;
            m << "' of surface '" << name
              << "' selects no boundary face; check the side and the axial range against "
                 "the body's Sections (a body's start and end are its lowest and highest z).";
            throw InputError(m.str());
          }
  }

  template <int dim>
  SectionMesh::Refinement
  SectionMesh::refined(const Triangulation<dim> &tria,
                       const Vector<float>      &indicator,
                       const double              fraction) const
  {
    const SectionLayout layout = plan();
    const auto         &z      = layout.axial_nodes();
    const auto         &chains = layout.chains();

    // sums of indicator^2 over each axial layer and each radial interval
    std::vector<double>              layer(z.size() - 1, 0.);
    std::vector<std::vector<double>> interval(chains.size());
    for (unsigned int i = 0; i < chains.size(); ++i)
      interval[i].assign(chains[i].fractions.size() - 1, 0.);
    for (const auto &cell : tria.active_cell_iterators())
      {
        const double     eta2 = std::pow(indicator[cell->active_cell_index()], 2);
        const Point<dim> x    = cell->center();
        // 3D: Cartesian; the meridian: x = r, y = z
        const double zc = x[dim - 1], rc = dim == 3 ? std::hypot(x[0], x[1]) : x[0];
        const auto   l  = std::upper_bound(z.begin(), z.end(), zc) - z.begin() - 1;
        layer[std::clamp<long>(l, 0, layer.size() - 1)] += eta2;
        const unsigned int b = cell->material_id();
        for (unsigned int i = 0; i < chains.size(); ++i)
          {
            const auto &c = chains[i];
            if (c.body != b || !(zc > sections[b][c.first].z0 && zc < sections[b][c.last].z1))
              continue;
            const AxialSection &s = section_at(sections[b], zc);
            const double        a = layout.inner_radius(c, s, zc);
            const double        f = (rc - a) / (s.ro(zc) - a);
            if (f < 0) // the O-grid core: refined by the circumferential cells only
              break;
            const auto j = std::upper_bound(c.fractions.begin(), c.fractions.end(), f) -
                           c.fractions.begin() - 1;
            interval[i][std::clamp<long>(j, 0, interval[i].size() - 1)] += eta2;
            break;
          }
      }

    // split the largest share of each kind in the middle
    Refinement next = refinement;
    const auto top  = [fraction](const std::vector<double> &v) {
      std::vector<unsigned int> order(v.size());
      for (unsigned int i = 0; i < v.size(); ++i)
        order[i] = i;
      std::sort(order.begin(), order.end(), [&](unsigned a, unsigned b) { return v[a] > v[b]; });
      order.resize(std::min<std::size_t>(v.size(), std::max(1., std::round(fraction * v.size()))));
      return order;
    };
    for (const unsigned int l : top(layer))
      next.z.push_back(0.5 * (z[l] + z[l + 1]));
    next.layers_split = std::max(1., std::round(fraction * layer.size()));
    std::vector<double>                                      flat;
    std::vector<std::pair<unsigned int, unsigned int>>       where;
    for (unsigned int i = 0; i < chains.size(); ++i)
      for (unsigned int j = 0; j < interval[i].size(); ++j)
        {
          flat.push_back(interval[i][j]);
          where.emplace_back(i, j);
        }
    const auto marked    = top(flat);
    next.intervals_split = marked.size();
    for (const unsigned int k : marked)
      {
        const auto &[i, j] = where[k];
        const auto &c      = chains[i];
        next.fractions[{c.body, c.first}].push_back(0.5 * (c.fractions[j] + c.fractions[j + 1]));
      }
    next.layers_split = top(layer).size();
    return next;
  }

  template SectionMesh::Refinement
  SectionMesh::refined(const Triangulation<2> &, const Vector<float> &, const double) const;
  template SectionMesh::Refinement
  SectionMesh::refined(const Triangulation<3> &, const Vector<float> &, const double) const;

} // namespace rotorfit
