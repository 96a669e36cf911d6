// LowRankUpdate (the Woodbury algebra of ContactSolver, doc/theory.md 7.7)
// against a direct dense solve of K_A x = r, K_A = K_base + B_D S B_D^T, on a
// small random SPD system with dense pair vectors b_p: springs added
// (+eps) and removed (-eps) together, only removed, only added, none. Checks
// the gaps B^T K_A^-1 r, the displacement K_base^-1 (r - B_D c) and
// c = S B_D^T x. A singular capacitance matrix is refused.

#include <rotorfit/contact/low_rank_update.h>

#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/lapack_full_matrix.h>
#include <deal.II/lac/vector.h>

#include <random>
#include <set>

#include "unit_check.h"

using namespace dealii;
using namespace rotorfit_unit;

namespace
{
  constexpr unsigned int n_dofs = 14, n_pairs = 7;

  struct System
  {
    FullMatrix<double>          K0; // SPD, without springs
    std::vector<Vector<double>> b;  // pair vectors
    std::vector<double>         eps;
  };

  System
  random_system(std::mt19937 &rng)
  {
    std::uniform_real_distribution<double> u(-1., 1.);
    System                                 s;
    FullMatrix<double>                     A(n_dofs, n_dofs);
    for (unsigned int i = 0; i < n_dofs; ++i)
      for (unsigned int j = 0; j < n_dofs; ++j)
        A(i, j) = u(rng);
    s.K0.reinit(n_dofs, n_dofs);
    A.mTmult(s.K0, A);
    for (unsigned int i = 0; i < n_dofs; ++i)
      s.K0(i, i) += n_dofs;
    for (unsigned int p = 0; p < n_pairs; ++p)
      {
        Vector<double> bp(n_dofs);
        for (auto &v : bp)
          v = u(rng);
        s.b.push_back(bp);
        // penalties ten times the diagonal, like the contact solver's
        s.eps.push_back(10. * n_dofs * (1.5 + 0.5 * u(rng)));
      }
    return s;
  }

  /// K0 + sum over the active pairs of eps b b^T.
  LAPACKFullMatrix<double>
  matrix(const System &s, const std::vector<bool> &active)
  {
    FullMatrix<double> K(s.K0);
    for (unsigned int p = 0; p < n_pairs; ++p)
      if (active[p])
        for (unsigned int i = 0; i < n_dofs; ++i)
          for (unsigned int j = 0; j < n_dofs; ++j)
            K(i, j) += s.eps[p] * s.b[p][i] * s.b[p][j];
    LAPACKFullMatrix<double> L(n_dofs);
    L = K;
    return L;
  }

  std::vector<double>
  project(const System &s, const Vector<double> &x) // B^T x
  {
    std::vector<double> t(n_pairs);
    for (unsigned int p = 0; p < n_pairs; ++p)
      t[p] = s.b[p] * x;
    return t;
  }

  double
  relative(const std::vector<double> &a, const std::vector<double> &b)
  {
    double d = 0, scale = 0;
    for (unsigned int i = 0; i < b.size(); ++i)
      {
        const double e = std::abs(a[i] - b[i]);
        if (!(e <= d)) // keeps a NaN
          d = e;
        scale = std::max(scale, std::abs(b[i]));
      }
    return d / scale;
  }

  void
  check_case(Checks &check, const std::string &name, const System &s,
             const std::vector<bool> &base_active, const std::vector<bool> &active,
             std::mt19937 &rng)
  {
    LAPACKFullMatrix<double> K_base = matrix(s, base_active), K_A = matrix(s, active);
    K_base.compute_lu_factorization();
    K_A.compute_lu_factorization();

    // D, S as ContactSolver forms them; the columns F(:,p) = B^T K_base^-1 b_p
    // of the changed pairs only (the others stay empty, as in its cache)
    std::vector<unsigned int>        D;
    std::vector<double>              S;
    std::vector<std::vector<double>> column(n_pairs);
    for (unsigned int p = 0; p < n_pairs; ++p)
      if (active[p] != base_active[p])
        {
          D.push_back(p);
          S.push_back((active[p] ? 1. : -1.) * s.eps[p]);
          Vector<double> x = s.b[p];
          K_base.solve(x);
          column[p] = project(s, x);
        }
    rotorfit::LowRankUpdate update;
    check.equal(name + ": reinit accepts the capacitance matrix", update.reinit(D, S, column),
                true, "K_A is SPD");
    check.equal(name + ": changed pairs", update.changed().size(), D.size(), "set-up");

    std::uniform_real_distribution<double> u(-1., 1.);
    for (unsigned int k = 0; k < 3; ++k)
      {
        Vector<double> r(n_dofs);
        for (auto &v : r)
          v = u(rng);
        // direct: x = K_A^-1 r
        Vector<double> x = r;
        K_A.solve(x);
        // update: t = B^T K_base^-1 r -> B^T K_A^-1 r, c
        Vector<double> y = r;
        K_base.solve(y);
        std::vector<double>       t = project(s, y);
        const std::vector<double> c = update.apply(t, column);
        // u = K_base^-1 (r - B_D c)
        Vector<double> rhs = r;
        for (unsigned int a = 0; a < D.size(); ++a)
          rhs.add(-c[a], s.b[D[a]]);
        K_base.solve(rhs);
        Vector<double> diff = rhs;
        diff -= x;

        const std::string rk = name + ", rhs " + std::to_string(k) + ": ";
        check.error(rk + "max |t - B^T x| / max |B^T x| (gaps)", relative(t, project(s, x)),
                    1e-12, "direct dense LU of K_A");
        check.error(rk + "|K_base^-1 (r - B_D c) - x| / |x|", diff.linfty_norm() / x.linfty_norm(),
                    1e-12, "direct dense LU of K_A");
        if (!D.empty())
          {
            std::vector<double> c_ref(D.size());
            for (unsigned int a = 0; a < D.size(); ++a)
              c_ref[a] = S[a] * (s.b[D[a]] * x);
            check.error(rk + "max |c - S B_D^T x| / max |S B_D^T x|", relative(c, c_ref), 1e-12,
                        "exact identity with the direct solve");
          }
        else
          check.equal(rk + "no coefficients", c.size(), std::size_t(0), "empty update");
      }
  }
} // namespace

int
main()
{
  Checks       check;
  std::mt19937 rng(20240611);
  const System s = random_system(rng);

  const std::vector<bool> base = {true, true, true, true, false, false, false};
  check_case(check, "closed 4,5,6 and opened 1,3", s, base,
             {true, false, true, false, true, true, true}, rng);
  check_case(check, "opened 0,1,2", s, base, {false, false, false, true, false, false, false},
             rng);
  check_case(check, "closed 5", s, base, {true, true, true, true, false, true, false}, rng);
  check_case(check, "unchanged", s, base, base, rng);

  // singular: one pair on one DoF, K0 = 0, the spring removed: the
  // capacitance matrix is 1/eps - 1/eps = 0 exactly (eps a power of two)
  {
    rotorfit::LowRankUpdate                update;
    const std::vector<std::vector<double>> column = {{1. / 4.}};
    const bool accepted = update.reinit({0}, {-4.}, column);
    check.equal("singular capacitance matrix: reinit refuses it", accepted, false,
                "K_A = 0: capacitance 1/4 - 1/4 = 0");
    check.equal("singular capacitance matrix: left empty", update.empty(), true,
                "documented in low_rank_update.h");
  }
  return check.finish();
}
