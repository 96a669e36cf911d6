#include <rotorfit/eigen/reduced_solve.h>
#include <rotorfit/linear_algebra/replicated_blocks.h>
#include <rotorfit/statics/speed_schedule.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>

// A basis per contact segment (tied set) from the anchors; a speed is
// served by the projected problem when every mode it keeps meets the
// reduced tolerance on the full matrices and no mode outside the basis can
// have moved into the wanted range since the nearest anchor.

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    /// The dense eigenpairs (eigenvalue, right and left vectors) of rank 0
    /// on every rank, so that every rank takes the same decisions (and
    /// makes the same collective calls).
    void
    broadcast(std::vector<ReducedBasis::Pair> &pairs, const unsigned int m, const MPI_Comm comm)
    {
      if (Utilities::MPI::n_mpi_processes(comm) == 1)
        return;
      unsigned long count = pairs.size();
      MPI_Bcast(&count, 1, MPI_UNSIGNED_LONG, 0, comm);
      const std::size_t   stride = 2 + 4 * m;
      std::vector<double> flat(count * stride);
      if (Utilities::MPI::this_mpi_process(comm) == 0)
        for (std::size_t k = 0; k < count; ++k)
          {
            double *f = flat.data() + k * stride;
            f[0]      = pairs[k].lambda.real();
            f[1]      = pairs[k].lambda.imag();
            for (unsigned int i = 0; i < m; ++i)
              {
                f[2 + 2 * i] = pairs[k].y[i].real(), f[3 + 2 * i] = pairs[k].y[i].imag();
                f[2 + 2 * m + 2 * i] = pairs[k].w[i].real();
                f[3 + 2 * m + 2 * i] = pairs[k].w[i].imag();
              }
          }
      MPI_Bcast(flat.data(), flat.size(), MPI_DOUBLE, 0, comm);
      pairs.assign(count, {});
      for (std::size_t k = 0; k < count; ++k)
        {
          const double *f = flat.data() + k * stride;
          pairs[k].lambda = {f[0], f[1]};
          pairs[k].y.resize(m);
          pairs[k].w.resize(m);
          for (unsigned int i = 0; i < m; ++i)
            {
              pairs[k].y[i] = {f[2 + 2 * i], f[3 + 2 * i]};
              pairs[k].w[i] = {f[2 + 2 * m + 2 * i], f[3 + 2 * m + 2 * i]};
            }
        }
    }
  } // namespace

  ReducedSolve::ReducedSolve(ReducedModel            &reduced,
                             ReducedEstimates        &estimates,
                             const SpeedTangent      &operators,
                             const DampedEigensolver &eigensolver,
                             const ModeClassifier    &classifier,
                             Log                     &log)
    : reduced(reduced)
    , estimates(estimates)
    , operators(operators)
    , eigensolver(eigensolver)
    , classifier(classifier)
    , log(log)
  {}

  bool
  ReducedSolve::solve_dense(const StaticState &state,
                            const unsigned int nev,
                            Dense             &d,
                            std::string       &why) const
  {
    const auto  &p     = reduced.projections();
    const double sigma = eigensolver.shift();
    d.omega            = SpeedSchedule::rpm_to_rad_per_s(state.rpm);
    d.w                = state.w();
    d.Kr               = p.tangent0;
    d.Cr               = p.bearing_c;
    d.Kr.add(state.w(), p.tangent2);
    d.Cr.add(d.omega, p.gyro);
    const bool solved = reduced.basis().solve(p.mass, d.Cr, d.Kr, d.all);
    const MPI_Comm comm = operators.communicator();
    if (Utilities::MPI::min(solved ? 1 : 0, comm) == 0)
      {
        why = "LAPACK dgeev failed on the projected problem";
        return false;
      }
    broadcast(d.all, reduced.basis().size(), comm);
    std::sort(d.all.begin(), d.all.end(), [sigma](const auto &a, const auto &b) {
      return std::abs(a.lambda - sigma) < std::abs(b.lambda - sigma);
    });
    // the nev eigenvalues nearest the shift, conjugates counted twice, as
    // the full solve picks them
    for (unsigned int count = 0, k = 0; count < nev && k < d.all.size(); ++k)
      {
        d.picked.push_back(k);
        d.y.push_back(d.all[k].y);
        count += d.all[k].lambda.imag() != 0 ? 2 : 1;
      }
    for (const auto k : d.picked)
      d.lambda.push_back(d.all[k].lambda);
    return true;
  }

  void
  ReducedSolve::expand(const Dense &d, const BackwardError &backward_error, const bool checked,
                       Expansion &e)
  {
    // phi = V y, M phi and the residual Q(lambda) phi from the kept products
    // A V: dense products for all modes at once instead of sparse ones per
    // mode (C phi and K_t phi are not kept: only the residual is needed)
    const std::size_t n = d.picked.size();
    e.v.resize(d.y.size());
    e.mv.resize(d.y.size());
    reduced.basis().multiply(nullptr, d.y, 1., column_pointers(e.v));
    reduced.basis().multiply(&reduced.projections().av_mass, d.y, 1., column_pointers(e.mv));
    // the right residuals' norms from the Euclidean Gram matrix of the
    // residual blocks where the basis has one and its estimates need no
    // back-substitution (no n-long residual vectors: a third of a reduced
    // speed on TS); checked once against the vectors, at its first speed
    const auto &gram = estimates.gram();
    e.gram_norms     = checked && !gram.e.empty() && !gram.e_refused && !gram.g.empty() &&
                   gram.checked; // (prepare_gram before: the speed's key)
    e.norm_r.assign(n, 0.);
    if (e.gram_norms)
      for (std::size_t i = 0; i < n; ++i)
        e.norm_r[i] = std::sqrt(inverse_norm_sqr(
          gram.e,
          reduced.residual_coefficients(d.y[i], d.lambda[i], d.omega, d.w, false, gram.blocks)));
    if (!e.gram_norms || !gram.e_checked)
      e.residual = reduced.residuals(d.y, d.lambda, d.omega, d.w, false);
    e.usable.resize(n);
    e.scale.resize(n);
    e.sum.resize(reduced.basis().size());
    for (std::size_t i = 0; i < n; ++i)
      {
        e.scale[i]  = std::sqrt(e.v[i].re.norm_sqr() + e.v[i].im.norm_sqr());
        e.usable[i] = e.scale[i] > 0;
        if (e.usable[i])
          {
            for (ComplexVector *z : {&e.v[i], &e.mv[i]})
              z->re /= e.scale[i], z->im /= e.scale[i];
            if (!e.residual.empty())
              e.residual[i].re /= e.scale[i], e.residual[i].im /= e.scale[i];
            e.norm_r[i] /= e.scale[i];
            for (std::size_t j = 0; j < e.sum.size(); ++j)
              e.sum[j] += d.y[i][j] / e.scale[i];
          }
      }
    if (e.gram_norms && e.residual.empty())
      residuals_near_limit(d, backward_error, e);
  }

  void
  ReducedSolve::residuals_near_limit(const Dense &d, const BackwardError &backward_error,
                                     Expansion &e)
  {
    // a mode near the Backward error limit is judged on its vector (the
    // same decision on every rank)
    bool near_limit = false;
    for (std::size_t i = 0; i < d.picked.size(); ++i)
      near_limit |= e.usable[i] && !(backward_error.from_norm(d.lambda[i], 1., e.norm_r[i]) <=
                                     1e-2 * eigensolver.backward_error_limit());
    if (Utilities::MPI::max(near_limit ? 1 : 0, operators.communicator()) == 1)
      {
        e.residual = reduced.residuals(d.y, d.lambda, d.omega, d.w, false);
        for (std::size_t j = 0; j < d.picked.size(); ++j)
          if (e.usable[j])
            e.residual[j].re /= e.scale[j], e.residual[j].im /= e.scale[j];
      }
    else
      ++estimates.norm_speeds;
  }

  double
  ReducedSolve::check_products(const Dense         &d,
                               const Expansion     &e,
                               const BackwardError &backward_error,
                               const bool           checked,
                               const double         rpm,
                               bool                &checked_now,
                               std::ostringstream  &reason)
  {
    // the products are checked against this speed's sparse matrices on one
    // combination of the modes: the checks on the full matrices rest on them
    auto &check = reduced.product_check();
    if (check)
      check->due = false;
    checked_now = checked && reduced.product_check_due(rpm);
    // (a root-solve trial before any check: its reasons are not read)
    const double mismatch =
      checked_now ? reduced.expanded({e.sum}, d.omega, d.w, false).mismatch(backward_error, false) :
                    (check ? check->mismatch : 0.);
    if (checked_now)
      check->mismatch = mismatch, check->rpm = rpm;
    else if (checked)
      ++checks_skipped;
    if (!(mismatch <= ReducedModel::product_tolerance))
      reason << "the reduced model's products differ from this speed's matrices by "
             << std::setprecision(3) << mismatch << " (relative)";
    return mismatch;
  }

  double
  ReducedSolve::make_pairs(Dense                  &d,
                           Expansion              &e,
                           const BackwardError    &backward_error,
                           const bool              checked,
                           std::vector<EigenPair> &pairs)
  {
    constexpr double agreement = ReducedEstimates::gram_agreement;
    constexpr double floor     = ReducedEstimates::gram_floor;
    const double     sigma     = eigensolver.shift();
    double           radius = 0, gram_norm_difference = 0;
    for (std::size_t i = 0; i < d.picked.size(); ++i)
      {
        if (!e.usable[i])
          continue;
        EigenPair p;
        p.lambda = d.all[d.picked[i]].lambda;
        p.phi    = std::move(e.v[i]);
        p.m_phi  = std::move(e.mv[i]);
        if (checked)
          p.backward_error = e.residual.empty() ?
                               backward_error.from_norm(p.lambda, 1., e.norm_r[i]) :
                               backward_error.from_residual(p.lambda, p.phi, e.residual[i]);
        if (e.gram_norms && !e.residual.empty())
          gram_norm_difference = std::max(
            gram_norm_difference,
            std::abs(backward_error.from_norm(p.lambda, 1., e.norm_r[i]) - p.backward_error) /
              std::max(p.backward_error, floor / agreement));
        radius = std::max(radius, std::abs(p.lambda - sigma));
        pairs.push_back(std::move(p));
      }
    if (e.gram_norms && !estimates.gram().e_checked)
      estimates.check_residual_norms(gram_norm_difference);
    return radius;
  }

  void
  ReducedSolve::check_reach(const double omega, const double radius, std::ostringstream &reason) const
  {
    // a mode outside the basis (beyond the anchor's radius) moves at most
    // slope x |Omega - Omega_anchor| in the complex plane
    double reach = std::numeric_limits<double>::infinity(), anchor_rpm = 0, anchor_radius = 0;
    for (const auto &a : reduced.basis().anchors)
      {
        const double d = reduced.basis().slope_bound() *
                         std::abs(omega - SpeedSchedule::rpm_to_rad_per_s(a.rpm));
        if (radius + d - a.radius < reach)
          reach = radius + d - a.radius, anchor_rpm = a.rpm, anchor_radius = a.radius;
      }
    if (reason.str().empty() && !(reach < 0))
      reason << "the modes kept reach " << std::setprecision(4) << radius / (2 * M_PI)
             << " Hz from the shift; a mode outside the basis may have moved "
             << (reach - radius + anchor_radius) / (2 * M_PI) << " Hz since the anchor at "
             << anchor_rpm << " r/min, whose solve covered " << anchor_radius / (2 * M_PI)
             << " Hz";
  }

  double
  ReducedSolve::estimate_errors(const Dense         &d,
                                const Expansion     &e,
                                const BackwardError &backward_error,
                                const double         rpm,
                                EigenSolution       &solution)
  {
    const unsigned int                      n_wanted = classifier.n_wanted;
    std::vector<const EigenPair *>          wanted;
    std::vector<const ReducedBasis::Pair *> dense;
    std::vector<const ComplexVector *>      r;
    std::vector<double>                     scales;
    for (unsigned int i = 0; i < std::min<std::size_t>(n_wanted, solution.elastic.size()); ++i)
      {
        // its dense pair: the eigenvalue was copied from it unchanged
        wanted.push_back(&solution.elastic[i]);
        const auto j = std::find_if(d.picked.begin(), d.picked.end(), [&](std::size_t k) {
          return d.all[k].lambda == solution.elastic[i].lambda;
        }) - d.picked.begin();
        dense.push_back(&d.all[d.picked[j]]);
        r.push_back(e.residual.empty() ? nullptr : &e.residual[j]);
        scales.push_back(e.scale[j]);
      }
    const std::vector<double> estimate =
      estimates.estimates(backward_error, wanted, dense, scales, r, d.Cr, d.omega, d.w, rpm);
    double worst = 0;
    for (unsigned int i = 0; i < solution.elastic.size(); ++i)
      {
        // (beyond the wanted modes: no estimate, and they are dropped)
        solution.elastic[i].error_estimate = i < wanted.size() ? estimate[i] : 0.;
        if (i < wanted.size())
          worst = std::max(worst, estimate[i]);
      }
    return worst;
  }

  bool
  ReducedSolve::solve(const StaticState       &state,
                      const std::vector<bool> &loose_body,
                      const unsigned int       nev,
                      EigenSolution           &solution,
                      std::string             &why,
                      const bool               checked,
                      double                  &worst_backward_error)
  {
    if (reduced.basis().size() == 0)
      return false;
    const auto t0      = Clock::now();
    const auto elapsed = [&t0]() { return std::chrono::duration<double>(Clock::now() - t0).count(); };
    reduced.update_projections(state);
    if (checked)
      estimates.prepare_gram(false); // a lasting anchor's, before the modes are expanded
    const double t_projections = elapsed();
    Dense        d;
    if (!solve_dense(state, nev, d, why))
      return false;
    const BackwardError backward_error(operators.mass(), operators.damping(), operators.stiffness());
    Expansion           e;
    expand(d, backward_error, checked, e);
    std::ostringstream reason;
    bool               checked_now = false;
    const double       mismatch =
      check_products(d, e, backward_error, checked, state.rpm, checked_now, reason);
    std::vector<EigenPair> pairs;
    const double           radius = make_pairs(d, e, backward_error, checked, pairs);
    check_reach(d.omega, radius, reason);

    // the backward error as for a full solve, then the wanted modes'
    // eigenvalue error estimate against the tolerance
    std::sort(pairs.begin(), pairs.end(), [](const EigenPair &a, const EigenPair &b) {
      return std::abs(a.lambda) < std::abs(b.lambda);
    });
    unsigned int unconverged = 0;
    double       worst = 0, estimate = 0;
    const bool   sorted = classifier.sort_eigenpairs(pairs, loose_body, solution, unconverged, worst);
    if (!checked)
      return sorted; // a root-solve trial: its root gets the checked solve
    const double t_modes = elapsed();
    if (reason.str().empty() && sorted)
      estimate = estimate_errors(d, e, backward_error, state.rpm, solution);
    const double t_estimate = elapsed();
    if (reason.str().empty() && !sorted)
      reason << unconverged << " mode(s) above the Backward error limit (worst "
             << std::setprecision(3) << worst << "), " << solution.elastic.size() << " of "
             << classifier.n_wanted << " elastic modes";
    if (reason.str().empty() && !(estimate <= reduced.basis().tolerance()))
      reason << "estimated eigenvalue error " << std::setprecision(3) << estimate
             << " above the Reduced tolerance " << reduced.basis().tolerance();
    why = reason.str();
    if (!why.empty())
      return false;

    reduced.keep_speed(std::move(d.Cr), std::move(d.Kr));
    worst_estimate       = std::max(worst_estimate, estimate);
    worst_products       = std::max(worst_products, mismatch);
    worst_backward_error = std::max(worst_backward_error, worst);
    log_speed(solution, worst, estimate, mismatch, checked_now, t_projections, t_modes, t_estimate,
              t0);
    return true;
  }

  void
  ReducedSolve::log_speed(const EigenSolution    &solution,
                          const double            worst,
                          const double            estimate,
                          const double            mismatch,
                          const bool              checked_now,
                          const double            t_projections,
                          const double            t_modes,
                          const double            t_estimate,
                          const Clock::time_point t0) const
  {
    const std::size_t  shown = std::min<std::size_t>(classifier.n_wanted, solution.elastic.size());
    std::ostringstream line;
    line << "  eigen (reduced, basis " << reduced.basis().size() << " from anchors at";
    for (const auto &a : reduced.basis().anchors)
      line << ' ' << a.rpm;
    line << " r/min): " << shown << " whirl modes " << std::setprecision(5)
         << solution.elastic.front().lambda.imag() / (2 * M_PI) << " .. "
         << solution.elastic[shown - 1].lambda.imag() / (2 * M_PI) << " Hz, max backward error "
         << std::setprecision(2) << worst << ", max estimated error " << estimate
         << ", products checked to " << mismatch;
    if (!checked_now)
      line << " (at " << reduced.product_check()->rpm << " r/min)";
    line << "; " << std::setprecision(3)
         << std::chrono::duration<double>(Clock::now() - t0).count() << " s (" << t_projections
         << " s projections, " << t_modes - t_projections << " s dense solve + residuals, "
         << t_estimate - t_modes << " s estimates)\n";
    log << line.str();
  }
} // namespace rotorfit
