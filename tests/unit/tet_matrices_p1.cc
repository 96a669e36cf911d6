// RotorMatrices::assemble (the dynamic M and K, with the code's quadrature
// rule and a Body parsed like an input file) on one skewed linear
// tetrahedron: M equals the consistent P1 mass rho V/20 (1 + delta_vw) per
// component, K the constant-strain stiffness V B^T D B.

#include <rotorfit/eigen/rotor_matrices.h>
#include <rotorfit/material/bodies.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/quadrature_lib.h>

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>

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
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  Checks check;
  const double E = 205e9, nu = 0.3, rho = 7850;

  ParameterHandler prm;
  rotorfit::Bodies::declare_list(prm);
  prm.parse_input_from_string("set Bodies = steel\n");
  rotorfit::Bodies::declare_parameters(prm, {"steel"});
  prm.parse_input_from_string("set Bodies = steel\n"
                              "subsection Body steel\n"
                              "  set Young's modulus = 205e9\n"
                              "  set Poisson's ratio = 0.3\n"
                              "  set Density = 7850\n"
                              "end\n");
  rotorfit::Bodies bodies;
  bodies.parse_parameters(prm);

  const std::vector<Point<3>> x = skewed_tet();
  Triangulation<3>            tria;
  std::vector<CellData<3>>    cells(1, CellData<3>(4));
  cells[0].vertices = {0, 1, 2, 3};
  tria.create_triangulation(x, cells, SubCellData()); // material_id 0: body 0

  const FESystem<3>  fe(FE_SimplexP<3>(1), 3);
  const MappingFE<3> mapping(FE_SimplexP<3>(1));
  DoFHandler<3>      dof_handler(tria);
  dof_handler.distribute_dofs(fe);
  const unsigned int     n = dof_handler.n_dofs();
  DynamicSparsityPattern sparsity(n);
  DoFTools::make_sparsity_pattern(dof_handler, sparsity);

  rotorfit::RotorMatrices matrices;
  matrices.reinit(complete_index_set(n), sparsity, MPI_COMM_WORLD);
  matrices.assemble(dof_handler, mapping, QGaussSimplex<3>(3), bodies); // the code's rule for P1: order + 2

  // local matrices in cell DoF order; component and vertex of each DoF
  const auto                           cell = dof_handler.begin_active();
  std::vector<types::global_dof_index> dofs(n);
  cell->get_dof_indices(dofs);
  FullMatrix<double> M(n, n), K(n, n);
  for (unsigned int i = 0; i < n; ++i)
    for (unsigned int j = 0; j < n; ++j)
      {
        M(i, j) = matrices.mass.el(dofs[i], dofs[j]);
        K(i, j) = matrices.stiffness.el(dofs[i], dofs[j]);
      }
  std::vector<unsigned int> c, v;
  rotorfit_unit::components_and_vertices(fe, mapping, cell, x, c, v);

  const double V = tet_volume(x);
  double       total = 0;
  for (unsigned int i = 0; i < n; ++i)
    for (unsigned int j = 0; j < n; ++j)
      if (c[i] == 0 && c[j] == 0)
        total += M(i, j);
  check.relative("sum of the x-component block of M", total, rho * V, 1e-13,
                 "closed form rho V");
  check.error("max |M - rho V/20 (1 + delta)| / max |M_ref| (12 x 12)",
              relative_max_difference(M, p1_mass(x, c, v, rho)), 1e-13,
              "closed form rho V/20 (1 + delta_vw) per component");
  check.error("max |K - V B^T D B| / max |V B^T D B| (12 x 12)",
              relative_max_difference(K, cst_stiffness(x, c, v, E, nu)), 1e-12,
              "closed form V B^T D B");
  return check.finish();
}
