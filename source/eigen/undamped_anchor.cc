#include <rotorfit/eigen/undamped_anchor.h>
#include <rotorfit/linear_algebra/replicated_blocks.h>
#include <rotorfit/statics/speed_schedule.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iterator>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

  UndampedAnchor::UndampedAnchor(const Discretization &model,
                                 ReducedModel         &reduced,
                                 ReducedEstimates     &estimates,
                                 TieUpdate            &ties,
                                 SpeedTangent         &operators,
                                 DampedEigensolver    &eigensolver,
                                 const Bearings       &bearings,
                                 Log                  &log,
                                 TimerOutput          &timer)
    : model(model)
    , reduced(reduced)
    , estimates(estimates)
    , ties(ties)
    , operators(operators)
    , eigensolver(eigensolver)
    , bearings(bearings)
    , log(log)
    , timer(timer)
  {}

  void
  UndampedAnchor::add_damped(const double                  rpm,
                             const std::vector<EigenPair> &pairs,
                             const bool                    lasting)
  {
    // the full solve found every eigenvalue within this distance of the
    // shift (ARPACK's nev nearest, all converged or the speed failed)
    const double       sigma   = eigensolver.shift();
    double             radius  = 0;
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
    const unsigned int directions = lasting ? (operators.stiffening_moves() ? 3 : 2) : 1;
    if (reduced.basis().size() + directions * vectors >
        reduced.basis().capacity(directions * vectors))
      reduced.clear();
    std::vector<const Vector<double> *> parts;
    for (const auto &p : pairs)
      if (p.backward_error <= eigensolver.backward_error_limit())
        {
          parts.push_back(&p.phi.re);
          if (p.lambda.imag() != 0)
            parts.push_back(&p.phi.im);
        }
    reduced.add(parts, operators.mass());
    if (directions > 1)
      add_directions(parts, false);
    reduced.add_anchor({rpm, radius});
    if (lasting)
      reduced.mark_lasting();
  }

  void
  UndampedAnchor::add_directions(const std::vector<const Vector<double> *> &all_parts,
                                 const bool                                 bearing_damping,
                                 const bool                                 gyroscopic)
  {
    const bool stiffening_moves = operators.stiffening_moves();
    for (std::size_t first = 0; first < all_parts.size(); first += modes_per_block)
      {
        const std::vector<const Vector<double> *> parts(
          all_parts.begin() + first,
          all_parts.begin() + std::min(all_parts.size(), first + modes_per_block));
        std::vector<Vector<double>> g, k2, cb;
        if (gyroscopic)
          replicated_mmult(operators.speed_independent().gyroscopic, parts, g);
        operators.stiffening_share(parts, k2);
        if (bearing_damping)
          replicated_mmult(operators.bearing_damping(), parts, cb);
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
        replicated_solve(eigensolver.linear_solver(), operators.mass(), pointers(products), found);
        reduced.add(pointers(found), operators.mass());
      }
  }

  bool
  UndampedAnchor::update_ties(const StaticState       &state,
                              const std::vector<bool> &tied,
                              const Clock::time_point  t0,
                              std::size_t             &springs,
                              double                  &seconds,
                              std::string             &why)
  {
    TimerOutput::Scope                      t(timer, "eigen: undamped anchor");
    std::vector<DirectSolver::UpdateColumn> columns;
    if (!ties.columns(eigensolver.linear_solver(), state, tied, reduced.basis().tie_update_limit(),
                      columns) ||
        !eigensolver.update_factorization(columns))
      {
        why = "the low-rank update of the ties failed (its capacitance matrix is singular)";
        return false;
      }
    springs = columns.size();
    seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return true;
  }

  std::vector<DampedEigensolver::UndampedMode>
  UndampedAnchor::solve_modes(const StaticState             &state,
                              const std::vector<bool>       &tied,
                              const unsigned int             n_modes,
                              const bool                     on_update,
                              const double                   update_seconds,
                              DampedEigensolver::Statistics &stats)
  {
    auto modes = eigensolver.solve_undamped(operators.mass(), operators.stiffness(), n_modes, stats,
                                            !on_update);
    if (on_update)
      {
        // S of another tangent plus the ties: no Gram shortcut, and other
        // speeds' anchors update the same factorisation
        estimates.set_undamped_factor(std::nullopt);
        stats.factorization_seconds = update_seconds;
      }
    else
      {
        estimates.set_undamped_factor(
          std::make_pair(eigensolver.linear_solver().n_operators(), operators.serial()));
        ties.record(eigensolver.linear_solver(), state, tied);
      }
    return modes;
  }

  void
  UndampedAnchor::add_modes(const std::vector<DampedEigensolver::UndampedMode> &modes,
                            const std::size_t                                   found,
                            const bool                                          lasting,
                            const bool                                          on_update)
  {
    const bool         stiffening_moves = operators.stiffening_moves();
    const unsigned int per_mode =
      lasting ? 3 + (stiffening_moves ? 1 : 0) + (bearings.size() > 0 ? 1 : 0) :
                3 + (on_update && stiffening_moves ? 1 : 0);
    if (reduced.basis().size() + per_mode * found > reduced.basis().capacity(per_mode * found))
      reduced.clear();
    std::vector<const Vector<double> *> parts;
    for (std::size_t i = 0; i < found; ++i)
      parts.push_back(&modes[i].phi);
    reduced.add(parts, operators.mass());
    // the directions other speeds of the contact state need: G, K_t2, C_b
    // apart (a set that changes at the next speed needs only this
    // speed's C, below)
    if (lasting)
      add_directions(parts, true);
    else if (on_update && stiffening_moves)
      add_directions(parts, false, false); // (S is of another speed's stiffening)
    add_damping_terms(parts, lasting);
  }

  void
  UndampedAnchor::add_damping_terms(const std::vector<const Vector<double> *> &parts,
                                    const bool                                 lasting)
  {
    // S^-1 C phi, and S^-1 M S^-1 C phi with this speed's C = C_b + Omega G. S^-1 weighs
    // a mode j above the basis by 1 / (mu_j + sigma^2) where the change of
    // mode i needs 1 / (mu_j - mu_i) = sum_k (mu_i + sigma^2)^k /
    // (mu_j + sigma^2)^(k+1): this is the series' next term (the conical
    // impeller at 26,000 r/min: largest estimated error 4.5e-7 -> 8e-10;
    // 14 margin modes instead of 6 gave 1.2e-8 at a larger basis)
    const auto                 &M = operators.mass();
    std::vector<Vector<double>> second;
    for (std::size_t begin = 0; begin < parts.size(); begin += modes_per_block)
      {
        const std::vector<const Vector<double> *> block(
          parts.begin() + begin, parts.begin() + std::min(parts.size(), begin + modes_per_block));
        std::vector<Vector<double>> cx, first, next;
        replicated_mmult(operators.damping(), block, cx);
        replicated_solve(eigensolver.linear_solver(), M, pointers(cx), first);
        if (!lasting)
          reduced.add(pointers(first), M);
        replicated_mmult(M, pointers(first), cx);
        replicated_solve(eigensolver.linear_solver(), M, pointers(cx), next);
        std::move(next.begin(), next.end(), std::back_inserter(second));
      }
    reduced.add(pointers(second), M);
  }

  bool
  UndampedAnchor::make(const StaticState       &state,
                       const std::vector<bool> &tied,
                       const unsigned int       nev,
                       const unsigned int       n_wanted,
                       const bool               lasting,
                       std::string             &why,
                       const bool               on_update)
  {
    const auto t0 = Clock::now();
    reduced.free_products(); // stale for the new basis, and the factorisation is the peak
    // on the last LDL^T: the ties changed since as a low-rank update
    std::size_t springs        = 0;
    double      update_seconds = 0;
    if (on_update && !update_ties(state, tied, t0, springs, update_seconds, why))
      return false;
    // as many modes as the damped anchor's whirl pairs (each undamped mode
    // is one line, FW or BW) and zero modes, with the margin
    const unsigned int zeros   = (nev - 1) / 2 - n_wanted;
    const unsigned int n_modes = n_wanted + zeros + reduced.basis().margin();
    DampedEigensolver::Statistics                stats;
    std::vector<DampedEigensolver::UndampedMode> modes;
    std::size_t                                  found = 0;
    {
      TimerOutput::Scope t(timer, "eigen: undamped anchor");
      modes = solve_modes(state, tied, n_modes, on_update, update_seconds, stats);
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
      add_modes(modes, found, lasting, on_update);
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
    const double sigma = eigensolver.shift();
    const double omega = SpeedSchedule::rpm_to_rad_per_s(state.rpm);
    const double top   = std::sqrt(top_mu + sigma * sigma);
    // on an update the modes are those of the factorised speed's stiffening:
    // the lines may have moved by the slope bound since that speed as well
    const double since =
      on_update ? std::abs(omega - SpeedSchedule::rpm_to_rad_per_s(ties.factorized_rpm())) : 0.;
    reduced.add_anchor({state.rpm, top - reduced.basis().slope_bound() * (omega + since)});
    if (lasting)
      reduced.mark_lasting();
    log_anchor(stats, found, top_mu, residual, on_update, springs, t0);
    return true;
  }

  void
  UndampedAnchor::log_anchor(const DampedEigensolver::Statistics &stats,
                             const std::size_t                    found,
                             const double                         top_mu,
                             const double                         residual,
                             const bool                           on_update,
                             const std::size_t                    springs,
                             const Clock::time_point              t0) const
  {
    std::ostringstream line; // (its precision must not stick to the log)
    line << "  eigen: undamped anchor: " << found << " modes up to " << std::setprecision(5)
         << std::sqrt(top_mu) / (2 * M_PI) << " Hz, max residual " << std::setprecision(2)
         << residual << "; ";
    if (stats.block_size > 1)
      line << "block Lanczos " << stats.requested << " of " << stats.krylov_size << ", "
           << stats.iterations << " steps, " << stats.operator_applications << " solves in "
           << stats.block_solves << " blocks of " << stats.block_size;
    else
      line << "Lanczos " << stats.requested << " of " << stats.krylov_size << ", "
           << stats.iterations << " restarts, " << stats.operator_applications << " solves"
           << (stats.fallback.empty() ? "" : " (" + stats.fallback + ")");
    line << "; basis " << reduced.basis().size() << "; ";
    if (on_update)
      line << springs << " tie springs updating the LDL^T of " << std::setprecision(6)
           << ties.factorized_rpm() << " r/min in " << std::setprecision(3)
           << stats.factorization_seconds << " s, ";
    else
      line << std::setprecision(3) << stats.factorization_seconds << " s LDL^T, ";
    line << stats.arnoldi_seconds << " s Lanczos (" << stats.solve_seconds
         << " s back-substitutions), "
         << std::chrono::duration<double>(Clock::now() - t0).count() << " s in all\n";
    log << line.str();
  }
} // namespace rotorfit
