#include <rotorfit/linear_algebra/replicated_blocks.h>
#include <rotorfit/response/projection_basis.h>

#include <deal.II/base/mpi.h>
#include <deal.II/lac/lapack_full_matrix.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace rotorfit
{
  using namespace dealii;

  unsigned int
  ProjectionBasis::head() const
  {
    return op.basis ? op.basis->size() : 0;
  }

  unsigned int
  ProjectionBasis::size() const
  {
    return head() + v.size();
  }

  void
  ProjectionBasis::solve(const ComplexVector &f,
                         const double         w,
                         const double         tolerance,
                         ComplexVector       &u,
                         ComplexVector       &r)
  {
    const unsigned int k = size();
    project();
    LAPACKFullMatrix<double> S(2 * k, 2 * k);
    for (unsigned int i = 0; i < k; ++i)
      for (unsigned int j = 0; j < k; ++j)
        {
          const double a = kr[i][j] - w * w * mr[i][j];
          const double b = w * dr[i][j];
          S(i, j) = S(k + i, k + j) = a;
          S(i, k + j)               = -b;
          S(k + i, j)               = b;
        }
    S.compute_lu_factorization();
    Vector<double> y = project_vector(f);
    S.solve(y);
    residual(f, w, y, u, r);
    // the projected system of a large basis solves to about eps times its
    // condition; one or two steps of refinement on the residual
    // recover what the basis can give
    const auto norm = [](const ComplexVector &z) {
      return std::sqrt(z.re.norm_sqr() + z.im.norm_sqr());
    };
    // (not where the residual already meets the tolerance: each step is
    // a full-space residual, most of a reused basis's speed)
    for (unsigned int refinement = 0;
         refinement < 2 && head() > 0 && !(norm(r) <= tolerance * norm(f));
         ++refinement)
      {
        Vector<double> dy = project_vector(r);
        S.solve(dy);
        Vector<double> y_new = y;
        y_new += dy;
        ComplexVector u_new, r_new;
        residual(f, w, y_new, u_new, r_new);
        if (!(norm(r_new) < 0.5 * norm(r)))
          break;
        y = std::move(y_new);
        u = std::move(u_new);
        r = std::move(r_new);
      }
  }

  Vector<double>
  ProjectionBasis::project_vector(const ComplexVector &g) const
  {
    const unsigned int k = size(), h = head();
    Vector<double>     y(2 * k);
    if (h > 0)
      {
        const std::vector<double> c = op.basis->coefficients(
          std::vector<const Vector<double> *>{&g.re, &g.im});
        for (unsigned int i = 0; i < h; ++i)
          y[i] = c[i], y[k + i] = c[h + i];
      }
    for (unsigned int i = h; i < k; ++i)
      {
        y[i]     = v[i - h] * g.re;
        y[k + i] = v[i - h] * g.im;
      }
    return y;
  }

  void
  ProjectionBasis::residual(const ComplexVector  &f,
                            const double          w,
                            const Vector<double> &y,
                            ComplexVector        &u,
                            ComplexVector        &r) const
  {
    const unsigned int k = size(), h = head();
    r = f;
    if (h > 0)
      {
        // the head's part from the products its projections were made of
        std::vector<std::complex<double>> yh(h);
        for (unsigned int i = 0; i < h; ++i)
          yh[i] = {y[i], y[k + i]};
        u = op.basis->expand(yh);
        ComplexVector mu, du, ku;
        op.products(yh, mu, du, ku);
        r.re.add(-1., ku.re, w * w, mu.re);
        r.re.add(w, du.im);
        r.im.add(-1., ku.im, w * w, mu.im);
        r.im.add(-w, du.re);
      }
    else
      u = {Vector<double>(f.re.size()), Vector<double>(f.re.size())};
    for (unsigned int j = h; j < k; ++j)
      {
        const double       yr = y[j], yi = y[k + j];
        const unsigned int e  = j - h;
        u.re.add(yr, v[e]);
        u.im.add(yi, v[e]);
        r.re.add(-yr, kv[e], w * w * yr, mv[e]);
        r.re.add(w * yi, dv[e]);
        r.im.add(-yi, kv[e], w * w * yi, mv[e]);
        r.im.add(-w * yr, dv[e]);
      }
  }

  void
  ProjectionBasis::project()
  {
    const std::size_t k = size(), h = head(), old = mr.size();
    for (auto *r : {&mr, &dr, &kr})
      {
        r->resize(k);
        for (auto &row : *r)
          row.resize(k);
      }
    if (old == 0)
      for (std::size_t i = 0; i < h; ++i)
        for (std::size_t j = 0; j < h; ++j)
          {
            mr[i][j] = (*op.Mr)(i, j);
            dr[i][j] = (*op.Cr)(i, j);
            kr[i][j] = (*op.Kr)(i, j);
          }
    const std::size_t first = std::max(old, h);
    if (affine && old == 0 && h > 0 && affine->projected && k - h == affine->d.size())
      project_adopted();
    else
      {
        if (h > 0 && first < k)
          project_on_head(first);
        project_explicit(first);
      }
  }

  void
  ProjectionBasis::project_adopted()
  {
    const std::size_t k = size(), h = head();
    // the adopted columns at this speed from their kept projections
    const UnbalanceResponse::KeptProducts &p = *affine;
    const double dO = omega - p.omega, dw = omega * omega - p.omega * p.omega,
                 dt = omega * omega - p.w_tangent;
    const std::size_t ke = k - h;
    for (std::size_t j = h; j < k; ++j)
      {
        for (std::size_t i = 0, at = (j - h) * h; i < h; ++i, ++at)
          {
            mr[i][j] = p.col[0][at], mr[j][i] = p.row[0][at];
            dr[i][j] = p.col[1][at] + dO * p.col[2][at];
            dr[j][i] = p.row[1][at] + omega * p.row[2][at];
            kr[i][j] = p.col[3][at] + dw * p.col[4][at];
            kr[j][i] = p.row[3][at] + dt * p.row[4][at];
          }
        for (std::size_t i = h; i < k; ++i)
          {
            const std::size_t at = (i - h) * ke + (j - h); // e_i^T X_j
            mr[i][j] = p.own[0][at];
            dr[i][j] = p.own[1][at] + dO * p.own[2][at];
            kr[i][j] = p.own[3][at] + dw * p.own[4][at];
          }
      }
  }

  void
  ProjectionBasis::project_on_head(const std::size_t first)
  {
    const std::size_t k = size(), h = head();
    // V_h^T (A e), and e^T (A V_h) from the head's products, so that
    // every entry rounds as the residual does; all new columns in one
    // pass over each block
    std::vector<const Vector<double> *> e_v, e_m, e_d, e_k;
    for (std::size_t j = first; j < k; ++j)
      {
        e_v.push_back(&v[j - h]);
        e_m.push_back(&mv[j - h]);
        e_d.push_back(&dv[j - h]);
        e_k.push_back(&kv[j - h]);
      }
    const std::vector<double> m_col = op.basis->coefficients(e_m),
                              d_col = op.basis->coefficients(e_d),
                              k_col = op.basis->coefficients(e_k);
    std::array<std::vector<double>, 5> row;
    op.row_parts(e_v, row);
    const double dt = omega * omega - op.w_tangent;
    for (std::size_t j = first; j < k; ++j)
      for (std::size_t i = 0, at = (j - first) * h; i < h; ++i, ++at)
        {
          mr[i][j] = m_col[at], mr[j][i] = row[0][at];
          dr[i][j] = d_col[at], dr[j][i] = row[1][at] + omega * row[2][at];
          kr[i][j] = k_col[at], kr[j][i] = row[3][at] + dt * row[4][at];
        }
  }

  void
  ProjectionBasis::project_explicit(const std::size_t first)
  {
    const std::size_t k = size(), h = head();
    for (std::size_t j = first; j < k; ++j)
      {
        const std::size_t e = j - h;
        for (std::size_t i = h; i < k; ++i)
          {
            const std::size_t c = i - h;
            mr[i][j] = v[c] * mv[e], mr[j][i] = v[e] * mv[c];
            dr[i][j] = v[c] * dv[e], dr[j][i] = v[e] * dv[c];
            kr[i][j] = v[c] * kv[e], kr[j][i] = v[e] * kv[c];
          }
      }
  }

  void
  ProjectionBasis::adopt(const std::vector<Vector<double>> &x,
                         const std::vector<Vector<double>> &mx,
                         UnbalanceResponse::KeptProducts   &p,
                         const double                        omega)
  {
    v  = x;
    mv = mx;
    if (op.segment == 0 || p.segment != op.segment || p.d.size() != v.size())
      {
        replicated_mmult(op.damping, pointers(v), dv);
        replicated_mmult(op.stiffness, pointers(v), kv);
        return;
      }
    // D = D_s + (Omega - Omega_s) G, K = K_s + (w - w_s) K_t2
    if (p.g.size() != v.size())
      op.speed_share(pointers(v), p.g, p.k2);
    if (!p.projected || p.w_tangent != op.w_tangent)
      {
        // projected once: later speeds combine these (project())
        const std::vector<Vector<double>> *x[5] = {&mv, &p.d, &p.g, &p.k, &p.k2};
        for (unsigned int b = 0; b < 5; ++b)
          {
            p.col[b] = op.basis->coefficients(pointers(*x[b]));
            p.own[b].resize(v.size() * v.size());
            for (std::size_t c = 0; c < v.size(); ++c)
              for (std::size_t e = 0; e < v.size(); ++e)
                p.own[b][c * v.size() + e] = v[c] * (*x[b])[e];
          }
        op.row_parts(pointers(v), p.row);
        p.w_tangent = op.w_tangent;
        p.projected = true;
      }
    dv = p.d;
    kv = p.k;
    for (std::size_t e = 0; e < v.size(); ++e)
      {
        dv[e].add(omega - p.omega, p.g[e]);
        kv[e].add(omega * omega - p.omega * p.omega, p.k2[e]);
      }
    // checked against this speed's sparse products at the first speed
    // after the columns were kept and every tenth after: a mismatch
    // (a share that does not follow the matrices) drops the kept base
    if (p.uses++ % 10 == 0)
      {
        std::vector<Vector<double>> d, k;
        replicated_mmult(op.damping, pointers(v), d);
        replicated_mmult(op.stiffness, pointers(v), k);
        double worst = 0;
        for (std::size_t e = 0; e < v.size(); ++e)
          for (const auto &[fresh, kept] : {std::pair{&d[e], &dv[e]}, std::pair{&k[e], &kv[e]}})
            {
              Vector<double> diff = *fresh;
              diff -= *kept;
              const double norm = fresh->l2_norm();
              worst = std::max(worst, norm > 0 ? diff.l2_norm() / norm : diff.l2_norm());
            }
        if (!std::isfinite(worst))
          worst = std::numeric_limits<double>::infinity();
        // the same decision on every rank (the columns are replicated)
        worst = Utilities::MPI::max(worst, op.mass.get_mpi_communicator());
        p.worst = std::max(p.worst, worst);
        if (!(worst <= 1e-6))
          {
            ++p.refused;
            p.segment = 0; // kept again from this speed's products
            dv        = std::move(d);
            kv        = std::move(k);
            return;
          }
      }
    ++p.served;
    affine      = &p;
    this->omega = omega;
  }

  bool
  ProjectionBasis::add(std::vector<Vector<double>> xs)
  {
    std::vector<Vector<double>> x;
    std::vector<double>         norm0;
    for (auto &z : xs)
      {
        const double a = z.l2_norm();
        if (a > 0 && std::isfinite(a))
          {
            norm0.push_back(a);
            x.push_back(std::move(z));
          }
      }
    if (x.empty())
      return false;
    const std::size_t old = v.size();
    if (head() > 0)
      add_m_orthonormal(x, norm0);
    else
      add_orthonormal(x, norm0);
    std::vector<const Vector<double> *> added;
    for (std::size_t e = old; e < v.size(); ++e)
      added.push_back(&v[e]);
    std::vector<Vector<double>> dx, kx;
    replicated_mmult(op.damping, added, dx);
    replicated_mmult(op.stiffness, added, kx);
    for (std::size_t e = 0; e < added.size(); ++e)
      {
        dv.push_back(std::move(dx[e]));
        kv.push_back(std::move(kx[e]));
      }
    return v.size() > old;
  }

  void
  ProjectionBasis::add_m_orthonormal(std::vector<Vector<double>> &x, std::vector<double> &norm0)
  {
    // M-orthonormal like the head (columns of one scale keep the projected
    // system as well conditioned as the basis is): against the head twice,
    // then the explicit columns, then each other
    const std::size_t           old = v.size();
    std::vector<Vector<double>> mx;
    replicated_mmult(op.mass, pointers(x), mx);
    for (std::size_t i = 0; i < x.size(); ++i)
      norm0[i] = std::sqrt(std::max(0., x[i] * mx[i]));
    for (unsigned int pass = 0; pass < 2; ++pass)
      {
        for (std::size_t i = 0; i < x.size(); ++i)
          op.basis->subtract_projection(x[i], mx[i]);
        replicated_mmult(op.mass, pointers(x), mx);
      }
    for (std::size_t i = 0; i < x.size(); ++i)
      for (unsigned int pass = 0; pass < 2; ++pass)
        for (std::size_t e = 0; e < old; ++e)
          x[i].add(-(mv[e] * x[i]), v[e]);
    replicated_mmult(op.mass, pointers(x), mx);
    for (std::size_t i = 0; i < x.size(); ++i)
      {
        if (v.size() > old)
          {
            // the columns of this block kept before it
            for (unsigned int pass = 0; pass < 2; ++pass)
              for (std::size_t e = old; e < v.size(); ++e)
                x[i].add(-(mv[e] * x[i]), v[e]);
            replicated_vmult(op.mass, x[i], mx[i]);
          }
        const double m_norm = std::sqrt(std::max(0., x[i] * mx[i]));
        if (!(m_norm > 1e-10 * norm0[i]))
          continue;
        x[i] /= m_norm;
        mx[i] /= m_norm;
        v.push_back(std::move(x[i]));
        mv.push_back(std::move(mx[i]));
      }
  }

  void
  ProjectionBasis::add_orthonormal(std::vector<Vector<double>> &x, const std::vector<double> &norm0)
  {
    const std::size_t old = v.size();
    for (std::size_t i = 0; i < x.size(); ++i)
      {
        for (unsigned int pass = 0; pass < 2; ++pass)
          for (const auto &q : v)
            x[i].add(-(q * x[i]), q);
        const double norm = x[i].l2_norm();
        if (!(norm > 1e-10 * norm0[i]))
          continue;
        x[i] /= norm;
        v.push_back(std::move(x[i]));
      }
    std::vector<const Vector<double> *> added;
    for (std::size_t e = old; e < v.size(); ++e)
      added.push_back(&v[e]);
    std::vector<Vector<double>> mx;
    replicated_mmult(op.mass, added, mx);
    for (auto &z : mx)
      mv.push_back(std::move(z));
  }
} // namespace rotorfit
