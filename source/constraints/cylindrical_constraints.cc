#include <rotorfit/base/dof_utilities.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/constraints/cylindrical_constraints.h>
#include <rotorfit/mesh/assembly_mesh.h>

#include <deal.II/base/numbers.h>

#include <deal.II/lac/lapack_full_matrix.h>

#include <cmath>
#include <map>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    struct Node
    {
      std::array<types::global_dof_index, 3> dofs;
      Point<3>                               x;
    };

    // u_theta = -sin(t) u_x + cos(t) u_y = 0 as one AffineConstraints line;
    // the DoF with the larger coefficient is the constrained one (|c| <= 1)
    void
    add_tangential_constraint(const Node &node, AffineConstraints<double> &c)
    {
      const double t = std::atan2(node.x[1], node.x[0]);
      if (std::abs(std::cos(t)) >= std::abs(std::sin(t)))
        {
          c.add_line(node.dofs[1]);
          if (std::abs(std::tan(t)) > 1e-14)
            c.add_entry(node.dofs[1], node.dofs[0], std::tan(t));
        }
      else
        {
          c.add_line(node.dofs[0]);
          if (std::abs(std::cos(t) / std::sin(t)) > 1e-14)
            c.add_entry(node.dofs[0], node.dofs[1], std::cos(t) / std::sin(t));
        }
    }

    /// u_z = 0 on every support point of the roller surfaces.
    void
    add_roller_constraints(const AssemblyMesh              &mesh,
                           const DoFHandler<3>             &dof_handler,
                           const std::vector<std::string>  &roller_surfaces,
                           AffineConstraints<double>       &constraints,
                           std::ostringstream              &log)
    {
      const auto &fe = dof_handler.get_fe();
      std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
      for (const auto &surface : roller_surfaces)
        {
          mesh.check_surface_exists(surface, "Supports/Axial roller surfaces");
          unsigned int n = 0;
          for (const auto &cell : dof_handler.active_cell_iterators())
            for (const unsigned int f : cell->face_indices())
              if (cell->face(f)->at_boundary() && mesh.face_on_surface(surface, cell, f))
                {
                  cell->get_dof_indices(dofs);
                  for (const unsigned int i : cell_dofs_on_face(cell, f))
                    if (fe.system_to_component_index(i).first == 2 &&
                        !constraints.is_constrained(dofs[i]))
                      {
                        constraints.add_line(dofs[i]);
                        ++n;
                      }
                }
          log << "  u_z = 0 on " << n << " points of surface '" << surface << "'\n";
        }
    }

    /// The nodes (three DoFs and the point) of every body.
    std::vector<std::map<types::global_dof_index, Node>>
    nodes_by_body(const DoFHandler<3>         &dof_handler,
                  const std::vector<Point<3>> &support_points,
                  const unsigned int           n_bodies)
    {
      const auto &fe = dof_handler.get_fe();
      std::vector<types::global_dof_index>                 dofs(fe.n_dofs_per_cell());
      std::vector<std::map<types::global_dof_index, Node>> nodes(n_bodies);
      for (const auto &cell : dof_handler.active_cell_iterators())
        {
          cell->get_dof_indices(dofs);
          auto &body_nodes = nodes[cell->material_id()];
          for (unsigned int i = 0; i < fe.n_dofs_per_cell(); ++i)
            {
              const auto [c, k] = fe.system_to_component_index(i);
              if (c != 0)
                continue;
              Node n;
              for (unsigned int d = 0; d < 3; ++d)
                n.dofs[d] = dofs[fe.component_to_system_index(d, k)];
              n.x                 = support_points[dofs[i]];
              body_nodes[dofs[i]] = n;
            }
        }
      return nodes;
    }

    /// Extent of a body's nodes.
    struct Extent
    {
      double r_max = 0, z_min = 1e300, z_max = -1e300;
    };

    Extent
    extent_of(const std::map<types::global_dof_index, Node> &nodes)
    {
      Extent e;
      for (const auto &[d, n] : nodes)
        {
          e.r_max = std::max(e.r_max, std::hypot(n.x[0], n.x[1]));
          e.z_min = std::min(e.z_min, n.x[2]);
          e.z_max = std::max(e.z_max, n.x[2]);
        }
      return e;
    }

    /// Five outer nodes near (theta, z) = (0, z1), (pi/2, z1), (pi, z1),
    /// (0, z2), (pi/2, z2) at a quarter of the length from each end.
    std::vector<const Node *>
    choose_support_nodes(const std::map<types::global_dof_index, Node> &nodes,
                         const Extent                                  &e,
                         const std::string                             &body)
    {
      const double length = e.z_max - e.z_min;
      const double z1 = e.z_min + 0.25 * length, z2 = e.z_max - 0.25 * length;
      const std::array<std::pair<double, double>, 5> targets{
        {{0., z1}, {0.5 * numbers::PI, z1}, {numbers::PI, z1}, {0., z2}, {0.5 * numbers::PI, z2}}};
      std::vector<const Node *> chosen;
      for (const auto &[theta, z] : targets)
        {
          const Node *best      = nullptr;
          double      best_cost = 1e300;
          for (const auto &[d, n] : nodes)
            {
              const double r = std::hypot(n.x[0], n.x[1]);
              if (r < 0.5 * e.r_max)
                continue;
              double dt = std::abs(std::atan2(n.x[1], n.x[0]) - theta);
              dt        = std::min(dt, 2 * numbers::PI - dt);
              const double cost = e.r_max * dt + std::abs(n.x[2] - z);
              if (cost < best_cost && std::find(chosen.begin(), chosen.end(), &n) == chosen.end())
                {
                  best_cost = cost;
                  best      = &n;
                }
            }
          if (best == nullptr)
            throw InputError("Body " + body +
                             ": no support points away from the axis for "
                             "its cylindrical supports; is the body meshed?");
          chosen.push_back(best);
        }
      return chosen;
    }

    /// The five u_theta rows must remove U_x, U_y and the three rotations.
    void
    check_rigid_motions_fixed(const std::vector<const Node *> &chosen,
                              const Extent                    &e,
                              const std::string               &body)
    {
      const double length = e.z_max - e.z_min;
      const double z_mid  = 0.5 * (e.z_min + e.z_max);
      LAPACKFullMatrix<double> rows(5, 5);
      for (unsigned int i = 0; i < 5; ++i)
        {
          const Point<3> &x = chosen[i]->x;
          const double    t = std::atan2(x[1], x[0]);
          const double    r = std::hypot(x[0], x[1]);
          const double    z = (x[2] - z_mid) / std::max(length, e.r_max);
          rows(i, 0) = -std::sin(t);
          rows(i, 1) = std::cos(t);
          rows(i, 2) = r / e.r_max;
          rows(i, 3) = -z * std::cos(t);
          rows(i, 4) = -z * std::sin(t);
        }
      rows.compute_svd();
      const double ratio = rows.singular_value(4) / rows.singular_value(0);
      if (!(ratio > 1e-4))
        throw InputError("Body " + body +
                         ": its support points do not fix its rigid "
                         "motions (too short or too thin a body?).");
    }

    /// The node nearest to the axis in the body's mid-plane: its u_z = 0.
    const Node *
    axial_support_node(const std::map<types::global_dof_index, Node> &nodes, const Extent &e)
    {
      const double z_mid     = 0.5 * (e.z_min + e.z_max);
      const Node  *axial     = nullptr;
      double       best_cost = 1e300;
      for (const auto &[d, n] : nodes)
        {
          const double cost = std::abs(n.x[2] - z_mid) + 1e-3 * std::hypot(n.x[0], n.x[1]);
          if (cost < best_cost)
            {
              best_cost = cost;
              axial     = &n;
            }
        }
      return axial;
    }
  } // namespace

  std::string
  make_cylindrical_constraints(const AssemblyMesh             &mesh,
                               const DoFHandler<3>            &dof_handler,
                               const std::vector<Point<3>>    &support_points,
                               const std::vector<std::string> &body_names,
                               const std::vector<std::string> &roller_surfaces,
                               AffineConstraints<double>      &constraints)
  {
    std::ostringstream log;
    // rollers first: their u_z rows are not constrained twice
    add_roller_constraints(mesh, dof_handler, roller_surfaces, constraints, log);
    const auto nodes = nodes_by_body(dof_handler, support_points, body_names.size());
    for (unsigned int b = 0; b < body_names.size(); ++b)
      {
        const Extent e      = extent_of(nodes[b]);
        const auto   chosen = choose_support_nodes(nodes[b], e, body_names[b]);
        check_rigid_motions_fixed(chosen, e, body_names[b]);
        for (const Node *n : chosen)
          add_tangential_constraint(*n, constraints);
        const Node *axial = axial_support_node(nodes[b], e);
        if (!constraints.is_constrained(axial->dofs[2]))
          constraints.add_line(axial->dofs[2]);

        log << "  body " << body_names[b] << ": u_theta = 0 at";
        for (const Node *n : chosen)
          log << " (" << n->x << ")";
        log << "; u_z = 0 at (" << axial->x << ")\n";
      }
    return log.str();
  }
} // namespace rotorfit
