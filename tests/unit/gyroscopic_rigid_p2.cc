// The gyroscopic matrix G and the convective stiffness K_theta of
// RotorMatrices::assemble (and the -K_theta of assemble_stress_stiffness's
// K_t2 path), with the code's mappings and rules, on single quadratic
// elements: an affine P2 tetrahedron, a curved P2 tetrahedron (one face on
// the cylinder r = R, quadratic geometry through MappingFEField as the gmsh
// meshes) and a Q2 hexahedron that is a sector of a thick ring (MappingQ(2)
// on the (r, theta, z) chart, as the section mesher's ring cells).
//
// Definitions (doc/theory.md 0, 4.3): spin about +z, t = e_z x x = (-y, x, 0),
// d_theta w = (grad w) t, G_ij = 2 int rho phi_i . d_theta phi_j, kept
// skew cell by cell (G <- (G - G^T)/2, P4), (K_theta)_ij = int rho
// d_theta phi_i . d_theta phi_j. The rigid fields w = a + beta x x are
// exactly in the quadratic (isoparametric) spaces, so with their nodal
// vectors r_w:
//   r_v^T G r_w       = int rho (v . d_theta w - w . d_theta v) dV
//                       (the skew part of 2 int rho v . d_theta w: on one
//                       cell the symmetric part, a face integral with
//                       t.n != 0, is not zero and is dropped)
//   r_v^T K_theta r_w = int rho d_theta v . d_theta w dV
//   r_v^T M r_w       = int rho v . w dV,      d_theta (a + beta x x) = beta x t.
// For the modes T_x, T_y, T_z (translations) and R_x, R_y, R_z (e_k x x,
// rotations about the axes through the origin) the integrands are quadratic
// in x, and with the element's moments m0 = int rho, m_k = int rho x_k,
// m_kl = int rho x_k x_l (no symmetry of the element assumed):
//   G(R_x, R_y) = m_xx + m_yy = I_p (the element's polar moment, sign +:
//                 tilt about x against tilt about y, doc/theory.md 4.5)
//   G(R_x, R_z) = m_yz,  G(R_y, R_z) = -m_xz,
//   G(T_x, R_z) = -m_x,  G(T_y, R_z) = -m_y,  G(T_z, R_x) = m_x,  G(T_z, R_y) = m_y,
//   G skew, every other entry 0;
//   K_theta(R_x, R_x) = m_xx,  K_theta(R_y, R_y) = m_yy,  K_theta(R_x, R_y) = m_xy,
//   K_theta(R_z, R_z) = m_xx + m_yy = I_p, every other entry 0 (nothing on
//   translations: K_theta r_T = 0 as a vector, and no tilt-twist coupling);
//   M(T_a, T_a) = m0, M(T_a, R_b) = e_a . (e_b x m_1),
//   M(R_a, R_b) = delta_ab (m_xx + m_yy + m_zz) - m_ab.
// Checks, per element:
//  (a) the forms of the assembled matrices against the definitions'
//      integrands (the analytic rigid fields, no shape function) summed with
//      the code's rule at its own points: an exact identity, 1e-12;
//  (b) the same forms against the table above with closed-form moments:
//      affine tetrahedron: the vertex formula int x_k x_l = V/20 (sum_v
//      x_vk x_vl + s_k s_l), s = sum of the vertices; curved tetrahedron:
//      exact integration of the P2 map's polynomial integrand (rho x_k x_l
//      det J, degree 7, monomials xi^a = a!b!c!/(a+b+c+3)! on the unit
//      tetrahedron), which the code's rule (QGaussSimplex(4)) integrates
//      exactly: 1e-12; ring sector r in [a, b], theta in [t0, t1], z in
//      [z0, z1]: V = (b^2 - a^2)/2 (t1 - t0) h, m_xx + m_yy = (b^4 - a^4)/4
//      (t1 - t0) h, ... (sector_moments below); the Q2 map only approximates
//      the arcs and QGauss(3) is not exact on it, so this comparison has a
//      tolerance from the observed geometric and quadrature error (printed
//      as its two parts).
// The tetrahedra are body 0 (rho 7850), the hexahedron body 1 (rho 4430):
// rho is the cell's body's. Every matrix comparison is max |A_vw - A_ref,vw| / sqrt(M_ref,vv M_ref,ww)
// over the 6 x 6 modes (dimensionless; the forms of M, G and K_theta have
// the same units).

#include <rotorfit/eigen/rotor_matrices.h>
#include <rotorfit/material/bodies.h>
#include <rotorfit/mesh/cylindrical_chart.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/quadrature_lib.h>

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>

#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe_field.h>
#include <deal.II/fe/mapping_q.h>

#include <deal.II/grid/manifold.h>
#include <deal.II/grid/reference_cell.h>
#include <deal.II/grid/tria.h>

#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/petsc_vector.h>
#include <deal.II/lac/vector.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "unit_check.h"

using namespace dealii;
using namespace rotorfit_unit;

namespace
{
  constexpr unsigned int n_modes = 6;
  const char *mode_name[n_modes] = {"T_x", "T_y", "T_z", "R_x", "R_y", "R_z"};

  /// Rigid mode m: a + beta x x (T_x, T_y, T_z, then e_k x x).
  Tensor<1, 3>
  mode_value(const unsigned int m, const Point<3> &x)
  {
    Tensor<1, 3> e;
    e[m % 3] = 1;
    return m < 3 ? e : cross_product_3d(e, x);
  }

  /// d_theta of mode m: beta x t, t = e_z x x (0 for a translation).
  Tensor<1, 3>
  mode_d_theta(const unsigned int m, const Point<3> &x)
  {
    if (m < 3)
      return Tensor<1, 3>();
    Tensor<1, 3> e;
    e[m % 3] = 1;
    const Tensor<1, 3> t({-x[1], x[0], 0.});
    return cross_product_3d(e, t);
  }

  /// m0 = int rho, m1 = int rho x, m2 = int rho x x^T.
  struct Moments
  {
    double       m0 = 0;
    Tensor<1, 3> m1;
    Tensor<2, 3> m2;
  };

  /// The 6 x 6 forms of M, G and K_theta from the moments (the table above).
  struct Forms
  {
    FullMatrix<double> M{n_modes, n_modes}, G{n_modes, n_modes}, K{n_modes, n_modes};
  };

  Forms
  table_forms(const Moments &m)
  {
    const double m0 = m.m0, mx = m.m1[0], my = m.m1[1], mz = m.m1[2];
    const double xx = m.m2[0][0], yy = m.m2[1][1], zz = m.m2[2][2];
    const double xy = m.m2[0][1], xz = m.m2[0][2], yz = m.m2[1][2];
    Forms        f;
    const auto   sym = [](FullMatrix<double> &A, unsigned int i, unsigned int j, double v) {
      A(i, j) = v;
      A(j, i) = v;
    };
    const auto skew = [](FullMatrix<double> &A, unsigned int i, unsigned int j, double v) {
      A(i, j) = v;
      A(j, i) = -v;
    };
    enum
    {
      Tx,
      Ty,
      Tz,
      Rx,
      Ry,
      Rz
    };
    for (unsigned int a = 0; a < 3; ++a)
      f.M(a, a) = m0;
    sym(f.M, Tx, Ry, mz);
    sym(f.M, Tx, Rz, -my);
    sym(f.M, Ty, Rx, -mz);
    sym(f.M, Ty, Rz, mx);
    sym(f.M, Tz, Rx, my);
    sym(f.M, Tz, Ry, -mx);
    f.M(Rx, Rx) = yy + zz;
    f.M(Ry, Ry) = xx + zz;
    f.M(Rz, Rz) = xx + yy;
    sym(f.M, Rx, Ry, -xy);
    sym(f.M, Rx, Rz, -xz);
    sym(f.M, Ry, Rz, -yz);

    skew(f.G, Tx, Rz, -mx);
    skew(f.G, Ty, Rz, -my);
    skew(f.G, Tz, Rx, mx);
    skew(f.G, Tz, Ry, my);
    skew(f.G, Rx, Ry, xx + yy);
    skew(f.G, Rx, Rz, yz);
    skew(f.G, Ry, Rz, -xz);

    f.K(Rx, Rx) = xx;
    f.K(Ry, Ry) = yy;
    sym(f.K, Rx, Ry, xy);
    f.K(Rz, Rz) = xx + yy;
    return f;
  }

  /// max_vw |A - B| / sqrt(M_vv M_ww), M = @p mass (a reference M).
  double
  scaled_difference(const FullMatrix<double> &A, const FullMatrix<double> &B,
                    const FullMatrix<double> &mass)
  {
    double e = 0;
    for (unsigned int v = 0; v < A.m(); ++v)
      for (unsigned int w = 0; w < A.n(); ++w)
        {
          const double d = std::abs(A(v, w) - B(v, w)) / std::sqrt(mass(v, v) * mass(w, w));
          if (!(d <= e)) // keeps a NaN
            e = d;
        }
    return e;
  }

  /// Moments of rho over the mapped cell by @p rule (the closed-form
  /// integrand at the rule's points).
  Moments
  rule_moments(const Mapping<3> &mapping, const DoFHandler<3> &dof_handler,
               const Quadrature<3> &rule, const double rho)
  {
    FEValues<3> fe_values(mapping, dof_handler.get_fe(), rule,
                          update_quadrature_points | update_JxW_values);
    fe_values.reinit(dof_handler.begin_active());
    Moments m;
    for (unsigned int q = 0; q < rule.size(); ++q)
      {
        const Point<3> &x = fe_values.quadrature_point(q);
        const double    w = rho * fe_values.JxW(q);
        m.m0 += w;
        m.m1 += w * x;
        m.m2 += w * outer_product(Tensor<1, 3>(x), Tensor<1, 3>(x));
      }
    return m;
  }

  /// The definitions' integrands of the rigid modes summed with @p rule:
  /// rho v.w, rho (v . d_theta w - w . d_theta v), rho d_theta v . d_theta w.
  Forms
  rule_forms(const Mapping<3> &mapping, const DoFHandler<3> &dof_handler,
             const Quadrature<3> &rule, const double rho)
  {
    FEValues<3> fe_values(mapping, dof_handler.get_fe(), rule,
                          update_quadrature_points | update_JxW_values);
    fe_values.reinit(dof_handler.begin_active());
    Forms f;
    for (unsigned int q = 0; q < rule.size(); ++q)
      {
        const Point<3> &x = fe_values.quadrature_point(q);
        const double    w = rho * fe_values.JxW(q);
        for (unsigned int a = 0; a < n_modes; ++a)
          for (unsigned int b = 0; b < n_modes; ++b)
            {
              const Tensor<1, 3> va = mode_value(a, x), vb = mode_value(b, x);
              const Tensor<1, 3> da = mode_d_theta(a, x), db = mode_d_theta(b, x);
              f.M(a, b) += w * (va * vb);
              f.G(a, b) += w * (va * db - vb * da);
              f.K(a, b) += w * (da * db);
            }
      }
    return f;
  }

  /// Closed-form moments of the ring sector r in [a, b], theta in [t0, t1],
  /// z in [z0, z1] (dV = r dr dtheta dz).
  Moments
  sector_moments(const double a, const double b, const double t0, const double t1,
                 const double z0, const double z1, const double rho)
  {
    const double R1 = (b * b - a * a) / 2, R2 = (b * b * b - a * a * a) / 3,
                 R3 = (std::pow(b, 4) - std::pow(a, 4)) / 4; // int r^(k+1) dr
    const double dt = t1 - t0;
    const double C = std::sin(t1) - std::sin(t0), S = std::cos(t0) - std::cos(t1); // int cos, sin
    const double CC = dt / 2 + (std::sin(2 * t1) - std::sin(2 * t0)) / 4;           // int cos^2
    const double SS = dt / 2 - (std::sin(2 * t1) - std::sin(2 * t0)) / 4;           // int sin^2
    const double CS = (std::pow(std::sin(t1), 2) - std::pow(std::sin(t0), 2)) / 2;   // int cos sin
    const double h = z1 - z0, Z1 = (z1 * z1 - z0 * z0) / 2, Z2 = (std::pow(z1, 3) - std::pow(z0, 3)) / 3;
    Moments m;
    m.m0       = rho * R1 * dt * h;
    m.m1[0]    = rho * R2 * C * h;
    m.m1[1]    = rho * R2 * S * h;
    m.m1[2]    = rho * R1 * dt * Z1;
    m.m2[0][0] = rho * R3 * CC * h;
    m.m2[1][1] = rho * R3 * SS * h;
    m.m2[2][2] = rho * R1 * dt * Z2;
    m.m2[0][1] = m.m2[1][0] = rho * R3 * CS * h;
    m.m2[0][2] = m.m2[2][0] = rho * R2 * C * Z1;
    m.m2[1][2] = m.m2[2][1] = rho * R2 * S * Z1;
    return m;
  }

  /// Closed-form moments of the straight tetrahedron @p x: int 1 = V,
  /// int x_k = V s_k/4, int x_k x_l = V/20 (sum_v x_vk x_vl + s_k s_l).
  Moments
  tet_moments(const std::vector<Point<3>> &x, const double rho)
  {
    Tensor<2, 3> J;
    for (unsigned int k = 0; k < 3; ++k)
      for (unsigned int d = 0; d < 3; ++d)
        J[d][k] = x[k + 1][d] - x[0][d];
    const double V = determinant(J) / 6;
    Tensor<1, 3> s;
    for (const auto &p : x)
      s += p;
    Moments m;
    m.m0 = rho * V;
    m.m1 = rho * V / 4 * s;
    m.m2 = outer_product(s, s);
    for (const auto &p : x)
      m.m2 += outer_product(Tensor<1, 3>(p), Tensor<1, 3>(p));
    m.m2 *= rho * V / 20;
    return m;
  }

  /// Polynomials in the unit tetrahedron's coordinates xi = (xi_1, xi_2, xi_3).
  using Polynomial = std::map<std::array<unsigned int, 3>, double>;

  Polynomial
  operator*(const Polynomial &p, const Polynomial &q)
  {
    Polynomial r;
    for (const auto &[a, ca] : p)
      for (const auto &[b, cb] : q)
        r[{{a[0] + b[0], a[1] + b[1], a[2] + b[2]}}] += ca * cb;
    return r;
  }

  Polynomial
  operator+(Polynomial p, const Polynomial &q)
  {
    for (const auto &[b, cb] : q)
      p[b] += cb;
    return p;
  }

  Polynomial
  operator*(const double s, Polynomial p)
  {
    for (auto &[b, cb] : p)
      cb *= s;
    return p;
  }

  Polynomial
  derivative(const Polynomial &p, const unsigned int k)
  {
    Polynomial r;
    for (const auto &[a, ca] : p)
      if (a[k] > 0)
        {
          auto b = a;
          --b[k];
          r[b] += ca * a[k];
        }
    return r;
  }

  /// int over the unit tetrahedron: xi^a -> a1! a2! a3! / (a1 + a2 + a3 + 3)!.
  double
  integral(const Polynomial &p)
  {
    double s = 0;
    for (const auto &[a, ca] : p)
      s += ca * std::tgamma(a[0] + 1.) * std::tgamma(a[1] + 1.) * std::tgamma(a[2] + 1.) /
           std::tgamma(a[0] + a[1] + a[2] + 4.);
    return s;
  }

  /// Moments of the P2 tetrahedron with vertices @p x and mid-edge nodes
  /// @p mid (key: vertex pair v < w; the straight midpoint where absent), by exact integration of rho {1, x_k,
  /// x_k x_l} det J over the unit tetrahedron (own Lagrange basis in
  /// barycentric coordinates; nothing of deal.II's mapping or quadrature).
  Moments
  p2_tet_moments(const std::vector<Point<3>>                                   &x,
                 const std::map<std::pair<unsigned int, unsigned int>, Point<3>> &mid,
                 const double                                                   rho)
  {
    std::array<Polynomial, 4> lambda;
    lambda[0] = {{{{0, 0, 0}}, 1.}, {{{1, 0, 0}}, -1.}, {{{0, 1, 0}}, -1.}, {{{0, 0, 1}}, -1.}};
    for (unsigned int k = 0; k < 3; ++k)
      {
        std::array<unsigned int, 3> e{{0, 0, 0}};
        e[k]          = 1;
        lambda[k + 1] = {{e, 1.}};
      }
    const Polynomial one = {{{{0, 0, 0}}, 1.}};
    std::array<Polynomial, 3> pos;
    for (unsigned int v = 0; v < 4; ++v)
      {
        const Polynomial N = lambda[v] * (2. * lambda[v] + (-1.) * one);
        for (unsigned int d = 0; d < 3; ++d)
          pos[d] = pos[d] + x[v][d] * N;
      }
    for (unsigned int v = 0; v < 4; ++v)
      for (unsigned int w = v + 1; w < 4; ++w)
        {
          const auto       it = mid.find({v, w});
          const Point<3>   p  = it != mid.end() ? it->second : 0.5 * (x[v] + Tensor<1, 3>(x[w]));
          const Polynomial N  = 4. * (lambda[v] * lambda[w]);
          for (unsigned int d = 0; d < 3; ++d)
            pos[d] = pos[d] + p[d] * N;
        }
    std::array<std::array<Polynomial, 3>, 3> J;
    for (unsigned int d = 0; d < 3; ++d)
      for (unsigned int k = 0; k < 3; ++k)
        J[d][k] = derivative(pos[d], k);
    const Polynomial det = J[0][0] * (J[1][1] * J[2][2] + (-1.) * (J[1][2] * J[2][1])) +
                           (-1.) * (J[0][1] * (J[1][0] * J[2][2] + (-1.) * (J[1][2] * J[2][0]))) +
                           J[0][2] * (J[1][0] * J[2][1] + (-1.) * (J[1][1] * J[2][0]));
    Moments m;
    m.m0 = rho * integral(det);
    for (unsigned int k = 0; k < 3; ++k)
      {
        const Polynomial xk_det = pos[k] * det;
        m.m1[k]                 = rho * integral(xk_det);
        for (unsigned int l = 0; l < 3; ++l)
          m.m2[k][l] = rho * integral(pos[l] * xk_det);
      }
    return m;
  }

  /// The forms r_v^T A r_w of the assembled matrices (A = M, G, K_theta) and
  /// of -(assemble_stress_stiffness with u = 0, minus_convective): K_theta
  /// of the K_t2 path. Also K_theta r_T of the translations, relative to
  /// max |K_theta| max |r|.
  struct Assembled
  {
    Forms              forms;
    FullMatrix<double> K_t2{n_modes, n_modes};
    double             translation_residual = 0;
  };

  Assembled
  assemble(const DoFHandler<3> &dof_handler, const Mapping<3> &mapping,
           const Quadrature<3> &rule, const rotorfit::Bodies &bodies)
  {
    const unsigned int     n = dof_handler.n_dofs();
    DynamicSparsityPattern sparsity(n);
    DoFTools::make_sparsity_pattern(dof_handler, sparsity);
    rotorfit::RotorMatrices matrices;
    matrices.reinit(complete_index_set(n), sparsity, MPI_COMM_WORLD);
    matrices.assemble(dof_handler, mapping, rule, bodies);

    PETScWrappers::MPI::Vector zero(complete_index_set(n), MPI_COMM_WORLD);
    PETScWrappers::MPI::SparseMatrix minus_k_theta;
    matrices.assemble_stress_stiffness(dof_handler, mapping, rule, bodies, {&zero},
                                       {&minus_k_theta}, {}, {true});

    // rigid modes interpolated at the mapped support points
    const auto         &fe   = dof_handler.get_fe();
    const auto          cell = dof_handler.begin_active();
    const Quadrature<3> nodes(fe.base_element(0).get_unit_support_points());
    FEValues<3>         at_nodes(mapping, fe.base_element(0), nodes, update_quadrature_points);
    at_nodes.reinit(cell);
    std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
    cell->get_dof_indices(dofs);
    std::vector<Vector<double>> r(n_modes, Vector<double>(n));
    for (unsigned int i = 0; i < dofs.size(); ++i)
      {
        const auto [c, k] = fe.system_to_component_index(i);
        for (unsigned int m = 0; m < n_modes; ++m)
          r[m][dofs[i]] = mode_value(m, at_nodes.quadrature_point(k))[c];
      }

    FullMatrix<double> M(n, n), G(n, n), K(n, n), T(n, n);
    for (unsigned int i = 0; i < n; ++i)
      for (unsigned int j = 0; j < n; ++j)
        {
          M(i, j) = matrices.mass.el(i, j);
          G(i, j) = matrices.gyroscopic.el(i, j);
          K(i, j) = matrices.convective.el(i, j);
          T(i, j) = -minus_k_theta.el(i, j);
        }
    Assembled result;
    Vector<double> Ar(n);
    for (unsigned int b = 0; b < n_modes; ++b)
      {
        for (const auto &[A, F] : {std::make_pair(&M, &result.forms.M),
                                   std::make_pair(&G, &result.forms.G),
                                   std::make_pair(&K, &result.forms.K),
                                   std::make_pair(&T, &result.K_t2)})
          {
            A->vmult(Ar, r[b]);
            for (unsigned int a = 0; a < n_modes; ++a)
              (*F)(a, b) = r[a] * Ar;
          }
        if (b < 3)
          {
            K.vmult(Ar, r[b]);
            result.translation_residual =
              std::max(result.translation_residual,
                       Ar.linfty_norm() / (K.linfty_norm() * r[b].linfty_norm()));
          }
      }
    return result;
  }

  /// (a) and (b) on one element of density @p rho; @p tolerance_b for (b),
  /// @p fine (may be null): a high-order rule that splits the error of (b)
  /// into the code rule's quadrature error and the geometric one.
  void
  check_element(Checks &check, const std::string &name, const DoFHandler<3> &dof_handler,
                const Mapping<3> &mapping, const Quadrature<3> &code_rule,
                const rotorfit::Bodies &bodies, const double rho, const Moments &exact,
                const std::string &exact_kind, const double tolerance_b,
                const Quadrature<3> *fine = nullptr)
  {
    const Assembled a     = assemble(dof_handler, mapping, code_rule, bodies);
    const Forms     rule  = rule_forms(mapping, dof_handler, code_rule, rho);
    const Forms     table = table_forms(rule_moments(mapping, dof_handler, code_rule, rho));
    const Forms     ref   = table_forms(exact);
    const auto     &Mref  = ref.M;

    const std::string identity = "exact identity: definition's integrand, code's rule";
    check.error(name + ": (a) G forms against the integrands at the code's points",
                scaled_difference(a.forms.G, rule.G, Mref), 1e-12, identity);
    check.error(name + ": (a) K_theta forms against the integrands at the code's points",
                scaled_difference(a.forms.K, rule.K, Mref), 1e-12, identity);
    check.error(name + ": (a) -(K_t2 path, u = 0) forms against the integrands at the code's points",
                scaled_difference(a.K_t2, rule.K, Mref), 1e-12, identity);
    check.error(name + ": (a) M forms against the integrands at the code's points",
                scaled_difference(a.forms.M, rule.M, Mref), 1e-12, identity);
    check.error(name + ": |K_theta r_T| / (|K_theta| |r_T|), translations", a.translation_residual,
                1e-13, "exact identity d_theta T = 0");
    // the table of the header (the algebra of the moments) against the integrands
    const double t = std::max({scaled_difference(table.M, rule.M, Mref),
                               scaled_difference(table.G, rule.G, Mref),
                               scaled_difference(table.K, rule.K, Mref)});
    check.error(name + ": moment table (M, G, K_theta) against the integrands, code's rule", t,
                1e-13, "exact identity (guard of the table)");

    if (fine != nullptr)
      {
        const Forms f = table_forms(rule_moments(mapping, dof_handler, *fine, rho));
        std::printf("  %s: scaled error of the code's rule against a %u-point rule on the "
                    "mapped cell: M %.3e, G %.3e, K_theta %.3e\n",
                    name.c_str(), fine->size(), scaled_difference(table.M, f.M, Mref),
                    scaled_difference(table.G, f.G, Mref), scaled_difference(table.K, f.K, Mref));
        std::printf("  %s: scaled geometric error (mapped cell by the %u-point rule against "
                    "the exact body): M %.3e, G %.3e, K_theta %.3e; volume relative %.3e\n",
                    name.c_str(), fine->size(), scaled_difference(f.M, ref.M, Mref),
                    scaled_difference(f.G, ref.G, Mref), scaled_difference(f.K, ref.K, Mref),
                    std::abs(f.M(0, 0) - ref.M(0, 0)) / ref.M(0, 0));
      }

    check.error(name + ": (b) G forms against the closed form",
                scaled_difference(a.forms.G, ref.G, Mref), tolerance_b, exact_kind);
    check.error(name + ": (b) K_theta forms against the closed form",
                scaled_difference(a.forms.K, ref.K, Mref), tolerance_b, exact_kind);
    check.error(name + ": (b) -(K_t2 path, u = 0) forms against the closed form",
                scaled_difference(a.K_t2, ref.K, Mref), tolerance_b, exact_kind);
    check.error(name + ": (b) M forms against the closed form",
                scaled_difference(a.forms.M, ref.M, Mref), tolerance_b, exact_kind);

    // the named entries (relative): sign and axis show here
    const unsigned int Tx = 0, Ty = 1, Rx = 3, Ry = 4, Rz = 5;
    const auto         entry = [&](const char *matrix, const FullMatrix<double> &A,
                           const FullMatrix<double> &R, const unsigned int v,
                           const unsigned int w, const char *what) {
      check.relative(name + ": (b) " + matrix + "(" + mode_name[v] + ", " + mode_name[w] +
                       ") = " + what,
                     A(v, w), R(v, w), tolerance_b, exact_kind);
    };
    entry("M", a.forms.M, ref.M, Tx, Tx, "int rho (mass)");
    entry("G", a.forms.G, ref.G, Rx, Ry, "+int rho (x^2 + y^2) (I_p)");
    entry("G", a.forms.G, ref.G, Rx, Rz, "int rho y z");
    entry("G", a.forms.G, ref.G, Ry, Rz, "-int rho x z");
    entry("G", a.forms.G, ref.G, Tx, Rz, "-int rho x");
    entry("G", a.forms.G, ref.G, Ty, Rz, "-int rho y");
    entry("K_theta", a.forms.K, ref.K, Rx, Rx, "int rho x^2");
    entry("K_theta", a.forms.K, ref.K, Ry, Ry, "int rho y^2");
    entry("K_theta", a.forms.K, ref.K, Rx, Ry, "int rho x y");
    entry("K_theta", a.forms.K, ref.K, Rz, Rz, "int rho (x^2 + y^2) (I_p)");
  }

  Point<3>
  cylindrical(const double r, const double theta, const double z)
  {
    return Point<3>(r * std::cos(theta), r * std::sin(theta), z);
  }
} // namespace

int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  Checks                           check;

  // two bodies of different density: the tetrahedra are body 0, the
  // hexahedron body 1 (rho is the cell's body's)
  ParameterHandler prm;
  rotorfit::Bodies::declare_list(prm);
  const std::string list = "set Bodies = shaft, hub\n";
  prm.parse_input_from_string(list);
  rotorfit::Bodies::declare_parameters(prm, {"shaft", "hub"});
  prm.parse_input_from_string(list + "subsection Body shaft\n"
                                     "  set Young's modulus = 205e9\n"
                                     "  set Poisson's ratio = 0.3\n"
                                     "  set Density = 7850\n"
                                     "end\n"
                                     "subsection Body hub\n"
                                     "  set Young's modulus = 110e9\n"
                                     "  set Poisson's ratio = 0.34\n"
                                     "  set Density = 4430\n"
                                     "end\n");
  rotorfit::Bodies bodies;
  bodies.parse_parameters(prm);
  const double rho_tet = 7850, rho_hex = 4430;

  // ---- P2 tetrahedra: vertices 0, 1, 2 on the cylinder r = R, 3 inside
  const double          R = 0.08, t0 = 0.3, t1 = 0.3 + M_PI / 8, tm = 0.5 * (t0 + t1);
  std::vector<Point<3>> x = {cylindrical(R, t0, 0.02), cylindrical(R, t1, 0.02),
                             cylindrical(R, tm, 0.06), cylindrical(0.05, tm, 0.04)};
  {
    Tensor<2, 3> J;
    for (unsigned int k = 0; k < 3; ++k)
      for (unsigned int d = 0; d < 3; ++d)
        J[d][k] = x[k + 1][d] - x[0][d];
    if (determinant(J) < 0)
      std::swap(x[1], x[2]); // positive orientation
  }
  Triangulation<3>         tria_tet;
  std::vector<CellData<3>> tet_cells(1, CellData<3>(4));
  tet_cells[0].vertices    = {0, 1, 2, 3};
  tet_cells[0].material_id = 0;
  tria_tet.create_triangulation(x, tet_cells, SubCellData());

  const FESystem<3> fe_tet(FE_SimplexP<3>(2), 3);
  DoFHandler<3>     tet_dofs(tria_tet);
  tet_dofs.distribute_dofs(fe_tet);
  const QGaussSimplex<3> tet_rule(2 + 2); // the code's rule: order + 2 (AssemblyMesh::cell_quadrature)

  // the quadratic position field of the gmsh meshes (MappingFEField), mid-edge
  // nodes given per vertex pair (straight midpoints when absent)
  const auto position_field = [&](const std::map<std::pair<unsigned int, unsigned int>, Point<3>> &mid,
                                  DoFHandler<3> &position_dofs, Vector<double> &positions) {
    position_dofs.reinit(tria_tet);
    position_dofs.distribute_dofs(fe_tet);
    positions.reinit(position_dofs.n_dofs());
    const auto &unit = fe_tet.base_element(0).get_unit_support_points();
    const auto  ref  = ReferenceCells::Tetrahedron;
    const auto  cell = position_dofs.begin_active();
    std::vector<types::global_dof_index> dofs(fe_tet.n_dofs_per_cell());
    cell->get_dof_indices(dofs);
    for (unsigned int i = 0; i < dofs.size(); ++i)
      {
        const auto [c, k] = fe_tet.system_to_component_index(i);
        Point<3> p;
        bool     found = false;
        for (unsigned int v = 0; v < 4; ++v)
          {
            if (unit[k].distance(ref.vertex<3>(v)) < 1e-12)
              p = x[v], found = true;
            for (unsigned int w = v + 1; w < 4; ++w)
              if (unit[k].distance(0.5 * (ref.vertex<3>(v) + Tensor<1, 3>(ref.vertex<3>(w)))) <
                  1e-12)
                {
                  const auto it = mid.find({v, w});
                  p     = it != mid.end() ? it->second : 0.5 * (x[v] + Tensor<1, 3>(x[w]));
                  found = true;
                }
          }
        AssertThrow(found, ExcInternalError());
        positions[dofs[i]] = p[c];
      }
  };

  // (1) affine: straight edges
  {
    DoFHandler<3>  position_dofs;
    Vector<double> positions;
    position_field({}, position_dofs, positions);
    const MappingFEField<3, 3, Vector<double>> mapping(position_dofs, positions);
    check_element(check, "affine P2 tet", tet_dofs, mapping, tet_rule, bodies, rho_tet,
                  tet_moments(x, rho_tet), "closed form: vertex formula", 1e-12);
  }
  // (2) curved: the face of vertices 0, 1, 2 on the cylinder r = R, its
  // mid-edge nodes on it at the mean angle and height (as gmsh places them)
  {
    std::map<std::pair<unsigned int, unsigned int>, Point<3>> mid;
    for (unsigned int v = 0; v < 3; ++v)
      for (unsigned int w = v + 1; w < 3; ++w)
        mid[{v, w}] = cylindrical(R,
                                  0.5 * (std::atan2(x[v][1], x[v][0]) + std::atan2(x[w][1], x[w][0])),
                                  0.5 * (x[v][2] + x[w][2]));
    DoFHandler<3>  position_dofs;
    Vector<double> positions;
    position_field(mid, position_dofs, positions);
    const MappingFEField<3, 3, Vector<double>> mapping(position_dofs, positions);
    // the curved face bulges: more volume than the straight tetrahedron
    const Moments curved = p2_tet_moments(x, mid, rho_tet);
    std::printf("  curved P2 tet: volume %.6e m^3, straight %.6e m^3\n", curved.m0 / rho_tet,
                tet_moments(x, rho_tet).m0 / rho_tet);
    check.equal("curved P2 tet: volume above the straight tetrahedron's by more than 1 %",
                curved.m0 > 1.01 * tet_moments(x, rho_tet).m0, true, "set-up: the cell is curved");
    check_element(check, "curved P2 tet", tet_dofs, mapping, tet_rule, bodies, rho_tet, curved,
                  "closed form: exact polynomial integral of the P2 map", 1e-12);
  }

  // ---- Q2 hexahedron: the ring sector r in [a, b], theta in [h0, h1], z in [z0, z1]
  {
    const double a = 0.05, b = 0.08, h0 = 0.3, h1 = 0.3 + 2 * M_PI / 16, z0 = 0.02, z1 = 0.05;
    std::vector<Point<3>> v(8);
    for (unsigned int k = 0; k < 8; ++k) // lexicographic: xi_0 -> r, xi_1 -> theta, xi_2 -> z
      v[k] = cylindrical(k % 2 ? b : a, (k / 2) % 2 ? h1 : h0, k / 4 ? z1 : z0);
    Triangulation<3>         tria_hex;
    std::vector<CellData<3>> hex_cells(1, CellData<3>(8));
    for (unsigned int k = 0; k < 8; ++k)
      hex_cells[0].vertices[k] = k;
    hex_cells[0].material_id = 1;
    tria_hex.create_triangulation(v, hex_cells, SubCellData());
    tria_hex.begin_active()->set_all_manifold_ids(1);
    tria_hex.set_manifold(1, rotorfit::CylindricalChart());

    const FESystem<3> fe_hex(FE_Q<3>(2), 3);
    DoFHandler<3>     hex_dofs(tria_hex);
    hex_dofs.distribute_dofs(fe_hex);
    const MappingQ<3>  mapping(2);
    const QGauss<3>    hex_rule(2 + 1); // the code's rule: order + 1 per direction
    const QGauss<3>    fine(8); // exact on the mapped cell (degree <= 9 per direction)
    // (b) against the exact sector: the Q2 map puts its 27 points on the
    // (r, theta, z) grid, but between them its arcs are parabolas; with 22.5
    // degrees the mapped cell's volume is 4.93e-5 (relative) short of the
    // sector's (O(angle^4): 7.8e-4 at 45, 3.1e-6 at 11.25 degrees) and the
    // forms are off by up to 1.44e-4 (scaled; entries up to 1.0e-4
    // relative), the code's rule adding 2.4e-7 (both printed). Tolerance
    // 2.4e-4: about 5 times the volume error, 1.7 to 4.9 times each
    // observed error; a 1 % fault is 40 times it.
    check_element(check, "Q2 ring-sector hex", hex_dofs, mapping, hex_rule, bodies, rho_hex,
                  sector_moments(a, b, h0, h1, z0, z1, rho_hex),
                  "closed form: ring sector, geometric tolerance", 2.4e-4, &fine);
  }

  return check.finish();
}
