#include <rotorfit/eigen/reduced_estimates.h>
#include <rotorfit/linear_algebra/replicated_blocks.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

// What a reduced speed's modes are checked with (doc/theory.md 8.6): the
// error estimates of their eigenvalues, by back-substitution or from the
// Gram matrix of the residual blocks.

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    /// a^H b
    std::complex<double>
    dot(const ComplexVector &a, const ComplexVector &b)
    {
      return std::complex<double>(a.re * b.re + a.im * b.im, a.re * b.im - a.im * b.re);
    }

    /// z += a x
    void
    axpy(const std::complex<double> a, const ComplexVector &x, ComplexVector &z)
    {
      z.re.add(a.real(), x.re, -a.imag(), x.im);
      z.im.add(a.imag(), x.re, a.real(), x.im);
    }

    /// The error estimate from the residuals' norms and the denominator.
    double
    ratio(const double denominator, const double norm_r, const double norm_s)
    {
      return denominator > 0 ? norm_r * norm_s / denominator :
                               std::numeric_limits<double>::infinity();
    }
  } // namespace

  ReducedEstimates::ReducedEstimates(ReducedModel            &reduced,
                                     const SpeedTangent      &operators,
                                     const DampedEigensolver &eigensolver,
                                     const Bearings          &bearings,
                                     Log                     &log)
    : reduced(reduced)
    , operators(operators)
    , eigensolver(eigensolver)
    , bearings(bearings)
    , log(log)
  {}

  void
  ReducedEstimates::prepare_gram(const bool due)
  {
    auto      &gram = residual_gram;
    const auto key  = std::make_tuple(reduced.basis().version(), reduced.tangent_key()->k_sigma,
                                     reduced.tangent_key()->rpm, reduced.bearing_key()->rpm,
                                     eigensolver.linear_solver().n_operators());
    if (gram.key != key)
      gram = ResidualGram{{}, reduced.residual_blocks(), key};
    // (its rounding floor stays far below the tolerance)
    if (gram.g.empty() && !gram.refused && reduced.basis().tolerance() >= 10 * gram_floor &&
        (due || reduced.lasting()))
      {
        const auto t0 = std::chrono::steady_clock::now();
        const auto &p = reduced.projections();
        // S^-1 K_t V = V - sigma^2 S^-1 M V where S is this tangent's
        const auto at = [&](const RowBlock &P) {
          return std::find(gram.blocks.begin(), gram.blocks.end(), &P) - gram.blocks.begin();
        };
        const bool same_tangent =
          undamped_factor == std::make_pair(eigensolver.linear_solver().n_operators(),
                                            p.tangent_serial) &&
          at(p.av_mass) < at(p.av_tangent) && at(p.av_tangent) < std::ptrdiff_t(gram.blocks.size());
        const GramShortcut shortcut{std::size_t(at(p.av_mass)), std::size_t(at(p.av_tangent)),
                                    &reduced.basis().matrix(),
                                    -eigensolver.shift() * eigensolver.shift()};
        gram.g = replicated_inverse_gram(eigensolver.linear_solver(), operators.mass(), gram.blocks,
                                         same_tangent ? &shortcut : nullptr);
        gram.e = replicated_gram(gram.blocks, operators.communicator());
        gram.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        gram.checked = false;
      }
  }

  std::vector<double>
  ReducedEstimates::denominators(const std::vector<const EigenPair *>          &modes,
                                 const std::vector<const ReducedBasis::Pair *> &dense,
                                 const std::vector<double>                     &scale,
                                 const FullMatrix<double>                      &Cr) const
  {
    // y^H Q'(lambda) phi = y^H (2 lambda M + C) phi on the basis:
    // w^H (2 lambda M_r + C_r) y / scale (phi = V y / scale, y = V w)
    const FullMatrix<double> &Mr = reduced.projections().mass;
    std::vector<double>       denominator(modes.size());
    for (std::size_t k = 0; k < modes.size(); ++k)
      {
        const auto &yr = dense[k]->y, &wl = dense[k]->w;
        std::complex<double> d = 0;
        for (std::size_t i = 0; i < yr.size(); ++i)
          {
            std::complex<double> row = 0;
            for (std::size_t j = 0; j < yr.size(); ++j)
              row += (2. * modes[k]->lambda * Mr(i, j) + Cr(i, j)) * yr[j];
            d += std::conj(wl[i]) * row;
          }
        denominator[k] = std::abs(d) * std::abs(modes[k]->lambda) / scale[k];
      }
    return denominator;
  }

  bool
  ReducedEstimates::transposed_kept(const BackwardError                     &backward_error,
                                    const std::vector<std::complex<double>> &sum,
                                    const double                             omega,
                                    const double                             w,
                                    const double                             rpm)
  {
    // the left residuals s = Q(lambda)^H y straight from the kept products
    // with C^T = C_b - omega G and K_t^T = K_t, where the sparse transposed
    // products on the sum of the left vectors agree (not so with
    // cross-coupled bearings: then the sparse products for each)
    // (with symmetric bearings C^T = C_b - Omega G and K_t^T = K_t hold by
    // construction: decided with the products' check; cross-coupled ones
    // at every speed, as the asymmetry's share changes with the speed)
    auto &check = *reduced.product_check();
    if (!check.transposed_known || check.due || !bearings.symmetric(rpm, true))
      {
        check.transposed_kept = reduced.expanded({sum}, omega, w, true)
                                  .mismatch(backward_error, true) <= ReducedModel::product_tolerance;
        check.transposed_known = true;
      }
    return check.transposed_kept;
  }

  std::vector<ComplexVector>
  ReducedEstimates::sparse_left_residuals(
    const std::vector<std::vector<std::complex<double>>> &left,
    const std::vector<const EigenPair *>                 &modes,
    const double                                          omega,
    const double                                          w) const
  {
    ReducedModel::Expanded     y = reduced.expanded(left, omega, w, true);
    std::vector<ComplexVector> s(modes.size());
    for (std::size_t k = 0; k < left.size(); ++k)
      {
        replicated_vmult(operators.mass(), y.v[k], y.m[k]);
        replicated_vmult(operators.damping(), y.v[k], y.c[k], true);
        replicated_vmult(operators.stiffness(), y.v[k], y.k[k], true);
        const std::complex<double> l = std::conj(modes[k]->lambda);
        s[k]                         = std::move(y.k[k]);
        axpy(l * l, y.m[k], s[k]);
        axpy(l, y.c[k], s[k]);
      }
    return s;
  }

  std::vector<double>
  ReducedEstimates::from_gram(const std::vector<const EigenPair *>          &modes,
                              const std::vector<const ReducedBasis::Pair *> &dense,
                              const std::vector<double>                     &scale,
                              const std::vector<double>                     &denominator,
                              const double                                   omega,
                              const double                                   w) const
  {
    const auto         &gram = residual_gram;
    std::vector<double> estimate(modes.size());
    for (std::size_t k = 0; k < modes.size(); ++k)
      {
        const std::complex<double>        l = modes[k]->lambda;
        std::vector<std::complex<double>> x =
          reduced.residual_coefficients(dense[k]->y, l, omega, w, false, gram.blocks);
        for (auto &c : x)
          c /= scale[k];
        const double norm_r = std::sqrt(std::abs(inverse_norm_sqr(gram.g, x)));
        x = reduced.residual_coefficients(dense[k]->w, l, omega, w, true, gram.blocks);
        estimate[k] =
          ratio(denominator[k], norm_r, std::sqrt(std::abs(inverse_norm_sqr(gram.g, x))));
      }
    return estimate;
  }

  std::vector<double>
  ReducedEstimates::estimates(const BackwardError                           &backward_error,
                              const std::vector<const EigenPair *>          &modes,
                              const std::vector<const ReducedBasis::Pair *> &dense,
                              const std::vector<double>                     &scale,
                              const std::vector<const ComplexVector *>      &residual,
                              const FullMatrix<double>                      &Cr,
                              const double                                   omega,
                              const double                                   w,
                              const double                                   rpm)
  {
    // A Ritz value errs by about s^H Q^-1 r / (y^H Q'(lambda) phi), with the
    // right residual r = Q(lambda) phi and the left one s = Q(lambda)^H y of
    // the reduced left vector y (a damped rotor's left and right vectors
    // differ, so the error is not second order in r alone). Q(sigma) of the
    // latest full solve stands for Q: sigma lies far below the modes, and
    // the error components outside the basis are stiffer than the mode
    // (doc/theory.md 8.6). Bounded by Cauchy-Schwarz in its norm.
    std::vector<std::vector<std::complex<double>>> left;
    std::vector<std::complex<double>>              lambda, sum(reduced.basis().size());
    for (std::size_t k = 0; k < dense.size(); ++k)
      {
        left.push_back(dense[k]->w);
        lambda.push_back(modes[k]->lambda);
        for (std::size_t j = 0; j < sum.size(); ++j)
          sum[j] += dense[k]->w[j];
      }
    const std::vector<double> denominator = denominators(modes, dense, scale, Cr);
    std::vector<double>       estimate(modes.size());
    const bool kept = transposed_kept(backward_error, sum, omega, w, rpm);
    // (from the kept products only where back-substituted, below)
    std::vector<ComplexVector> s;
    if (!kept)
      s = sparse_left_residuals(left, modes, omega, w);

    // Both residuals lie in the span of the kept products [M V, C_b V, G V,
    // K_t V, K_t2 V] (unless the sparse transposed products were needed):
    // with their Gram matrix in the S^-1 norm a speed's estimates cost no
    // back-substitution. It costs as many back-substituted columns as the
    // blocks have, so it is made where the basis is to serve many speeds
    // (a lasting anchor's), or once the estimates on it have cost as much.
    auto              &gram      = residual_gram;
    const unsigned int rhs_count = 4 * modes.size();
    if (kept)
      prepare_gram(gram.spent + rhs_count > gram.blocks.size() * reduced.basis().size());
    // (a Gram matrix made before the modes were expanded is checked at the
    // first speed whose left residuals come from the kept products)
    const bool          fresh = kept && !gram.g.empty() && !gram.checked;
    std::vector<double> gram_estimate(modes.size());
    if (kept && !gram.g.empty())
      {
        gram_estimate = from_gram(modes, dense, scale, denominator, omega, w);
        // a new Gram matrix is checked once against the back-substitutions
        // below, on this speed's modes; after that it stands for them
        if (!fresh)
          return gram_estimate;
      }
    else
      gram.spent += rhs_count;

    // the vectors of both residuals where the reduced solve made none
    if (kept)
      s = reduced.residuals(left, lambda, omega, w, true);
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
        own = reduced.residuals(y, lambda, omega, w, false);
        for (std::size_t k = 0; k < right.size(); ++k)
          right[k] = &own[k];
      }
    back_substitute(right, s, denominator, estimate);
    if (fresh)
      check_gram(gram_estimate, estimate);
    return estimate;
  }

  void
  ReducedEstimates::back_substitute(const std::vector<const ComplexVector *> &right,
                                    const std::vector<ComplexVector>         &s,
                                    const std::vector<double>                &denominator,
                                    std::vector<double>                      &estimate) const
  {
    // back-substituted for six modes at a time: the right-hand
    // sides, the solutions and MUMPS's copy of them are then 3 x 24 columns
    // instead of 3 x 48, at the memory peak of a run
    constexpr std::size_t modes_per_solve = 6;
    const std::size_t     n_modes         = estimate.size();
    for (std::size_t first = 0; first < n_modes; first += modes_per_solve)
      {
        const std::size_t                   end = std::min(n_modes, first + modes_per_solve);
        std::vector<const Vector<double> *> rhs;
        for (std::size_t k = first; k < end; ++k)
          rhs.insert(rhs.end(), {&right[k]->re, &right[k]->im, &s[k].re, &s[k].im});
        std::vector<Vector<double>> t;
        replicated_solve(eigensolver.linear_solver(), operators.mass(), rhs, t);
        for (std::size_t k = first; k < end; ++k)
          {
            const std::size_t   j = 4 * (k - first);
            const ComplexVector tr{std::move(t[j]), std::move(t[j + 1])},
              ts{std::move(t[j + 2]), std::move(t[j + 3])};
            estimate[k] = ratio(denominator[k], std::sqrt(std::abs(dot(*right[k], tr))),
                                std::sqrt(std::abs(dot(s[k], ts))));
          }
      }
  }

  void
  ReducedEstimates::check_gram(const std::vector<double> &gram_estimate,
                               const std::vector<double> &estimate)
  {
    // rounding of the Gram sums leaves a floor in an estimate (the
    // tutorial disk: 6e-15 with an LDL^T, 1.4e-12 with the LU of a
    // damped anchor), where the two may differ in relative terms; above
    // it both must agree, else the back-substitutions stay
    auto  &gram       = residual_gram;
    double difference = 0;
    for (std::size_t k = 0; k < estimate.size(); ++k)
      difference = std::max(difference, std::abs(gram_estimate[k] - estimate[k]) /
                                          std::max(estimate[k], gram_floor / gram_agreement));
    gram.refused = !(difference <= gram_agreement);
    gram.checked = true;
    ++builds;
    worst_difference = std::max(worst_difference, difference);
    std::ostringstream line;
    line << "  eigen: Gram matrix of the residual blocks (" << reduced.basis().size() << " x "
         << gram.blocks.size() << " columns) in " << std::setprecision(3) << gram.seconds
         << " s; its estimates differ from the back-substituted ones by "
         << std::setprecision(2) << difference
         << (gram.refused ? ": not used (the estimates back-substitute on this basis)" : "")
         << '\n';
    log << line.str();
    if (gram.refused)
      gram.g.clear();
  }

  void
  ReducedEstimates::check_residual_norms(const double difference)
  {
    auto &gram     = residual_gram;
    gram.e_checked = true;
    gram.e_refused = Utilities::MPI::max(difference <= gram_agreement ? 0 : 1,
                                         operators.communicator()) == 1;
    norms_worst_difference = std::max(norms_worst_difference, difference);
    std::ostringstream line;
    line << "  eigen: residual norms from the Gram matrix of the blocks differ from the "
            "vectors' by "
         << std::setprecision(2) << difference
         << (gram.e_refused ? ": not used (the residual vectors stay on this basis)" : "")
         << '\n';
    log << line.str();
  }
} // namespace rotorfit

