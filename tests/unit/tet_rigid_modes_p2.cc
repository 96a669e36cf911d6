// The quadratic-element stiffness of add_elastic_stiffness (the code's rule
// QGaussSimplex(degree + 2)) annihilates the six rigid-body modes on a
// skewed affine tetrahedron and on the same tetrahedron with a curved edge
// (quadratic geometry through MappingFEField, as the code maps every cell):
// K r = 0 to round-off, and K has no other zero-energy mode (rank 30 - 6).

#include <rotorfit/material/bodies.h>
#include <rotorfit/material/elasticity.h>

#include <deal.II/base/quadrature_lib.h>

#include <deal.II/dofs/dof_handler.h>

#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/fe/mapping_fe_field.h>

#include <deal.II/grid/tria.h>

#include <deal.II/lac/lapack_full_matrix.h>
#include <deal.II/lac/vector.h>

#include <algorithm>

#include "tet_closed_forms.h"
#include "unit_check.h"

using namespace dealii;
using namespace rotorfit_unit;

namespace
{
  const double E = 205e9, nu = 0.3;

  /// max_i |(K r)_i| / (max row sum |K| max |r|): <= 1 for any r, 0 for r in the kernel.
  double
  kernel_error(const FullMatrix<double> &K, const Vector<double> &r)
  {
    Vector<double> Kr(r.size());
    K.vmult(Kr, r);
    double row_max = 0;
    for (unsigned int i = 0; i < K.m(); ++i)
      {
        double row = 0;
        for (unsigned int j = 0; j < K.n(); ++j)
          row += std::abs(K(i, j));
        row_max = std::max(row_max, row);
      }
    return Kr.linfty_norm() / (row_max * r.linfty_norm());
  }

  /// K of one cell and the physical support point of each DoF.
  void
  check_cell(Checks &check, const std::string &name, const Mapping<3> &mapping,
             const DoFHandler<3> &dof_handler)
  {
    const auto            &fe   = dof_handler.get_fe();
    const auto             cell = dof_handler.begin_active();
    const rotorfit::Body   body{"steel", "steel", E, nu, 7850.};
    const QGaussSimplex<3> quadrature(fe.degree + 2);
    FEValues<3> fe_values(mapping, fe, quadrature, update_gradients | update_JxW_values);
    fe_values.reinit(cell);
    const unsigned int n = fe.n_dofs_per_cell();
    FullMatrix<double> K(n, n);
    std::vector<SymmetricTensor<2, 3>> eps;
    for (unsigned int q = 0; q < quadrature.size(); ++q)
      {
        if (!(fe_values.JxW(q) > 0))
          check.error(name + ": JxW > 0 at every point", 1, 0, "valid cell");
        rotorfit::add_elastic_stiffness(fe_values, q, body.lambda(), body.mu(), K, eps);
      }

    const Quadrature<3> nodes(fe.base_element(0).get_unit_support_points());
    FEValues<3>         at_nodes(mapping, fe.base_element(0), nodes, update_quadrature_points);
    at_nodes.reinit(cell);
    // rigid modes: translations e_a and rotations e_a x (x - x_c)
    const Point<3> xc(0.4, 0.3, 0.2);
    const char    *names[6] = {"translation x", "translation y", "translation z",
                               "rotation about x", "rotation about y", "rotation about z"};
    for (unsigned int m = 0; m < 6; ++m)
      {
        Vector<double> r(n);
        for (unsigned int i = 0; i < n; ++i)
          {
            const auto [c, k] = fe.system_to_component_index(i);
            Tensor<1, 3> e;
            e[m % 3] = 1;
            const Tensor<1, 3> value =
              m < 3 ? e : cross_product_3d(e, at_nodes.quadrature_point(k) - xc);
            r[i] = value[c];
          }
        check.error(name + ": |K r| / (|K| |r|), " + names[m], kernel_error(K, r), 1e-13,
                    "exact identity K r = 0");
      }
    // sensitivity of the measure: a uniform stretch is not in the kernel
    Vector<double> stretch(n);
    for (unsigned int i = 0; i < n; ++i)
      {
        const auto [c, k] = fe.system_to_component_index(i);
        if (c == 0)
          stretch[i] = at_nodes.quadrature_point(k)[0];
      }
    const double s = kernel_error(K, stretch);
    check.equal(name + ": |K r| / (|K| |r|) of a uniform stretch above 1e-3 (" +
                  std::to_string(s) + ")",
                s > 1e-3, true, "guard: the measure sees strain");

    // no further zero-energy mode: exactly 6 eigenvalues below 1e-10 of the largest
    LAPACKFullMatrix<double> KL(n);
    KL = K;
    KL.compute_eigenvalues();
    std::vector<double> ev(n);
    for (unsigned int i = 0; i < n; ++i)
      ev[i] = std::abs(KL.eigenvalue(i));
    std::sort(ev.begin(), ev.end());
    unsigned int zero = 0;
    for (const double e : ev)
      zero += (e < 1e-10 * ev.back());
    std::printf("  %s: smallest eigenvalues / largest: %.2e (6th), %.2e (7th)\n", name.c_str(),
                ev[5] / ev.back(), ev[6] / ev.back());
    check.equal(name + ": eigenvalues below 1e-10 of the largest", zero, 6u,
                "exact identity: kernel = rigid modes");
  }
} // namespace

int
main()
{
  Checks check;

  // skewed tetrahedron under a further stretch-and-shear map (det > 0)
  std::vector<Point<3>> x = skewed_tet();
  const double          A[3][3] = {{3, 0.5, 0.2}, {0.1, 0.4, -0.3}, {0.2, 0.1, 1.5}};
  for (auto &p : x)
    {
      Point<3> q(-0.2, 0.7, 0.1);
      for (unsigned int a = 0; a < 3; ++a)
        for (unsigned int b = 0; b < 3; ++b)
          q[a] += A[a][b] * p[b];
      p = q;
    }
  Triangulation<3>         tria;
  std::vector<CellData<3>> cells(1, CellData<3>(4));
  cells[0].vertices = {0, 1, 2, 3};
  tria.create_triangulation(x, cells, SubCellData());

  const FESystem<3> fe(FE_SimplexP<3>(2), 3);
  DoFHandler<3>     dof_handler(tria);
  dof_handler.distribute_dofs(fe);

  // (a) affine
  const MappingFE<3> affine(FE_SimplexP<3>(1));
  check_cell(check, "affine P2", affine, dof_handler);

  // (b) curved: the quadratic position field of the code's meshes with one
  // mid-edge node off its straight edge
  DoFHandler<3> position_dofs(tria);
  position_dofs.distribute_dofs(fe);
  Vector<double> positions(position_dofs.n_dofs());
  {
    const auto          cell = position_dofs.begin_active();
    const Quadrature<3> nodes(fe.base_element(0).get_unit_support_points());
    FEValues<3>         at_nodes(affine, fe.base_element(0), nodes, update_quadrature_points);
    at_nodes.reinit(cell);
    std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
    cell->get_dof_indices(dofs);
    // the midpoint of edge x0-x1 moved outwards (away from the centroid,
    // normal to the edge) by 10 % of the edge length
    const Point<3>     mid      = 0.5 * (x[0] + x[1]);
    const Tensor<1, 3> edge     = (x[1] - x[0]) / x[0].distance(x[1]);
    Tensor<1, 3>       outwards = mid - 0.25 * (x[0] + x[1] + x[2] + x[3]);
    outwards -= (outwards * edge) * edge;
    const Tensor<1, 3> shift = 0.1 * x[0].distance(x[1]) * outwards / outwards.norm();
    bool               moved = false;
    for (unsigned int i = 0; i < dofs.size(); ++i)
      {
        const auto [c, k] = fe.system_to_component_index(i);
        Point<3> p        = at_nodes.quadrature_point(k);
        if (p.distance(mid) < 1e-12)
          {
            p += shift;
            moved = true;
          }
        positions[dofs[i]] = p[c];
      }
    check.equal("curved P2: a mid-edge node was moved", moved, true, "set-up");
  }
  const MappingFEField<3, 3, Vector<double>> curved(position_dofs, positions);
  check_cell(check, "curved P2", curved, dof_handler);

  return check.finish();
}
