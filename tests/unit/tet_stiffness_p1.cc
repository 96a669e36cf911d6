// add_elastic_stiffness, summed over the code's quadrature rule (QGaussSimplex
// of degree + 2) on one skewed linear tetrahedron, equals the closed-form
// constant-strain stiffness V B^T D B; lambda and mu from Body, D from E and nu.

#include <rotorfit/material/bodies.h>
#include <rotorfit/material/elasticity.h>

#include <deal.II/base/quadrature_lib.h>

#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe.h>

#include <deal.II/grid/tria.h>

#include "tet_closed_forms.h"
#include "unit_check.h"

using namespace dealii;
using namespace rotorfit_unit;

int
main()
{
  Checks check;
  const double E = 205e9, nu = 0.3;
  const rotorfit::Body body{"steel", "steel", E, nu, 7850.};

  const std::vector<Point<3>> x = skewed_tet();
  Triangulation<3>            tria;
  std::vector<CellData<3>>    cells(1, CellData<3>(4));
  cells[0].vertices = {0, 1, 2, 3};
  tria.create_triangulation(x, cells, SubCellData());
  const auto cell = tria.begin_active();

  const FESystem<3>      fe(FE_SimplexP<3>(1), 3);
  const MappingFE<3>     mapping(FE_SimplexP<3>(1));
  const QGaussSimplex<3> quadrature(fe.degree + 2); // the rule of the code
  FEValues<3> fe_values(mapping, fe, quadrature, update_gradients | update_JxW_values);
  fe_values.reinit(cell);

  const unsigned int n = fe.n_dofs_per_cell();
  FullMatrix<double> K(n, n);
  std::vector<SymmetricTensor<2, 3>> eps;
  for (unsigned int q = 0; q < quadrature.size(); ++q)
    rotorfit::add_elastic_stiffness(fe_values, q, body.lambda(), body.mu(), K, eps);

  // component and vertex of each DoF: the vertex at the DoF's support point
  std::vector<unsigned int> c, v;
  rotorfit_unit::components_and_vertices(fe, mapping, cell, x, c, v);

  const FullMatrix<double> K_ref = cst_stiffness(x, c, v, E, nu);
  check.relative("volume from JxW", [&] {
    double V = 0;
    for (unsigned int q = 0; q < quadrature.size(); ++q)
      V += fe_values.JxW(q);
    return V;
  }(), tet_volume(x), 1e-14, "closed form det(J)/6");
  check.error("max |K - V B^T D B| / max |V B^T D B| (12 x 12)", relative_max_difference(K, K_ref),
              1e-12, "closed form V B^T D B");
  check.relative("K(0,0)", K(0, 0), K_ref(0, 0), 1e-12, "closed form V B^T D B");
  return check.finish();
}
