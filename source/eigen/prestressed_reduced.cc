#include <rotorfit/base/resources.h>
#include <rotorfit/eigen/prestressed_eigenproblem.h>
#include <rotorfit/linear_algebra/replicated_blocks.h>
#include <rotorfit/statics/speed_schedule.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iterator>
#include <limits>
#include <sstream>

// PrestressedEigenproblem, part 3: the reduced model (doc/theory.md 8.6).
// A basis per contact segment (tied set) from the full solves at anchor
// speeds; a speed is served by the projected problem when every mode it
// keeps meets the reduced tolerance on the full matrices and no mode
// outside the basis can have moved into the wanted range since the nearest
// anchor. Anything else is a full solve, which becomes a new anchor.

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

  PrestressedEigenproblem::SpeedOperators
  PrestressedEigenproblem::operators()
  {
    // the factorisation of the latest full solve serves the response's
    // basis (it checks its residual on this speed's matrices); a new one
    // only if there is none
    if (!eigensolver.linear_solver().factorized())
      {
        TimerOutput::Scope t(timer, "eigen: factorisation + ARPACK");
        eigensolver.factorize(matrices.mass, damping, tangent);
      }
    SpeedOperators op{matrices.mass, damping, tangent, eigensolver.linear_solver(), last_rpm};
    // as assemble_tangent() moves within a segment
    if (made_for.valid && !bearings.speed_dependent() &&
        (stiffening != StressStiffening::full || convective_folded || !convective_term))
      {
        op.segment     = segment_serial;
        op.speed_share = [this](const std::vector<const Vector<double> *> &x,
                                std::vector<Vector<double>>               &gx,
                                std::vector<Vector<double>>               &k2x) {
          replicated_mmult(matrices.gyroscopic, x, gx);
          if (stiffening == StressStiffening::full)
            replicated_mmult(k_sigma_C, x, k2x);
          else
            k2x.assign(x.size(), Vector<double>(matrices.mass.m()));
        };
      }
    // the reduced model of this speed, for the response: only with the
    // products its projections were made of (freed by a full solve)
    if (speed_reduced && !av_mass.empty())
      {
        op.basis = &reduced;
        op.Mr    = &p_mass;
        op.Cr    = &speed_Cr;
        op.Kr    = &speed_Kr;
        const double omega = SpeedSchedule::rpm_to_rad_per_s(last_rpm);
        op.products = [this, omega](const std::vector<std::complex<double>> &y,
                                    ComplexVector                           &Mu,
                                    ComplexVector                           &Cu,
                                    ComplexVector                           &Ku) {
          Expanded e = expanded({y}, omega, omega * omega, false);
          Mu         = std::move(e.m[0]);
          Cu         = std::move(e.c[0]);
          Ku         = std::move(e.k[0]);
        };
        op.w_tangent = w_tangent;
        op.row_parts = [this](const std::vector<const Vector<double> *> &x,
                              std::array<std::vector<double>, 5>        &parts) {
          const std::size_t   n = matrices.mass.m();
          std::vector<double> X(n * x.size());
          for (std::size_t j = 0; j < x.size(); ++j)
            std::copy(x[j]->begin(), x[j]->end(), X.begin() + j * n);
          const RowBlock *blocks[5] = {&av_mass, &av_bearing_c, &av_gyro, &av_tangent,
                                       &av_tangent2};
          for (unsigned int b = 0; b < 5; ++b)
            {
              parts[b].assign(reduced.size() * x.size(), 0.);
              if (!blocks[b]->empty())
                reduced.apply_transpose(*blocks[b], X, 1., parts[b]);
            }
        };
      }
    return op;
  }

  void
  PrestressedEigenproblem::add_anchor(const double                  rpm,
                                      const std::vector<EigenPair> &pairs,
                                      const bool                    lasting)
  {
    // the full solve found every eigenvalue within this distance of the
    // shift (ARPACK's nev nearest, all converged or the speed failed)
    const double       sigma  = eigensolver.shift();
    double             radius = 0;
    unsigned int       vectors = 0;
    for (const auto &p : pairs)
      if (p.backward_error <= eigensolver.backward_error_limit())
        {
          radius = std::max(radius, std::abs(p.lambda - sigma));
          vectors += p.lambda.imag() != 0 ? 2 : 1;
        }
    // where the basis is to serve other speeds (a lasting contact state):
    // each mode's first-order change with the speed, Q(sigma)^-1 G phi
    // (gyroscopic) and Q(sigma)^-1 dK_t/dw phi (stress stiffening, spin
    // softening), so that one anchor covers a wider range (doc/theory.md 8.6)
    const bool stiffening_moves = stiffening == StressStiffening::full;
    const unsigned int directions = lasting ? (stiffening_moves ? 3 : 2) : 1;
    if (reduced.size() + directions * vectors > reduced.capacity(directions * vectors))
      reduced.clear();
    std::vector<const Vector<double> *> parts;
    for (const auto &p : pairs)
      if (p.backward_error <= eigensolver.backward_error_limit())
        {
          parts.push_back(&p.phi.re);
          if (p.lambda.imag() != 0)
            parts.push_back(&p.phi.im);
        }
    reduced.add(parts, matrices.mass);
    if (directions > 1)
      add_directions(parts, false);
    reduced.anchors.push_back({rpm, radius});
    if (lasting)
      gram_eager_version = reduced.version();
  }

  void
  PrestressedEigenproblem::add_directions(const std::vector<const Vector<double> *> &all_parts,
                                          const bool bearing_damping,
                                          const bool gyroscopic)
  {
    const bool stiffening_moves = stiffening == StressStiffening::full;
    for (std::size_t first = 0; first < all_parts.size(); first += modes_per_block)
      {
        const std::vector<const Vector<double> *> parts(
          all_parts.begin() + first,
          all_parts.begin() + std::min(all_parts.size(), first + modes_per_block));
        std::vector<Vector<double>> g, k2, cb, theta;
        if (gyroscopic)
          replicated_mmult(matrices.gyroscopic, parts, g);
        if (stiffening_moves)
          {
            replicated_mmult(k_sigma_C, parts, k2);
            if (convective_term && !convective_folded) // (folded: in k_sigma_C)
              {
                replicated_mmult(matrices.convective, parts, theta);
                for (std::size_t i = 0; i < parts.size(); ++i)
                  k2[i] -= theta[i];
              }
          }
        if (bearing_damping)
          replicated_mmult(bearing_c, parts, cb);
        std::vector<Vector<double>> products;
        for (std::size_t i = 0; i < parts.size(); ++i)
          {
            if (gyroscopic)
              products.push_back(std::move(g[i]));
            if (stiffening_moves)
              products.push_back(std::move(k2[i]));
            if (bearing_damping && cb[i].l2_norm() > 0) // undamped bearings: nothing to add
              products.push_back(std::move(cb[i]));
          }
        std::vector<Vector<double>> found;
        replicated_solve(eigensolver.linear_solver(), matrices.mass, pointers(products), found);
        reduced.add(pointers(found), matrices.mass);
      }
  }

  void
  PrestressedEigenproblem::free_products()
  {
    for (auto *av : {&av_mass, &av_gyro, &av_tangent, &av_tangent2, &av_bearing_c})
      av->clear();
    key_basis = key_tangent = key_bearing = ProjectionKey{~0u, 0, -1};
    resources::give_back_free_memory();
  }

  bool
  PrestressedEigenproblem::anchor_undamped(const StaticState       &state,
                                           const std::vector<bool> &loose_body,
                                           const unsigned int       nev,
                                           const bool               lasting,
                                           EigenSolution           &solution,
                                           std::string             &why,
                                           const bool               on_update)
  {
    const auto t0 = std::chrono::steady_clock::now();
    free_products(); // stale for the new basis, and the factorisation is the peak
    // on the last LDL^T: the ties changed since as a low-rank update
    std::size_t springs = 0;
    double      update_seconds = 0;
    if (on_update)
      {
        TimerOutput::Scope                      t(timer, "eigen: undamped anchor");
        std::vector<DirectSolver::UpdateColumn> columns;
        if (!tie_update(state, solution.tied, columns) ||
            !eigensolver.update_factorization(columns))
          {
            why = "the low-rank update of the ties failed (its capacitance matrix is singular)";
            return false;
          }
        springs        = columns.size();
        update_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      }
    // as many modes as the damped anchor's whirl pairs (each undamped mode
    // is one line, FW or BW) and zero modes, with the margin
    const unsigned int zeros   = (nev - 1) / 2 - n_wanted;
    const unsigned int n_modes = n_wanted + zeros + reduced.margin();
    DampedEigensolver::Statistics                stats;
    std::vector<DampedEigensolver::UndampedMode> modes;
    std::size_t                                  found = 0;
    {
      TimerOutput::Scope t(timer, "eigen: undamped anchor");
      modes = eigensolver.solve_undamped(matrices.mass, tangent, n_modes, stats, !on_update);
      if (on_update)
        {
          // S of another tangent plus the ties: no Gram shortcut, and other
          // speeds' anchors update the same factorisation
          undamped_factor       = {~0u, ~0u};
          stats.factorization_seconds = update_seconds;
        }
      else
        {
          undamped_factor = {eigensolver.linear_solver().n_operators(), tangent_serial};
          const std::size_t n_pairs = model.pairs().pairs().size();
          factor_ties = {eigensolver.linear_solver().n_factorizations(), state.rpm,
                         std::vector<double>(n_pairs, 0.)};
          for (unsigned int i = 0; i < n_pairs; ++i)
            if (solution.tied[i])
              factor_ties.eps[i] = tie_spring(state, i);
        }
      // every mode below the first unconverged one was found
      while (found < modes.size() && modes[found].residual <= eigensolver.backward_error_limit())
        ++found;
      if (found < n_wanted + zeros)
        {
          std::ostringstream m;
          m << "Lanczos converged " << found << " of the " << n_wanted + zeros
            << " lowest undamped modes needed";
          why = m.str();
          return false;
        }
      const unsigned int per_mode =
        lasting ? 3 + (stiffening == StressStiffening::full ? 1 : 0) + (bearings.size() > 0 ? 1 : 0) :
                  3 + (on_update && stiffening == StressStiffening::full ? 1 : 0);
      if (reduced.size() + per_mode * found > reduced.capacity(per_mode * found))
        reduced.clear();
      std::vector<const Vector<double> *> parts;
      for (std::size_t i = 0; i < found; ++i)
        parts.push_back(&modes[i].phi);
      reduced.add(parts, matrices.mass);
      // the directions other speeds of the contact state need: G, K_t2, C_b
      // apart (a set that changes at the next speed needs only this
      // speed's C, below)
      if (lasting)
        add_directions(parts, true);
      else if (on_update && stiffening == StressStiffening::full)
        add_directions(parts, false, false); // (S is of another speed's stiffening)
      // S^-1 C phi, and S^-1 M S^-1 C phi with this speed's C = C_b + Omega G. S^-1 weighs
      // a mode j above the basis by 1 / (mu_j + sigma^2) where the change of
      // mode i needs 1 / (mu_j - mu_i) = sum_k (mu_i + sigma^2)^k /
      // (mu_j + sigma^2)^(k+1): this is the series' next term (the conical
      // impeller at 26,000 r/min: largest estimated error 4.5e-7 -> 8e-10;
      // 14 margin modes instead of 6 gave 1.2e-8 at a larger basis)
      std::vector<Vector<double>> second;
      for (std::size_t begin = 0; begin < parts.size(); begin += modes_per_block)
        {
          const std::vector<const Vector<double> *> block(
            parts.begin() + begin, parts.begin() + std::min(parts.size(), begin + modes_per_block));
          std::vector<Vector<double>> cx, first, next;
          replicated_mmult(damping, block, cx);
          replicated_solve(eigensolver.linear_solver(), matrices.mass, pointers(cx), first);
          if (!lasting)
            reduced.add(pointers(first), matrices.mass);
          replicated_mmult(matrices.mass, pointers(first), cx);
          replicated_solve(eigensolver.linear_solver(), matrices.mass, pointers(cx), next);
          std::move(next.begin(), next.end(), std::back_inserter(second));
        }
      reduced.add(pointers(second), matrices.mass);
    }
    // the vectors are in the basis now: not held through the reduced solve,
    // a run's memory peak on TS (the 23,000 r/min anchor: 20 .. 26 of them)
    const double top_mu   = std::max(0., modes[found - 1].mu);
    double       residual = 0;
    for (std::size_t i = 0; i < found; ++i)
      residual = std::max(residual, modes[i].residual);
    std::vector<DampedEigensolver::UndampedMode>().swap(modes);
    // the damped modes of this speed outside the basis come from undamped
    // ones above the top found, moved by the gyroscopic and damping terms:
    // at most the slope bound times the spin (damping assumed light)
    const double sigma  = eigensolver.shift();
    const double omega  = SpeedSchedule::rpm_to_rad_per_s(state.rpm);
    const double top    = std::sqrt(top_mu + sigma * sigma);
    // on an update the modes are those of the factorised speed's stiffening:
    // the lines may have moved by the slope bound since that speed as well
    const double since =
      on_update ? std::abs(omega - SpeedSchedule::rpm_to_rad_per_s(factor_ties.rpm)) : 0.;
    reduced.anchors.push_back({state.rpm, top - reduced.slope_bound() * (omega + since)});
    if (lasting)
      gram_eager_version = reduced.version();
    std::ostringstream line; // (its precision must not stick to the log)
    line << "  eigen: undamped anchor: " << found << " modes up to " << std::setprecision(5)
        << std::sqrt(top_mu) / (2 * M_PI) << " Hz, max residual "
        << std::setprecision(2) << residual << "; ";
    if (stats.block_size > 1)
      line << "block Lanczos " << stats.requested << " of " << stats.krylov_size << ", "
           << stats.iterations << " steps, " << stats.operator_applications << " solves in "
           << stats.block_solves << " blocks of " << stats.block_size;
    else
      line << "Lanczos " << stats.requested << " of " << stats.krylov_size << ", "
           << stats.iterations << " restarts, " << stats.operator_applications << " solves"
           << (stats.fallback.empty() ? "" : " (" + stats.fallback + ")");
    line << "; basis " << reduced.size() << "; ";
    if (on_update)
      line << springs << " tie springs updating the LDL^T of " << std::setprecision(6)
           << factor_ties.rpm << " r/min in " << std::setprecision(3)
           << stats.factorization_seconds << " s, ";
    else
      line << std::setprecision(3) << stats.factorization_seconds << " s LDL^T, ";
    line << stats.arnoldi_seconds << " s Lanczos ("
        << stats.solve_seconds << " s back-substitutions), "
        << std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()
        << " s in all\n";
    log << line.str();
    TimerOutput::Scope t(timer, "eigen: reduced model");
    return solve_reduced(state, loose_body, nev, solution, why);
  }

  void
  PrestressedEigenproblem::update_projections(const StaticState &state)
  {
    const unsigned int v = reduced.version();
    const unsigned int m = reduced.size();
    if (!(key_basis == ProjectionKey{v, 0, -1}))
      {
        p_mass    = reduced.project(matrices.mass, &av_mass);
        p_gyro    = reduced.project(matrices.gyroscopic, &av_gyro);
        key_basis = {v, 0, -1};
      }
    // K_t = K_t0 + w K_t2 on an active set's affine law (doc/theory.md B):
    // one projection per segment; otherwise (spin softening, bearing
    // coefficients that change with speed) one per speed
    const bool affine  = state.decomposition().affine || stiffening == StressStiffening::off;
    const bool per_rpm = !affine || bearings.speed_dependent();
    const ProjectionKey tangent_key{v, stiffening == StressStiffening::off ? 0 : k_sigma_serial,
                                    per_rpm ? state.rpm : -1};
    if (!(key_tangent == tangent_key))
      {
        p_tangent2.reinit(m, m);
        av_tangent2.clear();
        if (stiffening == StressStiffening::full && state.decomposition().affine)
          {
            p_tangent2 = reduced.project(k_sigma_C, &av_tangent2);
            if (convective_term && !convective_folded) // (folded: in k_sigma_C)
              {
                RowBlock convective;
                p_tangent2.add(-1., reduced.project(matrices.convective, &convective));
                av_tangent2.add(-1., convective);
              }
          }
        p_tangent0        = reduced.project(tangent, &av_tangent);
        av_tangent_serial = tangent_serial;
        p_tangent0.add(-state.w(), p_tangent2);
        w_tangent = state.w();
        key_tangent = tangent_key;
      }
    const ProjectionKey bearing_key{v, 0, bearings.speed_dependent() ? state.rpm : -1};
    if (!(key_bearing == bearing_key))
      {
        p_bearing_c = reduced.project(bearing_c, &av_bearing_c);
        key_bearing = bearing_key;
      }
  }

  bool
  PrestressedEigenproblem::product_check_due(const double rpm)
  {
    auto &c = product_check;
    if (c.basis != reduced.version() || !(c.tangent == key_tangent) ||
        !(c.bearing == key_bearing) || c.segment != segment_serial)
      {
        c       = ProductCheck{key_tangent, key_bearing, reduced.version(), segment_serial, 0, 0., rpm,
                         false, false, true};
        return true;
      }
    // also at the key's second speed: at its first the projections were
    // just made there (w = w_tangent), so the K_t2 share went unchecked
    ++c.speeds;
    c.due = c.speeds == 1 || c.speeds % product_check_interval == 0;
    return c.due;
  }

  bool
  PrestressedEigenproblem::solve_reduced(const StaticState       &state,
                                         const std::vector<bool> &loose_body,
                                         const unsigned int       nev,
                                         EigenSolution           &solution,
                                         std::string             &why,
                                         const bool               checked)
  {
    if (reduced.size() == 0)
      return false;
    const auto t0      = std::chrono::steady_clock::now();
    const auto elapsed = [&t0]() {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    };
    const double omega = SpeedSchedule::rpm_to_rad_per_s(state.rpm);
    const double sigma = eigensolver.shift();
    update_projections(state);
    if (checked)
      prepare_gram(false); // a lasting anchor's, before the modes are expanded
    const double t_projections = elapsed();
    FullMatrix<double> Kr(p_tangent0), Cr(p_bearing_c);
    Kr.add(state.w(), p_tangent2);
    Cr.add(omega, p_gyro);
    std::vector<ReducedBasis::Pair> all;
    const bool solved = reduced.solve(p_mass, Cr, Kr, all);
    if (Utilities::MPI::min(solved ? 1 : 0, comm) == 0)
      {
        why = "LAPACK dgeev failed on the projected problem";
        return false;
      }
    broadcast(all, reduced.size(), comm);
    std::sort(all.begin(), all.end(), [sigma](const auto &a, const auto &b) {
      return std::abs(a.lambda - sigma) < std::abs(b.lambda - sigma);
    });

    // the nev eigenvalues nearest the shift, conjugates counted twice, as
    // the full solve picks them
    std::vector<std::size_t>                       picked;
    std::vector<std::vector<std::complex<double>>> y;
    for (unsigned int count = 0, k = 0; count < nev && k < all.size(); ++k)
      {
        picked.push_back(k);
        y.push_back(all[k].y);
        count += all[k].lambda.imag() != 0 ? 2 : 1;
      }
    // phi = V y, M phi and the residual Q(lambda) phi from the kept products
    // A V: dense products for all modes at once instead of sparse ones per
    // mode (C phi and K_t phi are not kept: only the residual is needed)
    std::vector<ComplexVector>        v(y.size()), mv(y.size());
    std::vector<std::complex<double>> lambda;
    for (const auto k : picked)
      lambda.push_back(all[k].lambda);
    reduced.multiply(nullptr, y, 1., column_pointers(v));
    reduced.multiply(&av_mass, y, 1., column_pointers(mv));
    const BackwardError backward_error(matrices.mass, damping, tangent);
    // the right residuals' norms from the Euclidean Gram matrix of the
    // residual blocks where the basis has one and its estimates need no
    // back-substitution (no n-long residual vectors: a third of a reduced
    // speed on TS); checked once against the vectors, at its first speed
    const bool gram_norms = checked && !gram.e.empty() && !gram.e_refused && !gram.g.empty() &&
                            gram.checked; // (prepare_gram above: the speed's key)
    std::vector<double> norm_r(picked.size(), 0.);
    if (gram_norms)
      for (std::size_t i = 0; i < picked.size(); ++i)
        norm_r[i] = std::sqrt(inverse_norm_sqr(
          gram.e, residual_coefficients(y[i], lambda[i], omega, state.w(), false, gram.blocks)));
    std::vector<ComplexVector> residual;
    if (!gram_norms || !gram.e_checked)
      residual = residuals(y, lambda, omega, state.w(), false);
    std::vector<EigenPair>     pairs;
    std::vector<bool>          usable(picked.size());
    std::vector<double>        scale(picked.size());
    std::vector<std::complex<double>> sum(reduced.size());
    for (std::size_t i = 0; i < picked.size(); ++i)
      {
        scale[i]  = std::sqrt(v[i].re.norm_sqr() + v[i].im.norm_sqr());
        usable[i] = scale[i] > 0;
        if (usable[i])
          {
            for (ComplexVector *z : {&v[i], &mv[i]})
              z->re /= scale[i], z->im /= scale[i];
            if (!residual.empty())
              residual[i].re /= scale[i], residual[i].im /= scale[i];
            norm_r[i] /= scale[i];
            for (std::size_t j = 0; j < sum.size(); ++j)
              sum[j] += y[i][j] / scale[i];
          }
      }
    // a mode near the Backward error limit is judged on its vector (the
    // same decision on every rank)
    if (gram_norms && residual.empty())
      {
        bool near_limit = false;
        for (std::size_t i = 0; i < picked.size(); ++i)
          near_limit |= usable[i] && !(backward_error.from_norm(lambda[i], 1., norm_r[i]) <=
                                       1e-2 * eigensolver.backward_error_limit());
        if (Utilities::MPI::max(near_limit ? 1 : 0, comm) == 1)
          {
            residual = residuals(y, lambda, omega, state.w(), false);
            for (std::size_t j = 0; j < picked.size(); ++j)
              if (usable[j])
                residual[j].re /= scale[j], residual[j].im /= scale[j];
          }
        else
          ++gram_norm_speeds;
      }
    double gram_norm_difference = 0;
    // the products are checked against this speed's sparse matrices on one
    // combination of the modes: the checks on the full matrices rest on them
    std::ostringstream reason;
    product_check.due           = false;
    const bool   check_products = checked && product_check_due(state.rpm);
    const double mismatch =
      check_products ? expanded({sum}, omega, state.w(), false).mismatch(backward_error, false) :
                       product_check.mismatch;
    if (check_products)
      product_check.mismatch = mismatch, product_check.rpm = state.rpm;
    else if (checked)
      ++product_checks_skipped;
    if (!(mismatch <= product_tolerance))
      reason << "the reduced model's products differ from this speed's matrices by "
             << std::setprecision(3) << mismatch << " (relative)";
    double radius = 0;
    for (std::size_t i = 0; i < picked.size(); ++i)
      {
        if (!usable[i])
          continue;
        EigenPair p;
        p.lambda = all[picked[i]].lambda;
        p.phi    = std::move(v[i]);
        p.m_phi  = std::move(mv[i]);
        if (checked)
          p.backward_error = residual.empty() ?
                               backward_error.from_norm(p.lambda, 1., norm_r[i]) :
                               backward_error.from_residual(p.lambda, p.phi, residual[i]);
        if (gram_norms && !residual.empty())
          gram_norm_difference = std::max(
            gram_norm_difference,
            std::abs(backward_error.from_norm(p.lambda, 1., norm_r[i]) - p.backward_error) /
              std::max(p.backward_error, gram_floor / gram_agreement));
        radius = std::max(radius, std::abs(p.lambda - sigma));
        pairs.push_back(std::move(p));
      }

    if (gram_norms && !gram.e_checked)
      {
        gram.e_checked = true;
        gram.e_refused =
          Utilities::MPI::max(gram_norm_difference <= gram_agreement ? 0 : 1, comm) == 1;
        gram_norms_worst_difference = std::max(gram_norms_worst_difference, gram_norm_difference);
        std::ostringstream line;
        line << "  eigen: residual norms from the Gram matrix of the blocks differ from the "
                "vectors' by "
             << std::setprecision(2) << gram_norm_difference
             << (gram.e_refused ? ": not used (the residual vectors stay on this basis)" : "")
             << '\n';
        log << line.str();
      }

    // a mode outside the basis (beyond the anchor's radius) moves at most
    // slope x |Omega - Omega_anchor| in the complex plane
    double reach = std::numeric_limits<double>::infinity(), anchor_rpm = 0, anchor_radius = 0;
    for (const auto &a : reduced.anchors)
      {
        const double d = reduced.slope_bound() *
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

    // the backward error as for a full solve, then the wanted modes'
    // eigenvalue error estimate against the tolerance
    std::sort(pairs.begin(), pairs.end(), [](const EigenPair &a, const EigenPair &b) {
      return std::abs(a.lambda) < std::abs(b.lambda);
    });
    unsigned int unconverged = 0;
    double       worst       = 0, worst_estimate = 0;
    const bool   sorted = sort_eigenpairs(pairs, loose_body, solution, unconverged, worst);
    if (!checked)
      return sorted; // a root-solve trial: its root gets the checked solve
    const double t_modes = elapsed();
    if (reason.str().empty() && sorted)
      {
        std::vector<const EigenPair *>          wanted;
        std::vector<const ReducedBasis::Pair *> dense;
        std::vector<const ComplexVector *>      r;
        std::vector<double>                     scales;
        for (unsigned int i = 0; i < std::min<std::size_t>(n_wanted, solution.elastic.size()); ++i)
          {
            // its dense pair: the eigenvalue was copied from it unchanged
            wanted.push_back(&solution.elastic[i]);
            const auto j = std::find_if(picked.begin(), picked.end(), [&](std::size_t k) {
              return all[k].lambda == solution.elastic[i].lambda;
            }) - picked.begin();
            dense.push_back(&all[picked[j]]);
            r.push_back(residual.empty() ? nullptr : &residual[j]);
            scales.push_back(scale[j]);
          }
        const std::vector<double> estimate =
          error_estimates(backward_error, wanted, dense, scales, r, Cr, omega, state.w());
        for (unsigned int i = 0; i < solution.elastic.size(); ++i)
          {
            // (beyond the wanted modes: no estimate, and they are dropped)
            solution.elastic[i].error_estimate = i < wanted.size() ? estimate[i] : 0.;
            if (i < wanted.size())
              worst_estimate = std::max(worst_estimate, estimate[i]);
          }
      }
    const double t_estimate = elapsed();
    if (reason.str().empty() && !sorted)
      reason << unconverged << " mode(s) above the Backward error limit (worst "
             << std::setprecision(3) << worst << "), " << solution.elastic.size() << " of "
             << n_wanted << " elastic modes";
    if (reason.str().empty() && !(worst_estimate <= reduced.tolerance()))
      reason << "estimated eigenvalue error " << std::setprecision(3) << worst_estimate
             << " above the Reduced tolerance " << reduced.tolerance();
    why = reason.str();
    if (!why.empty())
      return false;

    speed_Cr             = std::move(Cr);
    speed_Kr             = std::move(Kr);
    reduced_worst        = std::max(reduced_worst, worst_estimate);
    reduced_worst_products = std::max(reduced_worst_products, mismatch);
    worst_backward_error = std::max(worst_backward_error, worst);
    std::ostringstream line;
    line << "  eigen (reduced, basis " << reduced.size() << " from anchors at";
    for (const auto &a : reduced.anchors)
      line << ' ' << a.rpm;
    line << " r/min): " << std::min<std::size_t>(n_wanted, solution.elastic.size())
         << " whirl modes " << std::setprecision(5)
         << solution.elastic.front().lambda.imag() / (2 * M_PI) << " .. "
         << solution.elastic[std::min<std::size_t>(n_wanted, solution.elastic.size()) - 1]
                .lambda.imag() /
              (2 * M_PI)
         << " Hz, max backward error " << std::setprecision(2) << worst
         << ", max estimated error " << worst_estimate << ", products checked to " << mismatch;
    if (!check_products)
      line << " (at " << product_check.rpm << " r/min)";
    line
         << "; " << std::setprecision(3)
         << elapsed() << " s (" << t_projections << " s projections, " << t_modes - t_projections
         << " s dense solve + residuals, " << t_estimate - t_modes << " s estimates)\n";
    log << line.str();
    return true;
  }
} // namespace rotorfit
