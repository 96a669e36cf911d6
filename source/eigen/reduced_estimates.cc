#include <rotorfit/eigen/prestressed_eigenproblem.h>
#include <rotorfit/linear_algebra/replicated_blocks.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

// PrestressedEigenproblem, part 4: what a reduced speed's modes are checked
// with (doc/theory.md 8.6): the modes' products with the full matrices from
// the kept products A V, and the error estimates of their eigenvalues, by
// back-substitution or from the Gram matrix of the residual blocks.

namespace rotorfit
{
  using namespace dealii;

  PrestressedEigenproblem::Expanded
  PrestressedEigenproblem::expanded(const std::vector<std::vector<std::complex<double>>> &y,
                                    const double                                          omega,
                                    const double                                          w,
                                    const bool transpose) const
  {
    const std::size_t n = matrices.mass.m();
    Expanded          e;
    for (auto *list : {&e.v, &e.m, &e.c, &e.k})
      list->assign(y.size(), ComplexVector{Vector<double>(n), Vector<double>(n)});
    reduced.multiply(nullptr, y, 1., column_pointers(e.v));
    reduced.multiply(&av_mass, y, 1., column_pointers(e.m));
    reduced.multiply(&av_bearing_c, y, 1., column_pointers(e.c));
    reduced.multiply(&av_gyro, y, transpose ? -omega : omega, column_pointers(e.c)); // G^T = -G
    reduced.multiply(&av_tangent, y, 1., column_pointers(e.k));
    reduced.multiply(&av_tangent2, y, w - w_tangent, column_pointers(e.k));
    return e;
  }

  double
  PrestressedEigenproblem::Expanded::mismatch(const BackwardError &backward_error,
                                              const bool           transpose) const
  {
    ComplexVector sum[4];
    const std::vector<ComplexVector> *part[4] = {&v, &m, &c, &k};
    for (unsigned int j = 0; j < 4; ++j)
      for (const auto &z : *part[j])
        if (sum[j].re.size() == 0)
          sum[j] = z;
        else
          sum[j].re += z.re, sum[j].im += z.im;
    return v.empty() ? 0. : backward_error.mismatch(sum[0], sum[1], sum[2], sum[3], transpose);
  }

  std::vector<const RowBlock *>
  PrestressedEigenproblem::residual_blocks() const
  {
    // those kept by their rows last: the Gram matrix back-substitutes them
    // as sparse right-hand sides, the others in blocks across them
    std::vector<const RowBlock *> blocks;
    for (const bool dense : {true, false})
      for (const auto *P : {&av_mass, &av_bearing_c, &av_gyro, &av_tangent, &av_tangent2})
        if (!P->empty() && P->dense() == dense) // (a product zero everywhere keeps nothing)
          blocks.push_back(P);
    return blocks;
  }

  namespace
  {
    /// The factors of the kept products [M V, C_b V, G V, K_t V, K_t2 V] in
    /// Q(lambda) V y (Q(lambda)^H V y with @p transpose: conj(lambda) and
    /// G^T = -G), as expanded() combines them.
    std::array<std::complex<double>, 5>
    residual_factors(const std::complex<double> lambda,
                     const double               omega,
                     const double               dw,
                     const bool                 transpose)
    {
      const std::complex<double> l = transpose ? std::conj(lambda) : lambda;
      return {l * l, l, (transpose ? -omega : omega) * l, 1., dw};
    }
  } // namespace

  std::vector<ComplexVector>
  PrestressedEigenproblem::residuals(const std::vector<std::vector<std::complex<double>>> &y,
                                     const std::vector<std::complex<double>> &lambda,
                                     const double                             omega,
                                     const double                             w,
                                     const bool                               transpose) const
  {
    const std::size_t          n = matrices.mass.m();
    std::vector<ComplexVector> r(y.size(), ComplexVector{Vector<double>(n), Vector<double>(n)});
    const auto z = column_pointers(r);
    const RowBlock *P[5] = {&av_mass, &av_bearing_c, &av_gyro, &av_tangent, &av_tangent2};
    std::vector<std::vector<std::complex<double>>> scaled(y);
    for (unsigned int k = 0; k < 5; ++k)
      {
        for (std::size_t c = 0; c < y.size(); ++c)
          {
            const auto a = residual_factors(lambda[c], omega, w - w_tangent, transpose)[k];
            for (std::size_t j = 0; j < y[c].size(); ++j)
              scaled[c][j] = a * y[c][j];
          }
        reduced.multiply(P[k], scaled, 1., z);
      }
    return r;
  }

  std::vector<std::complex<double>>
  PrestressedEigenproblem::residual_coefficients(const std::vector<std::complex<double>> &y,
                                                 const std::complex<double>               lambda,
                                                 const double                             omega,
                                                 const double                             w,
                                                 const bool transpose,
                                                 const std::vector<const RowBlock *> &blocks) const
  {
    // Q(lambda) V y = lambda^2 M V y + lambda (C_b V + omega G V) y +
    // (K_t V + (w - w_tangent) K_t2 V) y, as expanded() makes it; its
    // transpose with conj(lambda) and C_b - omega G
    const auto                 a    = residual_factors(lambda, omega, w - w_tangent, transpose);
    const RowBlock *P[5] = {&av_mass, &av_bearing_c, &av_gyro, &av_tangent, &av_tangent2};
    std::vector<std::complex<double>> x;
    for (const auto *block : blocks) // (in the blocks' order, as the Gram matrix's)
      {
        const auto k = std::find(P, P + 5, block) - P;
        for (const auto &c : y)
          x.push_back(a[k] * c);
      }
    return x;
  }

  void
  PrestressedEigenproblem::prepare_gram(const bool due)
  {
    const auto key = std::make_tuple(reduced.version(), key_tangent.k_sigma, key_tangent.rpm,
                                     key_bearing.rpm, eigensolver.linear_solver().n_operators());
    if (gram.key != key)
      gram = ResidualGram{{}, residual_blocks(), key};
    // (its rounding floor stays far below the tolerance)
    if (gram.g.empty() && !gram.refused && reduced.tolerance() >= 10 * gram_floor &&
        (due || reduced.version() == gram_eager_version))
      {
        const auto t0 = std::chrono::steady_clock::now();
        // S^-1 K_t V = V - sigma^2 S^-1 M V where S is this tangent's
        const auto at = [&](const RowBlock &P) {
          return std::find(gram.blocks.begin(), gram.blocks.end(), &P) - gram.blocks.begin();
        };
        const bool same_tangent =
          undamped_factor == std::make_pair(eigensolver.linear_solver().n_operators(),
                                            av_tangent_serial) &&
          at(av_mass) < at(av_tangent) && at(av_tangent) < std::ptrdiff_t(gram.blocks.size());
        const GramShortcut shortcut{std::size_t(at(av_mass)), std::size_t(at(av_tangent)),
                                    &reduced.matrix(),
                                    -eigensolver.shift() * eigensolver.shift()};
        gram.g = replicated_inverse_gram(eigensolver.linear_solver(), matrices.mass, gram.blocks,
                                         same_tangent ? &shortcut : nullptr);
        gram.e = replicated_gram(gram.blocks, comm);
        gram.seconds  = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        gram.checked  = false;
      }
  }

  std::vector<double>
  PrestressedEigenproblem::error_estimates(const BackwardError                           &backward_error,
                                           const std::vector<const EigenPair *>          &modes,
                                           const std::vector<const ReducedBasis::Pair *> &dense,
                                           const std::vector<double>                     &scale,
                                           const std::vector<const ComplexVector *>      &residual,
                                           const FullMatrix<double>                      &Cr,
                                           const double                                   omega,
                                           const double                                   w)
  {
    // A Ritz value errs by about s^H Q^-1 r / (y^H Q'(lambda) phi), with the
    // right residual r = Q(lambda) phi and the left one s = Q(lambda)^H y of
    // the reduced left vector y (a damped rotor's left and right vectors
    // differ, so the error is not second order in r alone). Q(sigma) of the
    // latest full solve stands for Q: sigma lies far below the modes, and
    // the error components outside the basis are stiffer than the mode
    // (doc/theory.md 8.6). Bounded by Cauchy-Schwarz in its norm.
    const auto dot = [](const ComplexVector &a, const ComplexVector &b) { // a^H b
      return std::complex<double>(a.re * b.re + a.im * b.im, a.re * b.im - a.im * b.re);
    };
    const auto axpy = [](const std::complex<double> a, const ComplexVector &x, ComplexVector &z) {
      z.re.add(a.real(), x.re, -a.imag(), x.im);
      z.im.add(a.imag(), x.re, a.real(), x.im);
    };
    std::vector<std::vector<std::complex<double>>> left;
    std::vector<std::complex<double>>              lambda, sum(reduced.size());
    for (std::size_t k = 0; k < dense.size(); ++k)
      {
        left.push_back(dense[k]->w);
        lambda.push_back(modes[k]->lambda);
        for (std::size_t j = 0; j < sum.size(); ++j)
          sum[j] += dense[k]->w[j];
      }
    // y^H Q'(lambda) phi = y^H (2 lambda M + C) phi on the basis:
    // w^H (2 lambda M_r + C_r) y / scale (phi = V y / scale, y = V w)
    std::vector<double> denominator(modes.size()), estimate(modes.size());
    for (std::size_t k = 0; k < modes.size(); ++k)
      {
        const auto &yr = dense[k]->y, &wl = dense[k]->w;
        std::complex<double> d = 0;
        for (std::size_t i = 0; i < yr.size(); ++i)
          {
            std::complex<double> row = 0;
            for (std::size_t j = 0; j < yr.size(); ++j)
              row += (2. * modes[k]->lambda * p_mass(i, j) + Cr(i, j)) * yr[j];
            d += std::conj(wl[i]) * row;
          }
        denominator[k] = std::abs(d) * std::abs(modes[k]->lambda) / scale[k];
      }
    // the left residuals s = Q(lambda)^H y straight from the kept products
    // with C^T = C_b - omega G and K_t^T = K_t, where the sparse transposed
    // products on the sum of the left vectors agree (not so with
    // cross-coupled bearings: then the sparse products for each)
    // (with symmetric bearings C^T = C_b - Omega G and K_t^T = K_t hold by
    // construction: decided with the products' check; cross-coupled ones
    // at every speed, as the asymmetry's share changes with the speed)
    auto &check = product_check;
    if (!check.transposed_known || check.due || !bearings.symmetric(last_rpm, true))
      {
        check.transposed_kept =
          expanded({sum}, omega, w, true).mismatch(backward_error, true) <= product_tolerance;
        check.transposed_known = true;
      }
    const bool kept = check.transposed_kept;
    std::vector<ComplexVector> s; // (from the kept products only where back-substituted, below)
    if (!kept)
      {
        Expanded y = expanded(left, omega, w, true);
        s.resize(modes.size());
        for (std::size_t k = 0; k < left.size(); ++k)
          {
            replicated_vmult(matrices.mass, y.v[k], y.m[k]);
            replicated_vmult(damping, y.v[k], y.c[k], true);
            replicated_vmult(tangent, y.v[k], y.k[k], true);
            const std::complex<double> l = std::conj(modes[k]->lambda);
            s[k]                         = std::move(y.k[k]);
            axpy(l * l, y.m[k], s[k]);
            axpy(l, y.c[k], s[k]);
          }
      }
    const auto ratio = [&](const std::size_t k, const double norm_r, const double norm_s) {
      return denominator[k] > 0 ? norm_r * norm_s / denominator[k] :
                                  std::numeric_limits<double>::infinity();
    };

    // Both residuals lie in the span of the kept products [M V, C_b V, G V,
    // K_t V, K_t2 V] (unless the sparse transposed products were needed):
    // with their Gram matrix in the S^-1 norm a speed's estimates cost no
    // back-substitution. It costs as many back-substituted columns as the
    // blocks have, so it is made where the basis is to serve many speeds
    // (a lasting anchor's), or once the estimates on it have cost as much.
    const unsigned int rhs_count = 4 * modes.size();
    if (kept)
      prepare_gram(gram.spent + rhs_count > gram.blocks.size() * reduced.size());
    const auto &blocks = gram.blocks;
    // (a Gram matrix made before the modes were expanded is checked at the
    // first speed whose left residuals come from the kept products)
    const bool fresh = kept && !gram.g.empty() && !gram.checked;
    std::vector<double> from_gram(modes.size());
    if (kept && !gram.g.empty())
      {
        for (std::size_t k = 0; k < modes.size(); ++k)
          {
            const std::complex<double>        l = modes[k]->lambda;
            std::vector<std::complex<double>> x =
              residual_coefficients(dense[k]->y, l, omega, w, false, blocks);
            for (auto &c : x)
              c /= scale[k];
            const double norm_r = std::sqrt(std::abs(inverse_norm_sqr(gram.g, x)));
            x                   = residual_coefficients(dense[k]->w, l, omega, w, true, blocks);
            from_gram[k] = ratio(k, norm_r, std::sqrt(std::abs(inverse_norm_sqr(gram.g, x))));
          }
        // a new Gram matrix is checked once against the back-substitutions
        // below, on this speed's modes; after that it stands for them
        if (!fresh)
          return from_gram;
      }
    else
      gram.spent += rhs_count;

    // the vectors of both residuals where the reduced solve made none
    if (kept)
      s = residuals(left, lambda, omega, w, true);
    std::vector<ComplexVector>         own;
    std::vector<const ComplexVector *> right(residual);
    if (std::find(right.begin(), right.end(), nullptr) != right.end())
      {
        std::vector<std::vector<std::complex<double>>> y;
        for (std::size_t k = 0; k < dense.size(); ++k)
          {
            y.push_back(dense[k]->y);
            for (auto &c : y.back())
              c /= scale[k];
          }
        own = residuals(y, lambda, omega, w, false);
        for (std::size_t k = 0; k < right.size(); ++k)
          right[k] = &own[k];
      }

    // back-substituted for six modes at a time: the right-hand
    // sides, the solutions and MUMPS's copy of them are then 3 x 24 columns
    // instead of 3 x 48, at the memory peak of a run
    constexpr std::size_t modes_per_solve = 6;
    for (std::size_t first = 0; first < modes.size(); first += modes_per_solve)
      {
        const std::size_t                   end = std::min(modes.size(), first + modes_per_solve);
        std::vector<const Vector<double> *> rhs;
        for (std::size_t k = first; k < end; ++k)
          rhs.insert(rhs.end(), {&right[k]->re, &right[k]->im, &s[k].re, &s[k].im});
        std::vector<Vector<double>> t;
        replicated_solve(eigensolver.linear_solver(), matrices.mass, rhs, t);
        for (std::size_t k = first; k < end; ++k)
          {
            const std::size_t   j = 4 * (k - first);
            const ComplexVector tr{std::move(t[j]), std::move(t[j + 1])},
              ts{std::move(t[j + 2]), std::move(t[j + 3])};
            estimate[k] = ratio(k, std::sqrt(std::abs(dot(*right[k], tr))),
                                std::sqrt(std::abs(dot(s[k], ts))));
          }
      }
    if (fresh)
      {
        // rounding of the Gram sums leaves a floor in an estimate (the
        // tutorial disk: 6e-15 with an LDL^T, 1.4e-12 with the LU of a
        // damped anchor), where the two may differ in relative terms; above
        // it both must agree, else the back-substitutions stay
        double difference = 0;
        for (std::size_t k = 0; k < modes.size(); ++k)
          difference = std::max(difference, std::abs(from_gram[k] - estimate[k]) /
                                              std::max(estimate[k], gram_floor / gram_agreement));
        gram.refused = !(difference <= gram_agreement);
        gram.checked = true;
        ++gram_builds;
        gram_worst_difference = std::max(gram_worst_difference, difference);
        std::ostringstream line;
        line << "  eigen: Gram matrix of the residual blocks (" << reduced.size() << " x "
             << blocks.size() << " columns) in " << std::setprecision(3) << gram.seconds
             << " s; its estimates differ from the back-substituted ones by "
             << std::setprecision(2) << difference
             << (gram.refused ? ": not used (the estimates back-substitute on this basis)" : "")
             << '\n';
        log << line.str();
        if (gram.refused)
          gram.g.clear();
      }
    return estimate;
  }
} // namespace rotorfit
