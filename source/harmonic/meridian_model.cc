#include <rotorfit/base/dof_utilities.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/harmonic/meridian_model.h>
#include <rotorfit/mesh/section_mesh.h>

#include <deal.II/dofs/dof_tools.h>

#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q1.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

  MeridianModel::MeridianModel(Log &log)
    : log(log)
  {}

  void
  MeridianModel::setup(const SectionMesh              &sections,
                       const unsigned int              element_order,
                       const Bodies                   &bodies,
                       const ContactInterfaces        &interfaces,
                       const std::vector<std::string> &rollers)
  {
    order     = element_order;
    body_list = &bodies;
    tria.clear();
    sections.create_meridian(tria, boundary_names);
    fe = std::make_unique<FESystem<2>>(FE_Q<2>(order), FourierBasis::n_fields);
    dof_handler.reinit(tria);
    dof_handler.distribute_dofs(*fe);

    std::vector<Point<2>> points(dof_handler.n_dofs());
    DoFTools::map_dofs_to_support_points(linear_mapping, dof_handler, points);
    double r_max = 0;
    for (const auto &p : points)
      r_max = std::max(r_max, p[0]);
    axis_tol = 1e-9 * r_max;

    // nodes: the six DoFs at one support point of one body
    dof_node.assign(dof_handler.n_dofs(), numbers::invalid_unsigned_int);
    node_dofs.clear();
    node_position.clear();
    node_body.clear();
    std::vector<types::global_dof_index> dofs(fe->n_dofs_per_cell());
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        cell->get_dof_indices(dofs);
        for (unsigned int i = 0; i < dofs.size(); ++i)
          {
            const auto [component, k] = fe->system_to_component_index(i);
            if (component != 0 || dof_node[dofs[i]] != numbers::invalid_unsigned_int)
              continue;
            std::array<types::global_dof_index, 6> node;
            for (unsigned int c = 0; c < FourierBasis::n_fields; ++c)
              {
                node[c]                 = dofs[fe->component_to_system_index(c, k)];
                dof_node[node[c]]       = node_dofs.size();
              }
            node_dofs.push_back(node);
            node_position.push_back(points[dofs[i]]);
            node_body.push_back(cell->material_id());
          }
      }

    // the static problem: harmonic 0, fields a and e
    statics.clear();
    std::vector<unsigned int> support(bodies.size(), numbers::invalid_unsigned_int);
    std::vector<double>       z_lo(bodies.size(), 1e300), z_hi(bodies.size(), -1e300);
    for (unsigned int k = 0; k < node_dofs.size(); ++k)
      {
        z_lo[node_body[k]] = std::min(z_lo[node_body[k]], node_position[k][1]);
        z_hi[node_body[k]] = std::max(z_hi[node_body[k]], node_position[k][1]);
      }
    for (unsigned int k = 0; k < node_dofs.size(); ++k)
      {
        for (const unsigned int c : {FourierBasis::d, FourierBasis::b, FourierBasis::c,
                                     FourierBasis::f})
          statics.add_line(node_dofs[k][c]);
        if (node_position[k][0] <= axis_tol)
          statics.add_line(node_dofs[k][FourierBasis::a]);
        // the axial support of each body: the node nearest its mid-length,
        // innermost
        const unsigned int b  = node_body[k];
        const double       zc = 0.5 * (z_lo[b] + z_hi[b]);
        const auto better     = [&](const unsigned int j) {
          const double dk = std::abs(node_position[k][1] - zc), dj = std::abs(node_position[j][1] - zc);
          return dk < dj - 1e-12 || (dk <= dj + 1e-12 && node_position[k][0] < node_position[j][0]);
        };
        if (support[b] == numbers::invalid_unsigned_int || better(support[b]))
          support[b] = k;
      }
    // axial rollers: e = 0 on their lines; such a body needs no point support
    std::vector<bool> on_roller(bodies.size(), false);
    for (const auto &name : rollers)
      {
        check_surface_exists(name, "Supports/Axial roller surfaces");
        for (const auto &cell : dof_handler.active_cell_iterators())
          for (const unsigned int f : cell->face_indices())
            if (on_surface(name, cell, f))
              {
                cell->get_dof_indices(dofs);
                for (const unsigned int i : cell_dofs_on_face(cell, f))
                  if (fe->system_to_component_index(i).first == FourierBasis::e &&
                      !statics.is_constrained(dofs[i]))
                    statics.add_line(dofs[i]);
                on_roller[cell->material_id()] = true;
              }
      }
    for (unsigned int b = 0; b < bodies.size(); ++b)
      {
        if (support[b] == numbers::invalid_unsigned_int)
          throw InputError("Body " + bodies[b].name + " has no cells in the meridian mesh.");
        const auto dof = node_dofs[support[b]][FourierBasis::e];
        if (!on_roller[b] && !statics.is_constrained(dof))
          statics.add_line(dof);
      }
    statics.close();

    fit_surfaces.clear();
    for (const auto &f : interfaces.list())
      fit_surfaces.insert(fit_surfaces.end(), {f.shaft_surface, f.hub_surface});
    build_pairs(interfaces);
    std::ostringstream s;
    s << "Meridian mesh: " << tria.n_active_cells() << " quadrilaterals, " << node_dofs.size()
      << " nodes, element order " << order << "\n";
    s << sections.describe(true);
    for (unsigned int i = 0; i < contact_pairs.n_interfaces(); ++i)
      s << "Interface " << interfaces.list()[i].name << ": " << contact_pairs.pairs_of(i).size()
        << " ring pairs, area " << contact_pairs.area(i) * 1e6 << " mm^2, "
        << describe_interference(interfaces, contact_pairs, i) << "\n";
    log << s.str();
  }

  bool
  MeridianModel::on_surface(const std::string                         &name,
                            const DoFHandler<2>::active_cell_iterator &cell,
                            const unsigned int                          f) const
  {
    const auto face = cell->face(f);
    return face->at_boundary() && boundary_names.count(face->boundary_id()) &&
           boundary_names.at(face->boundary_id()).count(name) > 0;
  }

  void
  MeridianModel::check_surface_exists(const std::string &name, const std::string &entry) const
  {
    std::set<std::string> known;
    for (const auto &[id, names] : boundary_names)
      known.insert(names.begin(), names.end());
    if (known.count(name) > 0)
      return;
    std::string list;
    for (const auto &s : known)
      list += (list.empty() ? "" : ", ") + s;
    throw InputError(entry + " = '" + name +
                     "' is not a surface of Geometry/Sections/Surfaces; it has: " + list + ".");
  }

  void
  MeridianModel::build_pairs(const ContactInterfaces &interfaces)
  {
    const QGauss<1>   rule(order + 1);
    FEFaceValues<2>   fe_face(linear_mapping, *fe, rule,
                            update_values | update_JxW_values | update_quadrature_points);
    std::vector<types::global_dof_index> dofs(fe->n_dofs_per_cell());
    std::vector<ContactPairs::RingInterface> rings;
    for (const auto &def : interfaces.list())
      {
        check_surface_exists(def.shaft_surface, "Interface " + def.name + "/Shaft surface");
        check_surface_exists(def.hub_surface, "Interface " + def.name + "/Hub surface");
        // support nodes of each side (0 shaft: cell inside; 1 hub: outside)
        std::set<unsigned int>                 side[2];
        std::vector<std::vector<unsigned int>> shaft_lines; // nodes in shape order
        std::vector<FullMatrix<double>>        line_mass;
        std::vector<double>                    line_area;
        for (const auto &cell : dof_handler.active_cell_iterators())
          for (const unsigned int f : cell->face_indices())
            for (unsigned int s = 0; s < 2; ++s)
              {
                if (!on_surface(s == 0 ? def.shaft_surface : def.hub_surface, cell, f))
                  continue;
                if ((s == 0) != (cell->center()[0] < cell->face(f)->center()[0]))
                  continue;
                cell->get_dof_indices(dofs);
                std::vector<unsigned int> local; // cell dofs of field a on the line
                for (const unsigned int i : cell_dofs_on_face(cell, f))
                  if (fe->system_to_component_index(i).first == FourierBasis::a)
                    {
                      local.push_back(i);
                      side[s].insert(dof_node[dofs[i]]);
                    }
                if (s != 0)
                  continue;
                fe_face.reinit(cell, f);
                FullMatrix<double> m(local.size(), local.size());
                double             area = 0;
                for (unsigned int q = 0; q < rule.size(); ++q)
                  {
                    const double ring = 2 * M_PI * fe_face.quadrature_point(q)[0] * fe_face.JxW(q);
                    area += ring;
                    for (unsigned int i = 0; i < local.size(); ++i)
                      for (unsigned int j = 0; j < local.size(); ++j)
                        m(i, j) += fe_face.shape_value(local[i], q) *
                                   fe_face.shape_value(local[j], q) * ring;
                  }
                std::vector<unsigned int> nodes;
                for (const auto i : local)
                  nodes.push_back(dof_node[dofs[i]]);
                shaft_lines.push_back(nodes);
                line_mass.push_back(m);
                line_area.push_back(area);
              }
        for (unsigned int s = 0; s < 2; ++s)
          if (side[s].empty())
            throw InputError("Interface " + def.name + ": the surface '" +
                             (s == 0 ? def.shaft_surface : def.hub_surface) +
                             "' has no boundary lines on the " + (s == 0 ? "shaft" : "hub") +
                             " side of the meridian; the bodies do not touch there. Check "
                             "Geometry/Sections/Surfaces.");
        // pair the nodes by coordinates
        ContactPairs::RingInterface ring;
        std::map<unsigned int, unsigned int> pair_of_node;
        std::set<unsigned int>               hub_used;
        unsigned int                         unmatched = 0;
        Point<2>                             first;
        for (const unsigned int k : side[0])
          {
            const Point<2> &x     = node_position[k];
            const double    tol   = 1e-8 * std::max(x[0], 1e-12);
            unsigned int    match = numbers::invalid_unsigned_int;
            for (const unsigned int h : side[1])
              if (node_position[h].distance(x) <= tol)
                match = h;
            if (match == numbers::invalid_unsigned_int)
              {
                if (unmatched++ == 0)
                  first = x;
                continue;
              }
            hub_used.insert(match);
            ContactPair p;
            p.shaft_dofs = {{node_dofs[k][FourierBasis::a], node_dofs[k][FourierBasis::a],
                             node_dofs[k][FourierBasis::e]}};
            p.hub_dofs   = {{node_dofs[match][FourierBasis::a], node_dofs[match][FourierBasis::a],
                             node_dofs[match][FourierBasis::e]}};
            // the radial normal; the y slot repeats x with weight 0
            p.normal       = Tensor<1, 3>({1., 0., 0.});
            p.position     = Point<3>(x[0], 0., x[1]);
            p.interference = 0;
            pair_of_node[k] = ring.pairs.size();
            ring.pairs.push_back(p);
            ring.shaft_body.push_back(node_body[k]);
            ring.hub_body.push_back(node_body[match]);
          }
        unmatched += side[1].size() - hub_used.size();
        if (unmatched > 0)
          {
            std::ostringstream m;
            m << "Interface " << def.name << ": " << unmatched
              << " meridian nodes of the fit have no coincident partner on the other body "
                 "(first at r = "
              << first[0] << " m, z = " << first[1]
              << " m); the two bodies must meet at one radius over the fit.";
            throw InputError(m.str());
          }
        for (unsigned int l = 0; l < shaft_lines.size(); ++l)
          {
            std::vector<unsigned int> face;
            for (const auto k : shaft_lines[l])
              face.push_back(pair_of_node.at(k));
            ring.faces.push_back(face);
          }
        ring.face_area = line_area;
        ring.face_mass = line_mass;
        rings.push_back(std::move(ring));
      }
    contact_pairs.build_rings(interfaces, std::move(rings),
                              body_list->free_thermal_strains(interfaces.reference_temperature()));
  }

  MeridianModel::FreeDofs
  MeridianModel::free_dofs(const unsigned int n) const
  {
    const FourierBasis basis(n);
    FreeDofs           free;
    free.expansion.assign(dof_handler.n_dofs(), {});
    std::vector<std::pair<unsigned int, unsigned int>> slaves; // (dof, master dof)
    for (unsigned int k = 0; k < node_dofs.size(); ++k)
      {
        const bool on_axis = node_position[k][0] <= axis_tol;
        for (unsigned int c = 0; c < FourierBasis::n_fields; ++c)
          {
            if (!basis.active(c))
              continue;
            const auto dof = node_dofs[k][c];
            if (on_axis)
              {
                if (n == 0 && c != FourierBasis::e)
                  continue;
                if (n == 1)
                  {
                    if (c == FourierBasis::e || c == FourierBasis::f)
                      continue;
                    // a rigid lateral translation: d = a, c = b
                    if (c == FourierBasis::d)
                      {
                        slaves.emplace_back(dof, node_dofs[k][FourierBasis::a]);
                        continue;
                      }
                    if (c == FourierBasis::c)
                      {
                        slaves.emplace_back(dof, node_dofs[k][FourierBasis::b]);
                        continue;
                      }
                  }
                if (n >= 2)
                  continue;
              }
            free.expansion[dof] = {{free.n_free, 1.}};
            free.dof.push_back(dof);
            ++free.n_free;
          }
      }
    for (const auto &[dof, master] : slaves)
      free.expansion[dof] = free.expansion[master];
    return free;
  }

  void
  MeridianModel::station_weights(Station &s) const
  {
    unsigned int body = numbers::invalid_unsigned_int;
    if (s.is_band())
      {
        std::string names;
        for (unsigned int b = 0; b < body_list->size(); ++b)
          {
            if ((*body_list)[b].name == s.body)
              body = b;
            names += (names.empty() ? "" : ", ") + (*body_list)[b].name;
          }
        if (body == numbers::invalid_unsigned_int)
          throw InputError(s.owner + "/Body = '" + s.body + "' is not a body (Bodies = " + names +
                           ").");
      }
    else
      check_surface_exists(s.surface, s.owner + "/Surface");
    // a band is cut at the points of the rule: 16 sub-intervals of a line
    const QIterated<1> rule(QGauss<1>(order + 1), s.is_band() ? 16 : 1);
    FEFaceValues<2>    fe_face(linear_mapping, *fe, rule,
                            update_values | update_JxW_values | update_quadrature_points |
                              update_normal_vectors);
    std::vector<types::global_dof_index> dofs(fe->n_dofs_per_cell());
    std::map<unsigned int, double>       w; // node -> int N 2 pi r ds
    double area = 0, z_area = 0, r_area = 0;
    for (const auto &cell : dof_handler.active_cell_iterators())
      for (const unsigned int f : cell->face_indices())
        {
          if (!cell->face(f)->at_boundary())
            continue;
          if (s.is_band() ? cell->material_id() != body : !on_surface(s.surface, cell, f))
            continue;
          fe_face.reinit(cell, f);
          cell->get_dof_indices(dofs);
          bool used = false;
          for (unsigned int q = 0; q < rule.size(); ++q)
            {
              const Point<2> &x = fe_face.quadrature_point(q);
              if (s.is_band() && (fe_face.normal_vector(q)[0] <= 0.5 ||
                                  std::abs(x[1] - s.axial_position) > s.width / 2))
                continue;
              used            = true;
              const double da = 2 * M_PI * x[0] * fe_face.JxW(q);
              area += da;
              z_area += x[1] * da;
              r_area += x[0] * da;
              for (const unsigned int i : cell_dofs_on_face(cell, f))
                if (fe->system_to_component_index(i).first == FourierBasis::a)
                  w[dof_node[dofs[i]]] += fe_face.shape_value(i, q) * da;
            }
          if (used && s.is_band())
            for (const auto &name : fit_surfaces)
              if (on_surface(name, cell, f))
                throw InputError(s.owner + ": the " + s.describe() + " overlaps the fit surface '" +
                                 name + "'; a station acts on a free surface of the shaft (move "
                                        "the band or narrow it).");
        }
    if (!(area > 0))
      throw InputError(s.owner + ": the " + s.describe() +
                       (s.is_band() ? " meets no outer surface of the body in the meridian "
                                      "(is the axial position inside the body's length?)" :
                                      " has no boundary lines in the meridian mesh") +
                       ".");
    s.area   = area;
    s.z      = z_area / area;
    s.radius = r_area / area;
    s.dof_x.clear();
    s.dof_y.clear();
    s.weight.clear();
    for (const auto &[k, integral] : w)
      if (integral != 0)
        for (const auto [fx, fy] : {std::pair{FourierBasis::a, FourierBasis::b},
                                    std::pair{FourierBasis::d, FourierBasis::c}})
          {
            s.dof_x.push_back(node_dofs[k][fx]);
            s.dof_y.push_back(node_dofs[k][fy]);
            s.weight.push_back(0.5 * integral / area);
          }
  }
} // namespace rotorfit
