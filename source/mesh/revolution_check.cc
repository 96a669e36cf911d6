#include <rotorfit/mesh/revolution_check.h>

#include <deal.II/base/mpi.h>

#include <deal.II/fe/fe_values.h>

#include <cmath>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

  std::vector<double>
  RevolutionCheck::circumferential_share(const AssemblyMesh    &mesh,
                                         const DoFHandler<3>   &dofs,
                                         const unsigned int     n_bodies,
                                         const MPI_Comm         comm)
  {
    std::vector<double>   facing(n_bodies, 0.), area(n_bodies, 0.);
    const Quadrature<2>   rule = mesh.face_rule(3);
    FEFaceValues<3>       fe_face(mesh.mapping(), dofs.get_fe(), rule,
                            update_normal_vectors | update_quadrature_points |
                              update_JxW_values);
    for (const auto &cell : dofs.active_cell_iterators())
      if (cell->is_locally_owned())
        for (const unsigned int f : cell->face_indices())
          if (cell->face(f)->at_boundary())
            {
              fe_face.reinit(cell, f);
              const unsigned int b = cell->material_id();
              for (unsigned int q = 0; q < rule.size(); ++q)
                {
                  const Point<3>     &x = fe_face.quadrature_point(q);
                  const double        r = std::hypot(x[0], x[1]);
                  const Tensor<1, 3> &n = fe_face.normal_vector(q);
                  const double        w = fe_face.JxW(q);
                  area[b] += w;
                  // on the axis e_theta is undefined: such points count as
                  // revolved (end faces cross it with n = e_z)
                  if (r > 0 && std::abs(-n[0] * x[1] + n[1] * x[0]) > 0.5 * r)
                    facing[b] += w;
                }
            }
    std::vector<double> share(n_bodies, 0.);
    for (unsigned int b = 0; b < n_bodies; ++b)
      {
        const double a = Utilities::MPI::sum(area[b], comm);
        share[b]       = a > 0 ? Utilities::MPI::sum(facing[b], comm) / a : 0.;
      }
    return share;
  }

  std::vector<RevolutionCheck::Inertia>
  RevolutionCheck::transverse_inertia(const AssemblyMesh  &mesh,
                                      const DoFHandler<3> &dofs,
                                      const unsigned int   n_bodies,
                                      const MPI_Comm       comm)
  {
    // per body: V, int x, int y, J_xx, J_yy, J_xy
    std::vector<double> m(6 * n_bodies, 0.);
    const auto         &rule = mesh.cell_quadrature();
    FEValues<3> fe_values(mesh.mapping(), dofs.get_fe(), rule,
                          update_quadrature_points | update_JxW_values);
    for (const auto &cell : dofs.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          fe_values.reinit(cell);
          double *b = &m[6 * cell->material_id()];
          for (unsigned int q = 0; q < rule.size(); ++q)
            {
              const Point<3> &x = fe_values.quadrature_point(q);
              const double    w = fe_values.JxW(q);
              b[0] += w;
              b[1] += w * x[0];
              b[2] += w * x[1];
              b[3] += w * x[0] * x[0];
              b[4] += w * x[1] * x[1];
              b[5] += w * x[0] * x[1];
            }
        }
    Utilities::MPI::sum(m, comm, m);
    std::vector<Inertia> result(n_bodies);
    for (unsigned int k = 0; k < n_bodies; ++k)
      {
        const double *b = &m[6 * k];
        if (!(b[0] > 0))
          continue;
        // about the axis, not the centroid: the whirl turns the body about z
        const double jxx = b[3], jyy = b[4], jxy = b[5];
        result[k].volume     = b[0];
        result[k].offset     = std::hypot(b[1], b[2]) / b[0];
        result[k].gyration   = std::sqrt((jxx + jyy) / b[0]);
        result[k].anisotropy = jxx + jyy > 0 ? std::hypot(jxx - jyy, 2 * jxy) / (jxx + jyy) : 0.;
      }
    return result;
  }

  std::string
  RevolutionCheck::describe(const std::vector<double>  &share,
                            const std::vector<Inertia> &inertia,
                            const Bodies               &bodies)
  {
    std::ostringstream log;
    for (unsigned int b = 0; b < share.size(); ++b)
      if (share[b] > limit)
        log << "Body " << bodies[b].name << ": " << 100 * share[b]
            << " % of its surface faces the circumferential direction: not a body of "
               "revolution; the stationary frame holds above 0 r/min only for the modes that "
               "move it rigidly (doc/bladed_impeller.md)\n";
    for (unsigned int b = 0; b < inertia.size(); ++b)
      {
        const auto &i = inertia[b];
        if (i.anisotropy > anisotropy_limit)
          log << "Body " << bodies[b].name << ": its second moments about the axis are "
              << "anisotropic (" << i.anisotropy
              << " = |J_xx - J_yy, 2 J_xy| / (J_xx + J_yy): a flat, a keyway, one or two "
                 "blades, an elliptic section); the stationary frame holds above 0 r/min for "
                 "none of its modes, the whirl included (doc/theory.md 4.1)\n";
        if (i.offset > offset_limit * i.gyration)
          log << "Body " << bodies[b].name << ": its centroid lies " << i.offset * 1e3
              << " mm off the axis: a static unbalance of " << bodies[b].density * i.volume * i.offset
              << " kg m that the Unbalances do not include and the eigenproblem does not see\n";
      }
    return log.str();
  }
} // namespace rotorfit
