#include <rotorfit/harmonic/harmonic_reduced_model.h>
#include <rotorfit/linear_algebra/blas.h>
#include <rotorfit/linear_algebra/replicated_blocks.h>
#include <rotorfit/statics/speed_schedule.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <map>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;
  using complex = std::complex<double>;

  namespace
  {
    /// sum of a_ij b_ij over the entries of @p a (b's entries elsewhere do
    /// not count: used for b on a's pattern or a sub-pattern of it)
    double
    frobenius_product(const SparseMatrix<double> &a, const SparseMatrix<double> &b)
    {
      double s = 0;
      if (&a.get_sparsity_pattern() == &b.get_sparsity_pattern())
        {
          auto ib = b.begin();
          for (auto ia = a.begin(); ia != a.end(); ++ia, ++ib)
            s += ia->value() * ib->value();
          return s;
        }
      for (auto ia = a.begin(); ia != a.end(); ++ia)
        s += ia->value() * b.el(ia->row(), ia->column());
      return s;
    }
  } // namespace

  HarmonicReducedModel::HarmonicReducedModel(const unsigned int n, const ReducedBasis &settings)
    : n(n)
    , basis(settings)
  {
    basis.clear();
  }

  void
  HarmonicReducedModel::add_anchor(const Operators              &op,
                                   const std::size_t             law,
                                   const double                  rpm,
                                   const std::vector<EigenPair> &pairs,
                                   const double                  radius,
                                   const DirectSolver           &factors,
                                   const std::vector<Vector<double>> &loads)
  {
    // the eigenvectors' real and imaginary parts
    std::vector<Vector<double>> x;
    for (const auto &p : pairs)
      {
        x.push_back(p.phi.re);
        if (p.phi.im.linfty_norm() > 1e-12 * p.phi.re.linfty_norm())
          x.push_back(p.phi.im);
      }
    // their first-order changes with the speed and the bearings (doc/theory.md 8.6)
    std::vector<Vector<double>> gx, kx;
    replicated_mmult(*op.pG, pointers(x), gx);
    replicated_mmult(*op.pK2, pointers(x), kx);
    std::vector<Vector<double>> rhs;
    for (auto *list : {&gx, &kx})
      for (auto &v : *list)
        if (v.linfty_norm() > 0)
          rhs.push_back(std::move(v));
    for (const auto &a : *op.stations)
      {
        Vector<double> v(op.pM->m());
        for (const auto &[i, w] : a)
          v[i] += w;
        rhs.push_back(std::move(v));
      }
    // the static correction of the unbalance response (doc/theory.md 13.2)
    for (const auto &f : loads)
      if (f.linfty_norm() > 0)
        rhs.push_back(f);
    std::vector<Vector<double>> directions;
    if (!rhs.empty())
      replicated_solve(factors, *op.pM, pointers(rhs), directions);
    const unsigned int anchor_size = x.size() + directions.size();
    if (law != key || basis.size() + anchor_size > basis.capacity(anchor_size))
      {
        basis.clear();
        basis.anchors.clear();
      }
    key = law;
    std::vector<const Vector<double> *> all = pointers(x);
    for (const auto &d : directions)
      all.push_back(&d);
    basis.add(all, *op.pM);
    basis.anchors.push_back({rpm, radius});
    project(op, factors);
  }

  void
  HarmonicReducedModel::project(const Operators &op, const DirectSolver &factors)
  {
    Mr  = basis.project(*op.pM, &mv);
    Gr  = basis.project(*op.pG, &gv);
    K0r = basis.project(*op.pK0, &k0v);
    K2r = basis.project(*op.pK2, &k2v);
    const std::size_t rows = op.pM->m();
    const auto       &st   = *op.stations;
    station_r.assign(st.size(), std::vector<double>());
    std::vector<double> a(rows * st.size(), 0.);
    for (unsigned int p = 0; p < st.size(); ++p)
      {
        Vector<double> v(rows);
        for (const auto &[i, w] : st[p])
          v[i] += w, a[i + p * rows] += w;
        station_r[p] = basis.coefficients(v);
      }
    av.assign(std::move(a), rows);
    blocks.clear();
    for (const RowBlock *b : {&mv, &gv, &k0v, &k2v, &av})
      if (!b->empty())
        blocks.push_back(b);
    gram = replicated_inverse_gram(factors, *op.pM, blocks);
    // the norms of the law's matrices (the backward errors' scale)
    m_norm = std::sqrt(frobenius_product(*op.M, *op.M));
    k00    = frobenius_product(*op.K0, *op.K0);
    k02    = frobenius_product(*op.K0, *op.K2);
    k22    = frobenius_product(*op.K2, *op.K2);
    gg     = frobenius_product(*op.G, *op.G);
  }

  bool
  HarmonicReducedModel::solve(const Operators        &op,
                              const Speed            &speed,
                              std::vector<EigenPair> &out,
                              std::string            &why)
  {
    out.clear();
    const double       omega = SpeedSchedule::rpm_to_rad_per_s(speed.rpm), w = omega * omega;
    const unsigned int m     = basis.size();
    std::ostringstream reason;
    // the projections of this speed
    FullMatrix<double> Kr(K0r), Cr(Gr);
    Kr.add(w, K2r);
    Cr *= omega;
    for (const auto &c : speed.couplings)
      for (unsigned int i = 0; i < m; ++i)
        for (unsigned int j = 0; j < m; ++j)
          {
            const double s = station_r[c.p][i] * station_r[c.q][j];
            Kr(i, j) += c.k * s;
            Cr(i, j) += c.c * s;
          }
    std::vector<ReducedBasis::Pair> all;
    if (!basis.solve(Mr, Cr, Kr, all))
      {
        why = "LAPACK failed on the projected problem";
        return false;
      }
    // the eigenvalues nearest the shift, as the full solve takes them
    const double sigma = speed.sigma;
    std::sort(all.begin(), all.end(), [&](const auto &a, const auto &b) {
      return std::abs(a.lambda - sigma) < std::abs(b.lambda - sigma);
    });
    std::vector<ReducedBasis::Pair> kept;
    unsigned int                    count = 0;
    for (auto &p : all)
      {
        if (count >= speed.n_wanted)
          break;
        count += p.lambda.imag() != 0 ? 2 : 1;
        kept.push_back(std::move(p));
      }
    if (kept.empty())
      {
        why = "no mode in the basis";
        return false;
      }
    // coverage: no mode outside the basis can have come within reach
    const double reach = std::abs(kept.back().lambda - sigma);
    const double slope = std::max<double>(basis.slope_bound(), n);
    bool         covered = false;
    for (const auto &a : basis.anchors)
      covered = covered ||
                reach + slope * std::abs(omega - SpeedSchedule::rpm_to_rad_per_s(a.rpm)) < a.radius;
    if (!covered)
      {
        reason << "coverage: the modes reach " << reach / (2 * M_PI)
               << " Hz from the shift, beyond what an anchor covers at this speed";
        why = reason.str();
        return false;
      }

    // the modes on every DoF and their residuals from the kept products
    const unsigned int                              k = kept.size();
    std::vector<std::vector<complex>>               y(k);
    for (unsigned int c = 0; c < k; ++c)
      y[c] = kept[c].y;
    std::vector<ComplexVector> phi(k), mphi(k), r(k);
    basis.multiply(nullptr, y, 1., column_pointers(phi));
    for (unsigned int c = 0; c < k; ++c)
      {
        const double norm = std::sqrt(phi[c].re.norm_sqr() + phi[c].im.norm_sqr());
        if (!(norm > 0))
          {
            why = "a reduced mode is zero";
            return false;
          }
        phi[c].re /= norm;
        phi[c].im /= norm;
        for (auto &v : y[c])
          v /= norm;
      }
    const auto scaled = [&](const auto &factor) {
      std::vector<std::vector<complex>> z(k);
      for (unsigned int c = 0; c < k; ++c)
        {
          z[c] = y[c];
          for (auto &v : z[c])
            v *= factor(c);
        }
      return z;
    };
    basis.multiply(&mv, y, 1., column_pointers(mphi));
    const auto lambda = [&](const unsigned int c) { return kept[c].lambda; };
    if (!mv.empty())
      basis.multiply(&mv, scaled([&](unsigned c) { return lambda(c) * lambda(c); }), 1.,
                     column_pointers(r));
    if (!gv.empty())
      basis.multiply(&gv, scaled([&](unsigned c) { return lambda(c) * omega; }), 1.,
                     column_pointers(r));
    if (!k0v.empty())
      basis.multiply(&k0v, y, 1., column_pointers(r));
    if (!k2v.empty())
      basis.multiply(&k2v, scaled([&](unsigned) { return complex(w); }), 1., column_pointers(r));

    // the bearings' entries: their residual terms, and their share of the norms
    std::map<std::pair<unsigned int, unsigned int>, std::pair<double, double>> entries;
    for (const auto &cp : speed.couplings)
      for (const auto &[I, wi] : (*op.stations)[cp.p])
        for (const auto &[J, wj] : (*op.stations)[cp.q])
          {
            auto &e = entries[{I, J}];
            e.first += cp.k * wi * wj;
            e.second += cp.c * wi * wj;
          }
    double k_norm2 = k00 + 2 * w * k02 + w * w * k22, c_norm2 = w * gg;
    for (const auto &[ij, e] : entries)
      {
        const double kb = op.K0->el(ij.first, ij.second) + w * op.K2->el(ij.first, ij.second);
        const double cb = omega * op.G->el(ij.first, ij.second);
        k_norm2 += (kb + e.first) * (kb + e.first) - kb * kb;
        c_norm2 += (cb + e.second) * (cb + e.second) - cb * cb;
      }
    const double k_norm = std::sqrt(std::max(0., k_norm2)), c_norm = std::sqrt(std::max(0., c_norm2));
    const unsigned int n_st = station_r.size();
    for (unsigned int c = 0; c < k; ++c)
      {
        const complex l = lambda(c);
        for (const auto &[ij, e] : entries)
          {
            const complex v = (e.first + l * e.second) * complex(phi[c].re[ij.second], phi[c].im[ij.second]);
            r[c].re[ij.first] += v.real();
            r[c].im[ij.first] += v.imag();
          }
        const double norm_r = std::sqrt(r[c].re.norm_sqr() + r[c].im.norm_sqr());
        const double scale  = std::norm(l) * m_norm + std::abs(l) * c_norm + k_norm;
        EigenPair    pair;
        pair.lambda         = l;
        pair.backward_error = scale > 0 ? norm_r / scale : norm_r;
        if (!(pair.backward_error <= speed.backward_limit))
          {
            reason << "backward error " << pair.backward_error << " at "
                   << std::abs(l) / (2 * M_PI) << " Hz above the Backward error limit "
                   << speed.backward_limit;
            why = reason.str();
            return false;
          }
        // the eigenvalue's error estimate (doc/theory.md 8.6): right and left
        // residuals in the Q(sigma)^-1 norm, as combinations of the blocks
        if (std::abs(l) / (2 * M_PI) >= speed.rigid_hz)
          {
            const auto &wl = kept[c].w;
            std::vector<complex> xr, xs;
            const auto append = [&](const RowBlock &b, const complex fr, const complex fs) {
              if (b.empty())
                return;
              for (unsigned int i = 0; i < m; ++i)
                xr.push_back(fr * y[c][i]), xs.push_back(fs * wl[i]);
            };
            append(mv, l * l, std::conj(l * l));
            append(gv, l * omega, -std::conj(l) * omega);
            append(k0v, 1., 1.);
            append(k2v, w, w);
            if (!av.empty())
              {
                std::vector<complex> cr(n_st), cs(n_st);
                for (const auto &cp : speed.couplings)
                  {
                    complex ay = 0, aw = 0;
                    for (unsigned int i = 0; i < m; ++i)
                      ay += station_r[cp.q][i] * y[c][i], aw += station_r[cp.p][i] * wl[i];
                    cr[cp.p] += (cp.k + l * cp.c) * ay;
                    cs[cp.q] += (cp.k + std::conj(l) * cp.c) * aw;
                  }
                xr.insert(xr.end(), cr.begin(), cr.end());
                xs.insert(xs.end(), cs.begin(), cs.end());
              }
            // psi^H Q'(lambda) phi on the basis: w^H (2 lambda Mr + Cr) y
            complex d = 0;
            for (unsigned int i = 0; i < m; ++i)
              for (unsigned int j = 0; j < m; ++j)
                d += std::conj(wl[i]) * (2. * l * Mr(i, j) + Cr(i, j)) * y[c][j];
            const double estimate = std::sqrt(inverse_norm_sqr(gram, xr)) *
                                    std::sqrt(inverse_norm_sqr(gram, xs)) /
                                    (std::abs(d) * std::abs(l));
            if (!(estimate <= basis.tolerance()))
              {
                reason << "error estimate " << estimate << " at " << std::abs(l) / (2 * M_PI)
                       << " Hz above the Reduced tolerance " << basis.tolerance();
                why = reason.str();
                return false;
              }
            pair.error_estimate = estimate;
          }
        pair.phi   = std::move(phi[c]);
        pair.m_phi = std::move(mphi[c]);
        out.push_back(std::move(pair));
      }
    for (const auto &p : out)
      worst_estimate = std::max(worst_estimate, p.error_estimate);
    std::sort(out.begin(), out.end(), [](const EigenPair &a, const EigenPair &b) {
      return std::abs(a.lambda) < std::abs(b.lambda);
    });
    return true;
  }
} // namespace rotorfit

namespace rotorfit
{
  bool
  HarmonicReducedModel::respond(const Operators            &op,
                                const Speed                &speed,
                                const std::vector<complex> &F,
                                const double                tolerance,
                                const unsigned int          max_enrichments,
                                const DirectSolver         &factors,
                                std::vector<complex>       &U,
                                double                     &residual,
                                unsigned int               &basis_size) const
  {
    const double      omega = SpeedSchedule::rpm_to_rad_per_s(speed.rpm), w = omega * omega;
    const std::size_t rows  = op.pM->m();
    const unsigned int m    = basis.size();
    const auto        &st   = *op.stations;
    Vector<double>     f_re(rows), f_im(rows);
    for (std::size_t i = 0; i < rows; ++i)
      f_re[i] = F[i].real(), f_im[i] = F[i].imag();
    const double f_norm = std::sqrt(f_re.norm_sqr() + f_im.norm_sqr());
    U.assign(rows, 0.);
    residual   = 0;
    basis_size = m;
    if (!(f_norm > 0))
      return true;
    // Z = A + i B on W = [V E]: A = K_0 + w K_2 + K_b - w M, B = w G + Omega C_b
    const std::array<const RowBlock *, 4> kept{{&mv, &gv, &k0v, &k2v}};
    const std::array<const dealii::PETScWrappers::MPI::SparseMatrix *, 4> sparse{
      {op.pM, op.pG, op.pK0, op.pK2}};
    const std::array<double, 4> a_share{{-w, 0., 1., w}}, b_share{{0., w, 0., 0.}};
    std::vector<Vector<double>>                E;  // enrichments, M-orthonormal to V and each other
    std::vector<std::array<Vector<double>, 4>> AE; // their products with M, G, K_0, K_2
    for (unsigned int round = 0;; ++round)
      {
        const unsigned int ne = E.size(), n = m + ne;
        FullMatrix<double> A(n, n), B(n, n);
        for (unsigned int i = 0; i < m; ++i)
          for (unsigned int j = 0; j < m; ++j)
            {
              A(i, j) = K0r(i, j) + w * K2r(i, j) - w * Mr(i, j);
              B(i, j) = w * Gr(i, j);
            }
        for (unsigned int e = 0; e < ne; ++e)
          for (unsigned int t = 0; t < 4; ++t)
            {
              // V^T A e, e^T A V (from the kept A V: no symmetry assumed), E^T A e
              const auto          column = basis.coefficients(AE[e][t]);
              std::vector<double> row;
              if (!kept[t]->empty())
                basis.apply_transpose(*kept[t], std::vector<double>(E[e].begin(), E[e].end()), 1.,
                                      row);
              for (unsigned int i = 0; i < m; ++i)
                {
                  A(i, m + e) += a_share[t] * column[i];
                  B(i, m + e) += b_share[t] * column[i];
                  const double r_i = row.empty() ? 0. : row[i];
                  A(m + e, i) += a_share[t] * r_i;
                  B(m + e, i) += b_share[t] * r_i;
                }
              for (unsigned int i = 0; i < ne; ++i)
                {
                  const double v = E[i] * AE[e][t];
                  A(m + i, m + e) += a_share[t] * v;
                  B(m + i, m + e) += b_share[t] * v;
                }
            }
        // the bearings on every column: a_p^T W
        std::vector<std::vector<double>> sw(st.size(), std::vector<double>(n, 0.));
        for (unsigned int p = 0; p < st.size(); ++p)
          {
            std::copy(station_r[p].begin(), station_r[p].end(), sw[p].begin());
            for (unsigned int e = 0; e < ne; ++e)
              for (const auto &[I, a] : st[p])
                sw[p][m + e] += a * E[e][I];
          }
        for (const auto &c : speed.couplings)
          for (unsigned int i = 0; i < n; ++i)
            for (unsigned int j = 0; j < n; ++j)
              {
                const double s = sw[c.p][i] * sw[c.q][j];
                A(i, j) += c.k * s;
                B(i, j) += omega * c.c * s;
              }
        // W^T F, and the real block system [A -B; B A] (y_re, y_im) = (b_re, b_im)
        const auto b_re = basis.coefficients(f_re), b_im = basis.coefficients(f_im);
        const int  n2   = 2 * n;
        std::vector<double> S(std::size_t(n2) * n2), x(n2);
        for (unsigned int i = 0; i < n; ++i)
          {
            for (unsigned int j = 0; j < n; ++j)
              {
                S[i + std::size_t(j) * n2]           = A(i, j);
                S[i + std::size_t(n + j) * n2]       = -B(i, j);
                S[n + i + std::size_t(j) * n2]       = B(i, j);
                S[n + i + std::size_t(n + j) * n2]   = A(i, j);
              }
            x[i]     = i < m ? b_re[i] : E[i - m] * f_re;
            x[n + i] = i < m ? b_im[i] : E[i - m] * f_im;
          }
        std::vector<int> pivots(n2);
        int              info = 0, one = 1;
        dgetrf_(&n2, &n2, S.data(), &n2, pivots.data(), &info);
        if (info != 0)
          return false;
        dgetrs_("N", &n2, &one, S.data(), &n2, pivots.data(), x.data(), &n2, &info);
        if (info != 0)
          return false;
        std::vector<complex> y(n);
        for (unsigned int i = 0; i < n; ++i)
          y[i] = complex(x[i], x[n + i]);
        // r = F - Z W y from the kept products (the projection's own)
        const std::vector<complex> yv(y.begin(), y.begin() + m);
        ComplexVector              r{f_re, f_im}, u;
        const std::array<complex, 4> share{{-w, complex(0, w), 1., w}};
        for (unsigned int t = 0; t < 4; ++t)
          if (!kept[t]->empty())
            {
              std::vector<complex> z(yv);
              for (auto &v : z)
                v *= share[t];
              basis.multiply(kept[t], {z}, -1., {&r});
            }
        basis.multiply(nullptr, {yv}, 1., {&u});
        for (unsigned int e = 0; e < ne; ++e)
          {
            const complex ye = y[m + e];
            for (unsigned int t = 0; t < 4; ++t)
              {
                const complex c = share[t] * ye;
                r.re.add(-c.real(), AE[e][t]);
                r.im.add(-c.imag(), AE[e][t]);
              }
            u.re.add(ye.real(), E[e]);
            u.im.add(ye.imag(), E[e]);
          }
        for (const auto &c : speed.couplings)
          {
            complex aq = 0;
            for (unsigned int i = 0; i < n; ++i)
              aq += sw[c.q][i] * y[i];
            const complex v = complex(c.k, omega * c.c) * aq;
            for (const auto &[I, a] : st[c.p])
              {
                r.re[I] -= a * v.real();
                r.im[I] -= a * v.imag();
              }
          }
        residual   = std::sqrt(r.re.norm_sqr() + r.im.norm_sqr()) / f_norm;
        basis_size = n;
        if (residual <= tolerance)
          {
            for (std::size_t i = 0; i < rows; ++i)
              U[i] = complex(u.re[i], u.im[i]);
            return true;
          }
        if (!std::isfinite(residual) || round == max_enrichments)
          return false;
        // enrich by Q(sigma)^-1 of the residual's parts, M-orthonormal to W
        std::vector<Vector<double>> x_new;
        replicated_solve(factors, *op.pM, std::vector<const Vector<double> *>{&r.re, &r.im}, x_new);
        const auto product = [](const dealii::PETScWrappers::MPI::SparseMatrix &a,
                                const Vector<double>                           &v) {
          std::vector<Vector<double>> out;
          replicated_mmult(a, std::vector<const Vector<double> *>{&v}, out);
          return std::move(out[0]);
        };
        unsigned int added = 0;
        for (auto &v : x_new)
          {
            const double size = v.l2_norm();
            for (unsigned int pass = 0; pass < 2; ++pass)
              {
                const Vector<double> mvv = product(*op.pM, v);
                basis.subtract_projection(v, mvv);
                for (const auto &e : E)
                  v.add(-(e * mvv), e);
              }
            const Vector<double> mvv = product(*op.pM, v);
            const double norm = std::sqrt(std::max(0., v * mvv));
            if (!(norm > 1e-10 * size) || !std::isfinite(norm))
              continue;
            v /= norm;
            std::array<Vector<double>, 4> products;
            for (unsigned int t = 0; t < 4; ++t)
              products[t] = product(*sparse[t], v);
            E.push_back(std::move(v));
            AE.push_back(std::move(products));
            ++added;
          }
        if (added == 0)
          return false;
      }
  }
} // namespace rotorfit
