#include <rotorfit/harmonic/harmonic_reduced_model.h>
#include <rotorfit/linear_algebra/replicated_blocks.h>
#include <rotorfit/statics/speed_schedule.h>

#include <algorithm>
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
                                   const DirectSolver           &factors)
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
        reason << "coverage: the modes reach " << reach / (2 * M_PI) << " Hz from the shift";
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
                   << std::abs(l) / (2 * M_PI) << " Hz";
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
                       << " Hz";
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
