#pragma once

// Closed forms of a straight-sided linear tetrahedron, written without
// deal.II's finite elements: the references of the element-matrix tests.

#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>

#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping.h>

#include <deal.II/lac/full_matrix.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace rotorfit_unit
{
  using dealii::Point;
  using dealii::Tensor;

  /// A skewed tetrahedron (positive orientation), no face or edge aligned with an axis.
  inline std::vector<Point<3>>
  skewed_tet()
  {
    return {Point<3>(0.1, 0.0, 0.05),
            Point<3>(1.3, 0.2, -0.1),
            Point<3>(0.3, 0.9, 0.2),
            Point<3>(0.2, 0.35, 1.1)};
  }

  /// Jacobian of x(xi) = x0 + J xi (columns x_k - x0).
  inline Tensor<2, 3>
  tet_jacobian(const std::vector<Point<3>> &x)
  {
    Tensor<2, 3> J;
    for (unsigned int k = 0; k < 3; ++k)
      for (unsigned int d = 0; d < 3; ++d)
        J[d][k] = x[k + 1][d] - x[0][d];
    return J;
  }

  inline double
  tet_volume(const std::vector<Point<3>> &x)
  {
    return determinant(tet_jacobian(x)) / 6.;
  }

  /// Gradients of the barycentric coordinates lambda_v (v = vertex):
  /// lambda_{1,2,3} = rows of J^-1 applied to x - x0, lambda_0 = 1 - sum.
  inline std::array<Tensor<1, 3>, 4>
  barycentric_gradients(const std::vector<Point<3>> &x)
  {
    const Tensor<2, 3>            Jinv = invert(tet_jacobian(x));
    std::array<Tensor<1, 3>, 4> g;
    for (unsigned int k = 0; k < 3; ++k)
      {
        for (unsigned int d = 0; d < 3; ++d)
          g[k + 1][d] = Jinv[k][d];
        g[0] -= g[k + 1];
      }
    return g;
  }

  /**
   * Constant-strain stiffness V B^T D B of the 12 DoFs (component c[i],
   * vertex v[i]); Voigt strains (xx, yy, zz, 2yz, 2xz, 2xy) and the
   * isotropic D written with E and nu.
   */
  inline dealii::FullMatrix<double>
  cst_stiffness(const std::vector<Point<3>>     &x,
                const std::vector<unsigned int> &c,
                const std::vector<unsigned int> &v,
                const double                     E,
                const double                     nu)
  {
    const auto         g = barycentric_gradients(x);
    const unsigned int n = c.size();
    dealii::FullMatrix<double> B(6, n), D(6, 6), DB(6, n), K(n, n);
    for (unsigned int i = 0; i < n; ++i)
      {
        const Tensor<1, 3> &gi = g[v[i]];
        const unsigned int  a  = c[i];
        B(a, i) = gi[a];
        // engineering shear strains: 2 eps_yz, 2 eps_xz, 2 eps_xy
        const unsigned int pairs[3][2] = {{1, 2}, {0, 2}, {0, 1}};
        for (unsigned int s = 0; s < 3; ++s)
          {
            if (pairs[s][0] == a)
              B(3 + s, i) = gi[pairs[s][1]];
            if (pairs[s][1] == a)
              B(3 + s, i) = gi[pairs[s][0]];
          }
      }
    const double f = E / ((1 + nu) * (1 - 2 * nu));
    for (unsigned int a = 0; a < 3; ++a)
      {
        for (unsigned int b = 0; b < 3; ++b)
          D(a, b) = f * (a == b ? 1 - nu : nu);
        D(3 + a, 3 + a) = f * (1 - 2 * nu) / 2;
      }
    D.mmult(DB, B);
    B.Tmmult(K, DB);
    K *= tet_volume(x);
    return K;
  }

  /// Consistent P1 mass rho V/20 (1 + delta_vw) between equal components.
  inline dealii::FullMatrix<double>
  p1_mass(const std::vector<Point<3>>     &x,
          const std::vector<unsigned int> &c,
          const std::vector<unsigned int> &v,
          const double                     rho)
  {
    const unsigned int         n = c.size();
    const double               V = tet_volume(x);
    dealii::FullMatrix<double> M(n, n);
    for (unsigned int i = 0; i < n; ++i)
      for (unsigned int j = 0; j < n; ++j)
        if (c[i] == c[j])
          M(i, j) = rho * V / 20 * (v[i] == v[j] ? 2 : 1);
    return M;
  }

  /// max |A - B| / max |B|.
  inline double
  relative_max_difference(const dealii::FullMatrix<double> &A, const dealii::FullMatrix<double> &B)
  {
    double diff = 0, scale = 0;
    for (unsigned int i = 0; i < B.m(); ++i)
      for (unsigned int j = 0; j < B.n(); ++j)
        {
          const double d = std::abs(A(i, j) - B(i, j));
          if (!(d <= diff)) // keeps a NaN
            diff = d;
          scale = std::max(scale, std::abs(B(i, j)));
        }
    return diff / scale;
  }
  /// Component @p c[i] and vertex @p v[i] (of the points @p x) of each DoF
  /// i of a P1 vector element on @p cell: the vertex at its support point.
  template <typename Cell>
  void
  components_and_vertices(const dealii::FESystem<3>                 &fe,
                          const dealii::Mapping<3>                  &mapping,
                          const Cell                                &cell,
                          const std::vector<dealii::Point<3>>       &x,
                          std::vector<unsigned int>                 &c,
                          std::vector<unsigned int>                 &v)
  {
    const unsigned int            n = fe.n_dofs_per_cell();
    const dealii::Quadrature<3>   nodes(fe.base_element(0).get_unit_support_points());
    dealii::FEValues<3>           at_nodes(mapping, fe.base_element(0), nodes,
                                 dealii::update_quadrature_points);
    at_nodes.reinit(cell);
    c.assign(n, 0);
    v.assign(n, 0);
    for (unsigned int i = 0; i < n; ++i)
      {
        const auto [comp, k] = fe.system_to_component_index(i);
        c[i]                 = comp;
        for (unsigned int w = 0; w < 4; ++w)
          if (at_nodes.quadrature_point(k).distance(x[w]) < 1e-12)
            v[i] = w;
      }
  }
} // namespace rotorfit_unit
