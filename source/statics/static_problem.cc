#include <rotorfit/base/input_error.h>
#include <rotorfit/constraints/cylindrical_constraints.h>
#include <rotorfit/material/elasticity.h>
#include <rotorfit/statics/static_problem.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/utilities.h>

#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_values.h>

#include <deal.II/lac/full_matrix.h>

#include <filesystem>
#include <fstream>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <limits>

namespace rotorfit
{
  using namespace dealii;

  StaticProblem::StaticProblem(const MPI_Comm comm, Log &log)
    : comm(comm)
    , log(log)
    , mesh(comm)
  {}

  void
  StaticProblem::declare_parameters(ParameterHandler &prm)
  {
    AssemblyMesh::declare_parameters(prm);
    Bodies::declare_list(prm);
    ContactInterfaces::declare_list(prm);
    SpeedSchedule::declare_parameters(prm);
    ContactSolver::declare_parameters(prm);
    DirectSolver::declare_parameters(prm);

    prm.enter_subsection("Contact");
    prm.declare_entry("On loss of fit",
                      "continue",
                      Patterns::Selection("continue|stop"),
                      "What the sweep does once every interface is fully "
                      "open: 'continue' (loose bodies held by their "
                      "cylindrical supports) or 'stop'.");
    prm.leave_subsection();

    prm.enter_subsection("Physics");
    prm.declare_entry("Spin softening",
                      "false",
                      Patterns::Bool(),
                      "Centrifugal load on the deformed radius (-Omega^2 M_perp "
                      "in the static stiffness). Off by default: the "
                      "closed-form checks use the undeformed radius, and with "
                      "it on every speed needs its own factorisation.");
    prm.leave_subsection();

    prm.enter_subsection("Supports");
    prm.declare_entry("Axial roller surfaces",
                      "",
                      Patterns::List(Patterns::Anything(), 0),
                      "Physical surfaces with u_z = 0 (for plane-strain "
                      "verification set-ups). Every body is also held by "
                      "statically determinate cylindrical supports.");
    prm.leave_subsection();

    prm.enter_subsection("Output");
    prm.declare_entry("Directory",
                      "output",
                      Patterns::DirectoryName(),
                      "Where results go (created if missing; relative to the "
                      "working directory).");
    prm.declare_entry("Write ParaView files",
                      "true",
                      Patterns::Bool(),
                      "One .pvtu per speed (displacement, von Mises stress, "
                      "body, contact status, pressure and gap) and a .pvd "
                      "index.");
    prm.leave_subsection();
  }

  void
  StaticProblem::parse_parameters(ParameterHandler &prm,
                                  const std::string &prm_directory)
  {
    mesh.parse_parameters(prm, prm_directory);
    bodies.parse_parameters(prm);
    interfaces.parse_parameters(prm);
    speeds.parse_parameters(prm);
    contact.parse_parameters(prm);

    prm.enter_subsection("Contact");
    stop_on_loss_of_fit = (prm.get("On loss of fit") == "stop");
    prm.leave_subsection();
    prm.enter_subsection("Physics");
    spin_softening = prm.get_bool("Spin softening");
    prm.leave_subsection();
    prm.enter_subsection("Supports");
    roller_surfaces =
      Utilities::split_string_list(prm.get("Axial roller surfaces"), ',');
    check_unique(roller_surfaces, "Supports/Axial roller surfaces");
    prm.leave_subsection();
    prm.enter_subsection("Output");
    output_dir     = prm.get("Directory");
    write_paraview = prm.get_bool("Write ParaView files");
    prm.leave_subsection();
    if (output_dir.empty())
      throw InputError("Output/Directory is empty; give a directory name.");
  }

  void
  StaticProblem::setup()
  {
    timer = std::make_unique<TimerOutput>(timer_stream,
                                          TimerOutput::never,
                                          TimerOutput::wall_times);
    {
      TimerOutput::Scope t(*timer, "mesh (gmsh + triangulation)");
      mesh.create(bodies.physical_volumes());
    }
    TimerOutput::Scope t(*timer, "setup (DoFs, pairs, constraints)");
    fe = std::make_unique<FESystem<3>>(FE_SimplexP<3>(mesh.element_order()), 3);
    dof_handler.reinit(mesh.triangulation());
    dof_handler.distribute_dofs(*fe);
    owned = dof_handler.locally_owned_dofs();
    compute_support_points();

    pairs.build(mesh, dof_handler, support_points, interfaces.list());
    constraints.clear();
    const std::string description =
      make_cylindrical_constraints(mesh,
                                   dof_handler,
                                   support_points,
                                   [&] {
                                     std::vector<std::string> n;
                                     for (const auto &b : bodies.list())
                                       n.push_back(b.name);
                                     return n;
                                   }(),
                                   roller_surfaces,
                                   constraints);
    constraints.close();

    log << "Mesh: " << mesh.triangulation().n_global_active_cells()
        << " tetrahedra, " << dof_handler.n_dofs() << " DOFs (P"
        << mesh.element_order() << ", quadratic geometry), "
        << Utilities::MPI::n_mpi_processes(comm) << " MPI rank(s)\n";
    for (unsigned int i = 0; i < pairs.n_interfaces(); ++i)
      log << "Interface " << interfaces.list()[i].name << ": "
          << pairs.pairs_of(i).size() << " node pairs, area "
          << pairs.area(i) * 1e6 << " mm^2, radial interference "
          << interfaces.list()[i].interference * 1e6 << " um\n";
    log << "Static supports:\n" << description;
    check_interference();
    check_tip_speed();
  }

  void
  StaticProblem::check_interference() const
  {
    // The model is linear elastic in small strain: the interference is a
    // strain delta / r of the fit. Metals leave their elastic range at
    // strains of 0.1 .. 0.5 %; at 1 % the small-strain model itself fails.
    for (unsigned int f = 0; f < pairs.n_interfaces(); ++f)
      {
        double r = 0;
        for (const auto i : pairs.pairs_of(f))
          r += std::hypot(pairs.pairs()[i].position[0], pairs.pairs()[i].position[1]);
        r /= std::max<std::size_t>(1, pairs.pairs_of(f).size());
        const auto  &d      = interfaces.list()[f];
        const double strain = d.interference / r;
        std::ostringstream m;
        m << "Interface " << d.name << "/Radial interference = " << d.interference
          << " m is " << std::setprecision(3) << 100 * strain << " % of the fit radius "
          << r * 1e3 << " mm";
        if (strain > 1e-2)
          throw InputError(m.str() + "; rotorfit's linear small-strain model holds below 1 % "
                                     "(metals yield at 0.1 .. 0.5 %). Check the units (metres, "
                                     "on the radius).");
        if (strain > 2e-3)
          log << "Warning: " << m.str()
              << ": above the elastic limit strain of most shaft and hub alloys (about "
                 "0.2 %); the fit may yield, which a linear elastic model does not see.\n";
      }
  }

  void
  StaticProblem::check_tip_speed() const
  {
    // A speed range that no rotor survives is a units slip (rad/s, Hz
    // or r/min): the rim speed of the largest radius against 2,000 m/s,
    // about twice the burst speed of the strongest metal disks.
    double r_max = 0;
    for (const auto &p : support_points)
      r_max = std::max(r_max, std::hypot(p[0], p[1]));
    const double rpm = speeds.speeds_rpm().back();
    const double tip = SpeedSchedule::rpm_to_rad_per_s(rpm) * r_max;
    if (tip > 2000)
      {
        std::ostringstream m;
        m << std::setprecision(3) << "Speeds: the last speed, " << rpm
          << " r/min, moves the outer radius " << r_max * 1e3 << " mm at " << tip
          << " m/s; no metal rotor survives 2,000 m/s (disks burst at 500 .. 1,000 m/s). "
             "Speeds are in r/min.";
        throw InputError(m.str());
      }
  }

  void
  StaticProblem::compute_support_points()
  {
    // support points through the curved mapping: pairs and supports must
    // see the same geometry as the integrals
    support_points.assign(dof_handler.n_dofs(), Point<3>());
    const Quadrature<3> q(fe->get_unit_support_points());
    FEValues<3> fe_values(mesh.mapping(), *fe, q, update_quadrature_points);
    std::vector<types::global_dof_index> dofs(fe->n_dofs_per_cell());
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        fe_values.reinit(cell);
        cell->get_dof_indices(dofs);
        for (unsigned int i = 0; i < dofs.size(); ++i)
          support_points[dofs[i]] = fe_values.quadrature_point(i);
      }
  }

  void
  StaticProblem::setup_system()
  {
    sparsity.reinit(dof_handler.n_dofs(), dof_handler.n_dofs(), owned);
    std::vector<types::global_dof_index> dofs(fe->n_dofs_per_cell());
    // all cells, not only the owned ones: an owned row may couple to DoFs
    // of cells on other ranks
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        cell->get_dof_indices(dofs);
        constraints.add_entries_local_to_global(dofs, sparsity, false);
      }
    for (const auto &p : pairs.pairs())
      {
        std::vector<types::global_dof_index> d = {p.hub_dofs[0], p.hub_dofs[1],
                                                  p.shaft_dofs[0], p.shaft_dofs[1]};
        constraints.add_entries_local_to_global(d, sparsity, false);
      }
    stiffness.reinit(owned, owned, sparsity, comm);
    if (spin_softening)
      spin_softening_matrix.reinit(owned, owned, sparsity, comm);
    unit_centrifugal_load.reinit(owned, comm);
    stiffness_diagonal.reinit(dof_handler.n_dofs());
  }

  void
  StaticProblem::assemble()
  {
    TimerOutput::Scope t(*timer, "assembly (K, centrifugal load)");
    setup_system();
    // one rule for every volume integral (THEORY 0)
    const QGaussSimplex<3> quadrature(mesh.element_order() + 2);
    FEValues<3>            fe_values(mesh.mapping(),
                          *fe,
                          quadrature,
                          update_values | update_gradients |
                            update_quadrature_points | update_JxW_values);
    const FEValuesExtractors::Vector disp(0);
    const unsigned int               n = fe->n_dofs_per_cell();
    FullMatrix<double>               cell_k(n, n), cell_m(n, n);
    Vector<double>                   cell_f(n);
    std::vector<types::global_dof_index> dofs(n);
    std::vector<SymmetricTensor<2, 3>>   eps(n);
    std::vector<Tensor<1, 3>>            phi(n);
    std::vector<double> mass(bodies.size(), 0.), polar(bodies.size(), 0.);

    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          fe_values.reinit(cell);
          cell->get_dof_indices(dofs);
          const Body  &body   = bodies[cell->material_id()];
          const double lambda = body.lambda(), mu = body.mu(), rho = body.density;
          cell_k = 0;
          cell_m = 0;
          cell_f = 0;
          for (unsigned int q = 0; q < quadrature.size(); ++q)
            {
              const double    JxW = fe_values.JxW(q);
              const Point<3> &x   = fe_values.quadrature_point(q);
              const Tensor<1, 3> r_perp({x[0], x[1], 0.});
              mass[cell->material_id()] += rho * JxW;
              polar[cell->material_id()] += rho * (x[0] * x[0] + x[1] * x[1]) * JxW;
              add_elastic_stiffness(fe_values, q, lambda, mu, cell_k, eps);
              for (unsigned int i = 0; i < n; ++i)
                {
                  phi[i] = fe_values[disp].value(i, q);
                  cell_f(i) += rho * (phi[i] * r_perp) * JxW;
                }
              if (spin_softening)
                for (unsigned int i = 0; i < n; ++i)
                  for (unsigned int j = 0; j < n; ++j)
                    cell_m(i, j) += rho * (phi[i][0] * phi[j][0] + phi[i][1] * phi[j][1]) * JxW;
            }
          for (unsigned int i = 0; i < n; ++i)
            stiffness_diagonal[dofs[i]] += cell_k(i, i);
          constraints.distribute_local_to_global(cell_k, cell_f, dofs, stiffness,
                                                 unit_centrifugal_load);
          if (spin_softening)
            constraints.distribute_local_to_global(cell_m, dofs, spin_softening_matrix);
        }
    stiffness.compress(VectorOperation::add);
    unit_centrifugal_load.compress(VectorOperation::add);
    if (spin_softening)
      spin_softening_matrix.compress(VectorOperation::add);
    Utilities::MPI::sum(stiffness_diagonal, comm, stiffness_diagonal);
    for (unsigned int b = 0; b < bodies.size(); ++b)
      {
        mass[b]  = Utilities::MPI::sum(mass[b], comm);
        polar[b] = Utilities::MPI::sum(polar[b], comm);
      }

    std::ofstream summary;
    if (Utilities::MPI::this_mpi_process(comm) == 0)
      summary.open(output_dir + "/summary.txt", std::ios::app);
    summary << std::setprecision(8);
    log << "Mass properties (curved geometry):\n";
    for (unsigned int b = 0; b < bodies.size(); ++b)
      {
        log << "  body " << bodies[b].name << ": mass " << mass[b]
            << " kg, polar moment of inertia " << polar[b] << " kg m^2\n";
        summary << "body." << bodies[b].name << ".mass_kg " << mass[b] << "\n"
                << "body." << bodies[b].name << ".polar_moment_kgm2 "
                << polar[b] << "\n";
      }
  }

  void
  StaticProblem::run(const SpeedCallback &after_speed)
  {
    assemble();
    const double w_max =
      std::pow(SpeedSchedule::rpm_to_rad_per_s(speeds.speeds_rpm().back()), 2);
    contact.initialize(pairs,
                       constraints,
                       sparsity,
                       stiffness,
                       unit_centrifugal_load,
                       spin_softening ? &spin_softening_matrix : nullptr,
                       stiffness_diagonal,
                       owned,
                       comm,
                       w_max);
    log << "Contact: "
        << (contact.method() == ContactSolver::Method::penalty ? "penalty" :
                                                                  "augmented Lagrangian")
        << ", penalty scale " << contact.penalty_scale() << "; linear solver "
        << contact.linear_solver().name() << "; spin softening "
        << (spin_softening ? "on" : "off") << "\n";
    sweep(after_speed);
  }
} // namespace rotorfit
