#include <rotorfit/base/format.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/base/resources.h>
#include <rotorfit/problem/case_checks.h>
#include <rotorfit/statics/speed_schedule.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <sstream>

namespace rotorfit::case_checks
{
  using namespace dealii;

  void
  surface_use(const Discretization &model, const Bearings &bearings, Log &log)
  {
    // two interfaces on one surface halve the contact pressure, two
    // bearings on one face double the stiffness: refused. An axial roller
    // on a fit surface is legitimate for verification set-ups: warned.
    std::map<std::string, std::string> owner; // surface -> first feature
    const auto claim = [&](const std::string &surface, const std::string &feature,
                           const std::string &fix) {
      const auto [it, inserted] = owner.emplace(surface, feature);
      if (!inserted && it->second != feature)
        throw InputError("physical surface '" + surface + "' is used by " + it->second +
                         " and by " + feature + "; " + fix);
    };
    const std::string one_interface = "each fit surface belongs to one interface (a second one "
                                      "would halve its contact pressure).";
    for (const auto &f : model.interfaces().list())
      {
        claim(f.shaft_surface, "Interface " + f.name, one_interface);
        if (f.hub_surface != f.shaft_surface)
          claim(f.hub_surface, "Interface " + f.name, one_interface);
      }
    for (const auto &b : bearings.list())
      if (!b.station.is_band()) // a band is checked against the fits on the mesh
      claim(b.station.surface, "Bearing " + b.name,
            "a bearing acts on a shaft surface of its own (a fit surface is "
            "inside the assembly; two bearings on one face double its "
            "stiffness: add their coefficients into one bearing).");
    for (const auto &r : model.roller_surfaces())
      {
        const auto it = owner.find(r);
        if (it != owner.end() && it->second.rfind("Interface", 0) == 0)
          log << "Warning: Supports/Axial roller surfaces: '" << r << "' is a fit surface of "
              << it->second << "; its nodes are held axially.\n";
      }
  }

  void
  tip_speed(const Discretization &model, const double rpm, Log &log)
  {
    // A speed range that no rotor survives is a units slip (rad/s, Hz or
    // r/min): the rim speed of the largest radius against 2,000 m/s, about
    // twice the burst speed of the strongest metal disks.
    const double r_max = model.outer_radius();
    const double tip   = SpeedSchedule::rpm_to_rad_per_s(rpm) * r_max;
    if (tip > 2000)
      {
        std::ostringstream m;
        m << std::setprecision(3) << "Speeds: the last speed, " << rpm
          << " r/min, moves the outer radius " << r_max * 1e3 << " mm at " << tip
          << " m/s; no metal rotor survives 2,000 m/s (disks burst at 500 .. 1,000 m/s). "
             "Speeds are in r/min.";
        throw InputError(m.str());
      }
    // Below that, a rim speed in the burst range of metal disks: at 500 m/s
    // a free rotating ring's hoop stress rho v^2 is 2.0 GPa in steel, 1.1 in
    // titanium, 0.7 in aluminium, the strength of their strongest alloys; a
    // solid disk's peak, (3 + nu)/8 of it, gets there at about 1.6 x that
    // speed. Warned per body (its own radius and density).
    std::vector<double> r_body(model.bodies().size(), 0.);
    for (const auto &cell : model.mesh().triangulation().active_cell_iterators())
      for (const unsigned int v : cell->vertex_indices())
        r_body[cell->material_id()] =
          std::max(r_body[cell->material_id()], std::hypot(cell->vertex(v)[0], cell->vertex(v)[1]));
    for (unsigned int b = 0; b < r_body.size(); ++b)
      {
        const double v = SpeedSchedule::rpm_to_rad_per_s(rpm) * r_body[b];
        if (!(v > 500))
          continue;
        const double       rho = model.bodies()[b].density;
        std::ostringstream m;
        m << std::setprecision(3) << "Warning: Speeds: the last speed, " << format_number(rpm)
          << " r/min, moves the rim of body " << model.bodies()[b].name << " (r "
          << r_body[b] * 1e3 << " mm) at " << v << " m/s, above 500 m/s, where metal disks "
          << "begin to burst: a free rotating ring there carries the hoop stress rho v^2 = "
          << rho * v * v / 1e9 << " GPa (" << format_number(rho)
          << " kg/m^3; a solid disk about 0.41 of it), and at 500 m/s already 2.0 GPa in "
             "steel, 0.7 GPa in aluminium, the strength of their strongest alloys. "
             "rotorfit does not check strength: check the burst margin, and that the "
             "speeds are in r/min.\n";
        log << m.str();
      }
  }

  void
  resources(const Discretization          &model,
            const PrestressedEigenproblem &eigen,
            const MPI_Comm                 comm,
            Log                           &log)
  {
    using namespace rotorfit::resources;
    const double n       = model.dofs().n_dofs();
    const double statics = factorization_bytes(n, true) + 3 * sparse_matrix_bytes(n);
    double       modes   = 0;
    if (eigen.enabled())
      // K and the tangent on the full pattern; M, G, C, K_sigma(u_C) and
      // K_theta couple each component only with itself (a third of it)
      modes = factorization_bytes(n, false) + (2 + 5 / 3.) * sparse_matrix_bytes(n) +
              // the Arnoldi vectors are replicated on every rank
              Utilities::MPI::n_mpi_processes(comm) * eigen.state_vectors_needed(n) * 2 * n * 8.;
    const double peak = std::max(statics, modes);
    // rank 0 decides for all (ranks may see other environments or nodes)
    const double limit = Utilities::MPI::broadcast(comm, model.memory_limit(), 0);
    log << "Memory estimate: " << gigabytes(peak) << " at the peak ("
        << (modes > statics ? "eigenproblem" : "static solve") << "), machine "
        << gigabytes(limit) << '\n';
    if (peak > 0.9 * limit)
      throw InputError("the model (" + std::to_string(static_cast<long long>(n)) +
                       " DOFs) needs about " + gigabytes(peak) + " at its peak (" +
                       (modes > statics ? "the eigenproblem's LU and Krylov space" :
                                          "the static factorisation") +
                       ") but this run may use " + gigabytes(limit) +
                       " (Resources/Memory limit)" +
                       "; coarsen the mesh, or lower Eigenproblem/Number of modes or Krylov "
                       "size factor.");
  }
} // namespace rotorfit::case_checks
