#include <rotorfit/base/input_error.h>
#include <rotorfit/base/patterns.h>
#include <rotorfit/base/resources.h>
#include <rotorfit/constraints/cylindrical_constraints.h>
#include <rotorfit/model/discretization.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature.h>
#include <deal.II/base/utilities.h>

#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_values.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;



  namespace
  {
    /// 'machine' or a finite number > 0 (Resources/Memory limit).
    class MemoryLimitPattern : public Patterns::PatternBase
    {
    public:
      bool
      match(const std::string &s) const override
      {
        return s == "machine" || patterns::Positive().match(s);
      }

      std::string
      description(const OutputStyle = Machine) const override
      {
        return "[machine or Double > 0]";
      }

      std::unique_ptr<PatternBase>
      clone() const override
      {
        return std::make_unique<MemoryLimitPattern>();
      }
    };
  } // namespace

  Discretization::Discretization(const MPI_Comm comm, Log &log)
    : comm(comm)
    , log(log)
    , assembly_mesh(comm)
  {}

  void
  Discretization::declare_parameters(ParameterHandler &prm)
  {
    AssemblyMesh::declare_parameters(prm);
    Bodies::declare_list(prm);
    ContactInterfaces::declare_list(prm);
    ContactInterfaces::declare_fit_design(prm);
    prm.enter_subsection("Supports");
    prm.declare_entry("Axial roller surfaces",
                      "",
                      Patterns::List(Patterns::Anything(), 0),
                      "Physical surfaces with u_z = 0 (for plane-strain "
                      "verification set-ups). Every body is also held by "
                      "statically determinate cylindrical supports.");
    prm.leave_subsection();
    prm.enter_subsection("Resources");
    prm.declare_entry("Memory limit",
                      "machine",
                      MemoryLimitPattern(),
                      "Memory this run may use [GB, 10^9 bytes]; 'machine': the machine's "
                      "physical memory. A model whose estimated peak (the mesh's "
                      "factorisation before meshing; the factorisations and the Krylov "
                      "space before assembly) exceeds 90 % of it is refused before the "
                      "work starts (doc/limits.md). Set less on a machine shared with "
                      "others.");
    prm.leave_subsection();
  }

  void
  Discretization::parse_parameters(ParameterHandler &prm, const std::string &prm_directory)
  {
    body_list.parse_parameters(prm);
    std::vector<std::string> body_names;
    for (const auto &b : body_list.list())
      body_names.push_back(b.name);
    assembly_mesh.parse_parameters(prm, prm_directory, body_names);
    interface_list.parse_parameters(prm);
    prm.enter_subsection("Supports");
    rollers = Utilities::split_string_list(prm.get("Axial roller surfaces"), ',');
    check_unique(rollers, "Supports/Axial roller surfaces");
    prm.leave_subsection();
    prm.enter_subsection("Resources");
    const std::string limit = prm.get("Memory limit");
    prm.leave_subsection();
    memory_limit_bytes =
      limit == "machine" ? resources::physical_memory_bytes() : std::stod(limit) * 1e9;
    assembly_mesh.set_memory_limit(memory_limit_bytes);
  }

  void
  Discretization::setup(TimerOutput &timer)
  {
    {
      TimerOutput::Scope t(timer, "mesh (gmsh + triangulation)");
      assembly_mesh.create(body_list.physical_volumes());
    }
    TimerOutput::Scope t(timer, "setup (DoFs, pairs, constraints)");
    fe = std::make_unique<FESystem<3>>(*assembly_mesh.scalar_element(), 3);
    dof_handler.reinit(assembly_mesh.triangulation());
    dof_handler.distribute_dofs(*fe);
    owned = dof_handler.locally_owned_dofs();
    compute_support_points();

    const auto strains = body_list.free_thermal_strains(interface_list.reference_temperature());
    // the temperatures enter as free expansion: a roller restrains it
    if (!rollers.empty() && std::any_of(strains.begin(), strains.end(), [](const double e) {
          return e != 0;
        }))
      throw InputError("Supports/Axial roller surfaces hold u_z = 0, which would restrain the "
                       "thermal expansion of a body off the reference temperature; rotorfit "
                       "models temperatures as the free expansion of bodies on statically "
                       "determinate supports. Remove the rollers or keep every body at Fit "
                       "design/Reference temperature.");
    contact_pairs.build(assembly_mesh, dof_handler, points, interface_list, strains);
    std::vector<std::string> body_names;
    for (const auto &b : body_list.list())
      body_names.push_back(b.name);
    constraints.clear();
    const std::string description = make_cylindrical_constraints(
      assembly_mesh, dof_handler, points, body_names, rollers, constraints);
    constraints.close();

    log << assembly_mesh.describe();
    log << "Mesh: " << assembly_mesh.triangulation().n_global_active_cells()
        << " " << assembly_mesh.cell_name() << ", " << dof_handler.n_dofs() << " DOFs ("
        << (assembly_mesh.hexahedral() ? "Q" : "P") << assembly_mesh.element_order() << ", quadratic geometry), "
        << Utilities::MPI::n_mpi_processes(comm) << " MPI rank(s)\n";
    for (unsigned int i = 0; i < contact_pairs.n_interfaces(); ++i)
      log << "Interface " << interface_list.list()[i].name << ": "
          << contact_pairs.pairs_of(i).size() << " node pairs, area "
          << contact_pairs.area(i) * 1e6 << " mm^2, "
          << describe_interference(interface_list, contact_pairs, i)
          << "\n";
    log << "Static supports:\n" << description;
    check_interference();
    check_unused_fits();
  }

  namespace
  {
    /// A boundary face of a body that is not all at one z.
    struct Face
    {
      Point<3>                 centre;
      types::material_id       body;
      bool                     used; // on a surface of an Interface
      double                   r, z_lo, z_hi; // of its vertices
      std::vector<std::string> names;
    };

    /// Coincident faces of two bodies that no Interface uses.
    struct Touch
    {
      unsigned int          n = 0;
      double                r_lo = 1e300, r_hi = 0, z_lo = 1e300, z_hi = -1e300;
      std::set<std::string> names;
    };

    /// The boundary faces that are not all at one z (an end face against a
    /// shoulder is no fit), sorted by x of their centres; @p scale becomes
    /// the largest distance of a centre from the origin.
    std::vector<Face>
    side_faces(const AssemblyMesh &mesh, const ContactInterfaces &interfaces, double &scale)
    {
      std::vector<Face> faces;
      for (const auto &cell : mesh.triangulation().active_cell_iterators())
        for (const unsigned int f : cell->face_indices())
          if (cell->face(f)->at_boundary())
            {
              const auto face = cell->face(f);
              Point<3>   c;
              double     r = 0, z_lo = face->vertex(0)[2], z_hi = z_lo;
              for (const unsigned int v : face->vertex_indices())
                {
                  const Point<3> &p = face->vertex(v);
                  c += p / face->n_vertices();
                  r    = std::max(r, std::hypot(p[0], p[1]));
                  z_lo = std::min(z_lo, p[2]);
                  z_hi = std::max(z_hi, p[2]);
                }
              scale = std::max(scale, c.norm());
              if (z_hi - z_lo <= 1e-9 * std::max(1e-3, std::abs(z_hi)))
                continue;
              Face x{c, cell->material_id(), false, r, z_lo, z_hi, {}};
              for (const auto &i : interfaces.list())
                x.used |= mesh.face_on_surface(i.shaft_surface, cell, f) ||
                          mesh.face_on_surface(i.hub_surface, cell, f);
              if (!x.used)
                for (const auto &name : mesh.surface_names())
                  if (mesh.face_on_surface(name, cell, f))
                    x.names.push_back(name);
              faces.push_back(x);
            }
      std::sort(faces.begin(), faces.end(), [](const Face &a, const Face &b) {
        return a.centre[0] < b.centre[0];
      });
      return faces;
    }

    /// Faces of two bodies within @p tol of each other, neither used by an
    /// Interface, gathered per pair of bodies.
    std::map<std::pair<types::material_id, types::material_id>, Touch>
    unused_touches(const std::vector<Face> &faces, const double tol)
    {
      std::map<std::pair<types::material_id, types::material_id>, Touch> unused;
      for (std::size_t i = 0; i < faces.size(); ++i)
        for (std::size_t j = i + 1;
             j < faces.size() && faces[j].centre[0] - faces[i].centre[0] <= tol;
             ++j)
          if (faces[i].body != faces[j].body && !faces[i].used && !faces[j].used &&
              faces[i].centre.distance(faces[j].centre) <= tol)
            {
              auto &t = unused[{std::min(faces[i].body, faces[j].body),
                                std::max(faces[i].body, faces[j].body)}];
              ++t.n;
              t.r_lo = std::min(t.r_lo, faces[i].r);
              t.r_hi = std::max(t.r_hi, faces[i].r);
              t.z_lo = std::min(t.z_lo, faces[i].z_lo);
              t.z_hi = std::max(t.z_hi, faces[i].z_hi);
              for (const auto *f : {&faces[i], &faces[j]})
                t.names.insert(f->names.begin(), f->names.end());
            }
      return unused;
    }

    /// "lo .. hi mm", or "lo mm" where the two agree.
    std::string
    millimetre_range(const double lo, const double hi)
    {
      std::ostringstream s;
      s << std::setprecision(4) << lo * 1e3;
      if (hi - lo > 1e-6 * std::max(std::abs(lo), std::abs(hi)))
        s << " .. " << hi * 1e3;
      return s.str() + " mm";
    }
  } // namespace

  void
  Discretization::check_unused_fits() const
  {
    // Two bodies meshed against each other (coincident boundary faces, not
    // all at one z) are joined only by an Interface; without one each rides
    // on its supports alone.
    double            scale = 0;
    const auto        faces = side_faces(assembly_mesh, interface_list, scale);
    const double      tol   = std::max(assembly_mesh.matching_tolerance(), 1e-10) * scale;
    for (const auto &[bodies, t] : unused_touches(faces, tol))
      {
        std::string names;
        for (const auto &n : t.names)
          names += (names.empty() ? "" : ", ") + ("'" + n + "'");
        log << "Warning: bodies " << body_list[bodies.first].name << " and "
            << body_list[bodies.second].name << " touch on " << t.n << " faces (r "
            << millimetre_range(t.r_lo, t.r_hi) << ", z " << millimetre_range(t.z_lo, t.z_hi)
            << ") that no Interface uses"
            << (names.empty() ? std::string(" (no surface is named there)") :
                                " (surface " + names + " lies there)")
            << ": the two are not joined there, each held by its own supports alone. Name "
               "the fit in an Interface (Shaft surface, Hub surface), or part the bodies if "
               "they are meant apart.\n";
      }
  }

  double
  Discretization::outer_radius() const
  {
    double r_max = 0;
    for (const auto &p : points)
      r_max = std::max(r_max, std::hypot(p[0], p[1]));
    return r_max;
  }

  void
  Discretization::check_interference() const
  {
    // The model is linear elastic in small strain: the interference is a
    // strain delta / r of the fit. Metals leave their elastic range at
    // strains of 0.1 .. 0.5 %; at 1 % the small-strain model itself fails.
    for (unsigned int f = 0; f < contact_pairs.n_interfaces(); ++f)
      {
        double r = 0;
        for (const auto i : contact_pairs.pairs_of(f))
          r += std::hypot(contact_pairs.pairs()[i].position[0],
                          contact_pairs.pairs()[i].position[1]);
        r /= std::max<std::size_t>(1, contact_pairs.pairs_of(f).size());
        const auto  &d      = interface_list.list()[f];
        const double delta  = contact_pairs.geometry(f).radial_interference;
        const double strain = delta / r;
        std::ostringstream m;
        if (d.fit.toleranced())
          m << "Interface " << d.name << ": the radial interference of its " << d.fit.describe()
            << ", " << delta << " m,";
        else
          m << "Interface " << d.name << "/Radial interference = " << delta << " m";
        m << " is " << std::setprecision(3) << 100 * strain << " % of the fit radius "
          << r * 1e3 << " mm";
        if (strain > 1e-2)
          throw InputError(m.str() + "; rotorfit's linear small-strain model holds below 1 % "
                                     "(metals yield at 0.1 .. 0.5 %). Check the units " +
                           std::string(d.fit.toleranced() ?
                                         "(Limit deviations are diametral, in metres: 21e-6 "
                                         "for 21 um)." :
                                         "(metres, on the radius)."));
        if (strain > 2e-3)
          log << "Warning: " << m.str()
              << ": above the elastic limit strain of most shaft and hub alloys (about "
                 "0.2 %); the fit may yield, which a linear elastic model does not see.\n";
      }
  }

  void
  Discretization::compute_support_points()
  {
    // support points through the curved mapping: pairs and supports must
    // see the same geometry as the integrals
    points.assign(dof_handler.n_dofs(), Point<3>());
    const Quadrature<3> q(fe->get_unit_support_points());
    FEValues<3> fe_values(assembly_mesh.mapping(), *fe, q, update_quadrature_points);
    std::vector<types::global_dof_index> dofs(fe->n_dofs_per_cell());
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        fe_values.reinit(cell);
        cell->get_dof_indices(dofs);
        for (unsigned int i = 0; i < dofs.size(); ++i)
          points[dofs[i]] = fe_values.quadrature_point(i);
      }
  }
} // namespace rotorfit
