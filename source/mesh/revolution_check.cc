#include <rotorfit/mesh/revolution_check.h>

#include <deal.II/base/mpi.h>

#include <deal.II/fe/fe_values.h>

#include <cmath>

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
} // namespace rotorfit
