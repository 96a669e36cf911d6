#include <rotorfit/base/input_error.h>
#include <rotorfit/eigen/prestressed_eigenproblem.h>
#include <rotorfit/linear_algebra/replicated_blocks.h>
#include <rotorfit/statics/speed_schedule.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <numeric>
#include <sstream>

// PrestressedEigenproblem, part 2: the solve of a speed, what is set apart
// from the elastic modes, the self-checks and the totals. Part 1
// (parameters, set-up, matrices): prestressed_eigenproblem.cc.

namespace rotorfit
{
  using namespace dealii;

  std::vector<bool>
  PrestressedEigenproblem::tied_pairs(const StaticState &state)
  {
    switch (contact_model)
      {
        case ContactModel::bonded:
        case ContactModel::frictionless:
          return state.contact.active;
        case ContactModel::fixed:
          return std::vector<bool>(model.pairs().pairs().size(), true);
        case ContactModel::frozen:
          if (frozen_active.empty())
            frozen_active = state.contact.active;
          return frozen_active;
      }
    return {};
  }

  unsigned int
  PrestressedEigenproblem::begin_speed(const StaticState &state,
                                       EigenSolution     &solution,
                                       std::vector<bool> &loose_body)
  {
    solution.rpm   = state.rpm;
    solution.index = state.index;
    solution.tied  = tied_pairs(state);
    // isotropic supports keep the rotor axisymmetric: [[k, q], [-q, k]]
    for (unsigned int n = 0; n < bearings.size(); ++n)
      {
        Bearings::Coefficients k, c;
        bearings.coefficients(n, state.rpm, k, c);
        for (const auto &a : {k, c})
          if (a[0] != a[1] || a[2] != -a[3])
            solution.isotropic_supports = false;
      }
    assemble_tangent(state, solution.tied);
    last_rpm      = state.rpm;
    speed_reduced = false;
    if (self_check && checks.empty() && state.rpm > 0)
      matrix_checks(state);
    const unsigned int zeros = expected_zero_modes(solution.tied, loose_body);
    return 2 * n_wanted + 2 * zeros + 1;
  }

  bool
  PrestressedEigenproblem::solve_trial(const StaticState &state, EigenSolution &solution)
  {
    // only where the speed's own solve left a basis of this tied set
    if (!reduced.enabled() || reduced.size() == 0 || tied_pairs(state) != basis_tied)
      return false;
    solution = EigenSolution();
    std::vector<bool>  loose_body;
    const unsigned int nev = begin_speed(state, solution, loose_body);
    std::string        unused;
    TimerOutput::Scope t(timer, "eigen: reduced model");
    if (!solve_reduced(state, loose_body, nev, solution, unused, false))
      return false;
    ++reduced_trials;
    if (solution.elastic.size() > n_wanted)
      solution.elastic.resize(n_wanted);
    return true;
  }

  EigenSolution
  PrestressedEigenproblem::solve(const StaticState &state)
  {
    EigenSolution     solution;
    std::vector<bool> loose_body;
    unsigned int      nev = begin_speed(state, solution, loose_body);

    bool margin_pays = false;
    if (reduced.enabled())
      {
        // a contact segment (tied set) of its own starts a new basis. A set
        // that just changed with every fit part open, part closed is likely
        // to change again at the next speed (a fit opening gradually): its
        // anchor skips the margin. Fits wholly closed or wholly open last.
        const auto &pair_list = model.pairs();
        bool        settled   = true;
        for (unsigned int i = 0; i < pair_list.n_interfaces(); ++i)
          {
            const auto &ids = pair_list.pairs_of(i);
            const auto  n_tied =
              std::count_if(ids.begin(), ids.end(), [&](unsigned int p) { return solution.tied[p]; });
            settled &= n_tied == 0 || n_tied == static_cast<long>(ids.size());
          }
        margin_pays = solution.tied == basis_tied || basis_tied.empty() || settled;
        if (solution.tied != basis_tied)
          {
            reduced.clear();
            basis_tied = solution.tied;
          }
        std::string why;
        bool        done = false;
        {
          TimerOutput::Scope t(timer, "eigen: reduced model");
          done = solve_reduced(state, loose_body, nev, solution, why);
        }
        // a speed served by the reduced model (of the basis so far, or of
        // an undamped anchor made for it)
        const auto served = [&](unsigned int &counter) {
          speed_reduced = true;
          ++counter;
          if (solution.elastic.size() > n_wanted)
            solution.elastic.resize(n_wanted);
          warn_far_shift(solution, state.rpm);
          announce_loose_bodies(state, loose_body);
          ++speeds_done;
        };
        if (done)
          {
            served(reduced_solves);
            return solution;
          }
        if (reduced.size() > 0)
          {
            ++reduced_refusals;
            log << "  eigen: reduced model refused at " << state.rpm << " r/min (" << why
                << "): full solve, a new anchor\n";
          }
        // an undamped anchor where K_t is symmetric (LDL^T instead of LU)
        if (reduced.undamped_anchors() && bearings.symmetric(state.rpm, false))
          {
            // on the last LDL^T where few ties changed since (a fit opening
            // pair by pair), else on a new one
            std::vector<DirectSolver::UpdateColumn> columns;
            if (reduced.tie_update_limit() > 0 && tie_update(state, solution.tied, columns))
              {
                const std::size_t anchors_before = reduced.anchors.size();
                if (anchor_undamped(state, loose_body, nev, margin_pays, solution, why, true))
                  {
                    ++updated_anchors;
                    served(undamped_served);
                    return solution;
                  }
                ++updated_anchors_refused;
                log << "  eigen: undamped anchor on the tie update refused at " << state.rpm
                    << " r/min (" << why << "): a new LDL^T\n";
                // its vectors stay in the basis, the new anchor's join them
                // (TS at 23,900 r/min: the two together serve the speed,
                // the new anchor's alone do not, and the speed would need
                // the damped full solve, its LU the 301-speed run's peak);
                // its coverage claim goes (the checks refused it)
                if (reduced.anchors.size() > anchors_before)
                  reduced.anchors.resize(anchors_before);
              }
            if (anchor_undamped(state, loose_body, nev, margin_pays, solution, why))
              {
                served(undamped_served);
                return solution;
              }
            ++undamped_refused;
            log << "  eigen: undamped anchor at " << state.rpm << " r/min refused (" << why
                << "): the damped full solve\n";
          }
        // the anchor's margin: modes that may move into the wanted range
        if (margin_pays)
          nev = std::min<unsigned int>(nev + 2 * reduced.margin(), 2 * model.dofs().n_dofs() - 3);
      }

    // the reduced products serve no full solve and its anchor makes them
    // stale: free them before the factorisation, the memory peak
    free_products();

    unsigned int                  unconverged = 0;
    double                        worst       = 0;
    DampedEigensolver::Statistics stats;
    // a second attempt on the same factorisation with twice the Krylov
    // space and restarts (and room for the modes that were missing); then
    // the run stops: a Campbell diagram with a missing line is wrong
    for (unsigned int attempt = 0;; ++attempt)
      {
        std::vector<EigenPair> pairs;
        {
          TimerOutput::Scope t(timer, "eigen: factorisation + ARPACK");
          pairs = eigensolver.solve(matrices.mass, damping, tangent, nev, stats, attempt);
        }
        TimerOutput::Scope t(timer, "eigen: post-processing + output");
        unconverged = stats.unconverged_slots;
        std::vector<EigenPair> anchor;
        if (reduced.enabled())
          anchor = pairs; // sort_eigenpairs moves the vectors away
        if (sort_eigenpairs(pairs, loose_body, solution, unconverged, worst))
          {
            if (reduced.enabled())
              add_anchor(state.rpm, anchor, margin_pays);
            break;
          }
        unsigned int n_rigid = 0, n_loose = 0, n_overdamped = 0;
        for (const auto &r : solution.rigid)
          (r.kind == "loose" ? n_loose : r.kind == "rigid" ? n_rigid : n_overdamped) +=
            (r.lambda.imag() != 0 ? 2 : 1);
        std::ostringstream m;
        m << "at " << state.rpm << " r/min: " << solution.elastic.size()
          << " elastic modes converged (" << n_wanted << " wanted; " << stats.unconverged_slots
          << " ARPACK slots unconverged, " << unconverged - stats.unconverged_slots
          << " eigenpairs with a backward error above Eigenproblem/Backward error limit = "
          << eigensolver.backward_error_limit() << ", worst " << std::setprecision(3) << worst
          << "; " << n_rigid << " rigid, " << n_loose << " loose-body, " << n_overdamped
          << " overdamped) with " << stats.requested << " eigenvalues, Krylov size "
          << stats.krylov_size << ", at most " << stats.max_restarts << " restarts";
        const unsigned int more =
          2 * (n_wanted - std::min<unsigned int>(n_wanted, solution.elastic.size()));
        if (attempt == 0 && nev + more + 3 <= 2 * model.dofs().n_dofs())
          {
            nev += more;
            ++retried_speeds;
            log << "  eigen: retry " << m.str() << "; again with twice the Krylov space\n";
            continue;
          }
        throw SolverFailure(state.rpm,
                            "the eigensolver did not converge " + m.str() +
                              (attempt > 0 ? " (after one retry with twice the Krylov space)" :
                                             " (no retry: the model has too few DOFs for more "
                                             "eigenvalues)") +
                              "; raise Eigenproblem/Maximum restarts or Krylov size factor, or "
                              "move the Shift");
      }
    ++full_solves;
    log_speed(solution, stats, worst);
    if (solution.elastic.size() > n_wanted)
      solution.elastic.resize(n_wanted);
    warn_far_shift(solution, state.rpm);
    announce_loose_bodies(state, loose_body);
    worst_backward_error = std::max(worst_backward_error, worst);
    ++speeds_done;
    return solution;
  }

  bool
  PrestressedEigenproblem::sort_eigenpairs(std::vector<EigenPair>  &pairs,
                                           const std::vector<bool> &loose_body,
                                           EigenSolution           &solution,
                                           unsigned int            &unconverged,
                                           double                  &worst) const
  {
    const auto &bodies = model.bodies();
    solution.elastic.clear();
    solution.rigid.clear();
    worst = 0;
    for (auto &p : pairs)
      {
        if (std::isnan(p.backward_error) ||
            (!std::isnan(worst) && p.backward_error > worst)) // NaN sticks
          worst = p.backward_error;
        if (!(p.backward_error <= eigensolver.backward_error_limit()))
          {
            ++unconverged;
            continue;
          }
        // kinetic energy share per body: M is block diagonal by body
        std::vector<double> energy(bodies.size(), 0.);
        for (std::size_t i = 0; i < p.phi.re.size(); ++i)
          energy[body_of_dof[i]] += p.phi.re[i] * p.m_phi.re[i] + p.phi.im[i] * p.m_phi.im[i];
        const double       total = std::accumulate(energy.begin(), energy.end(), 0.);
        const unsigned int dominant =
          std::max_element(energy.begin(), energy.end()) - energy.begin();
        const bool in_loose_body = loose_body[dominant] && energy[dominant] > 0.9 * total;
        const bool rigid_mode    = std::abs(p.lambda) < 2 * M_PI * rigid_threshold_hz;
        const bool real_mode     = p.lambda.imag() == 0;
        if (rigid_mode || real_mode || in_loose_body)
          solution.rigid.push_back({in_loose_body ? "loose" :
                                    rigid_mode    ? "rigid" :
                                                    "overdamped",
                                    in_loose_body ? bodies[dominant].name : "assembly",
                                    p.lambda,
                                    p.backward_error});
        else
          solution.elastic.push_back(std::move(p));
      }
    return unconverged == 0 && solution.elastic.size() >= n_wanted;
  }

  void
  PrestressedEigenproblem::log_speed(const EigenSolution                 &solution,
                                     const DampedEigensolver::Statistics &stats,
                                     const double                         worst) const
  {
    // counted as state-space eigenvalues: a rigid motion is a double zero
    // that round-off splits into a tiny conjugate pair (one row) or two
    // tiny real values (two rows)
    unsigned int n_rigid = 0, n_loose = 0, n_overdamped = 0;
    for (const auto &r : solution.rigid)
      (r.kind == "loose" ? n_loose : r.kind == "rigid" ? n_rigid : n_overdamped) +=
        (r.lambda.imag() != 0 ? 2 : 1);
    const auto        &elastic = solution.elastic;
    const std::size_t  shown   = std::min<std::size_t>(n_wanted, elastic.size());
    std::ostringstream line;
    line << "  eigen: " << shown << " whirl modes";
    if (shown > 0)
      line << " " << std::setprecision(5) << elastic.front().lambda.imag() / (2 * M_PI)
           << " .. " << elastic[shown - 1].lambda.imag() / (2 * M_PI) << " Hz";
    if (elastic.size() > shown)
      line << " (+ " << elastic.size() - shown << " up to " << std::setprecision(5)
           << elastic.back().lambda.imag() / (2 * M_PI) << " Hz for the reduced basis)";
    line << ", " << n_rigid << " rigid, " << n_loose << " loose-body, " << n_overdamped
         << " overdamped (state-space eigenvalues); nev " << stats.requested << ", Krylov "
         << stats.krylov_size << ", " << stats.iterations << " restarts, "
         << stats.operator_applications << " solves, max backward error "
         << std::setprecision(2) << worst << "; " << std::setprecision(3)
         << stats.factorization_seconds << " s LU, " << stats.arnoldi_seconds
         << " s Arnoldi (" << stats.solve_seconds << " s back-substitutions), "
         << stats.check_seconds << " s checks\n";
    log << line.str();
  }

  void
  PrestressedEigenproblem::announce_loose_bodies(const StaticState       &state,
                                                 const std::vector<bool> &loose_body)
  {
    if (state.fit_state != "open" || contact_model == ContactModel::fixed ||
        contact_model == ContactModel::frozen || announced_loose)
      return;
    announced_loose = true;
    std::string names;
    for (unsigned int b = 0; b < model.bodies().size(); ++b)
      if (loose_body[b])
        names += (names.empty() ? "" : ", ") + model.bodies()[b].name;
    log << "  note: a fit is fully open at " << state.rpm << " r/min: "
        << (names.empty() ? "the assembly falls apart" : "body " + names + " is loose")
        << "; from here on the whirl lines are not assembly modes (fit_state = "
           "open in campbell.csv), loose-body modes go to rigid_modes.csv\n";
  }

  std::vector<Vector<double>>
  PrestressedEigenproblem::check_fields() const
  {
    const auto &points = model.support_points();
    const auto &fe     = model.dofs().get_fe();
    std::vector<unsigned int> component(points.size());
    {
      std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
      for (const auto &cell : model.dofs().active_cell_iterators())
        {
          cell->get_dof_indices(dofs);
          for (unsigned int i = 0; i < dofs.size(); ++i)
            component[dofs[i]] = fe.system_to_component_index(i).first;
        }
    }
    const auto field = [&](const std::function<Tensor<1, 3>(const Point<3> &)> &f) {
      Vector<double> v(points.size());
      for (std::size_t i = 0; i < points.size(); ++i)
        v[i] = f(points[i])[component[i]];
      return v;
    };
    const Vector<double> tilt  = field([](const Point<3> &x) { return Tensor<1, 3>({0., -x[2], x[1]}); });
    const Vector<double> twist = field([](const Point<3> &x) { return Tensor<1, 3>({-x[1], x[0], 0.}); });
    const Vector<double> y_in_x = field([](const Point<3> &x) { return Tensor<1, 3>({x[1], 0., 0.}); });
    return {tilt, twist, y_in_x};
  }

  void
  PrestressedEigenproblem::matrix_checks(const StaticState &state)
  {
    // On linear fields (exact in the FE space) the virial identity
    // int sigma dV = Omega^2 int rho P x (x) x dV makes w^T K_sigma w equal
    // Omega^2 int rho y^2 for the tilt w = e_x (x) x and Omega^2 w^T K_theta w
    // for the twist w = e_z x x, to round-off with reaction-free supports;
    // the tilt cancellation against Omega^2 K_theta is exact only on
    // rotationally symmetric meshes (doc/theory.md 10e-3/4).
    const double w             = state.w();
    const auto  &decomposition = state.decomposition();
    if (!decomposition.affine || stiffening != StressStiffening::full)
      return;
    // K_sigma(u_I + w u_C) of its own (matrices.stiffness holds it summed
    // with K)
    PETScWrappers::MPI::SparseMatrix k_sigma;
    {
      const auto                &owned = model.locally_owned_dofs();
      PETScWrappers::MPI::Vector u(owned, comm);
      u = decomposition.u_I;
      u.add(w, decomposition.u_C);
      PETScWrappers::MPI::Vector ghosted(owned, complete_index_set(model.dofs().n_dofs()), comm);
      ghosted = u;
      matrices.assemble_stress_stiffness(model.dofs(), model.mesh().mapping(),
                                         model.mesh().cell_quadrature(), model.bodies(), ghosted,
                                         k_sigma);
    }

    const auto energy = [&](const PETScWrappers::MPI::SparseMatrix &A, const Vector<double> &v) {
      Vector<double> Av;
      replicated_vmult(A, v, Av);
      return v * Av;
    };
    const auto           fields = check_fields();
    const Vector<double> &tilt = fields[0], &twist = fields[1], &y_in_x = fields[2];
    const double s_tilt = energy(k_sigma, tilt), t_tilt = check_theta_tilt;
    const double s_twist = energy(k_sigma, twist), t_twist = check_theta_twist;
    const double yy = energy(matrices.mass, y_in_x);
    checks.emplace_back("check.speed_rpm", state.rpm);
    checks.emplace_back("check.tilt_virial", s_tilt / (w * yy));
    checks.emplace_back("check.twist_virial", s_twist / (w * t_twist));
    checks.emplace_back("check.tilt_cancellation", (s_tilt - w * t_tilt) / (w * t_tilt));
    log << "  self-check at " << state.rpm << " r/min: w^T K_sigma w / (Omega^2 int rho y^2) = "
        << std::setprecision(12) << checks[1].second << " (tilt), "
        << checks[2].second << " (twist, against Omega^2 w^T K_theta w); tilt "
        << "cancellation error " << std::setprecision(3) << checks[3].second << '\n';
  }

  void
  PrestressedEigenproblem::finish(Summary &summary) const
  {
    if (!compute || speeds_done == 0)
      return;
    for (const auto &[key, value] : checks)
      summary.add(key, value, 12);
    summary.add("eigen.speeds", speeds_done);
    summary.add("eigen.worst_backward_error", worst_backward_error, 12);
    summary.add("eigen.retried_speeds", retried_speeds);
    summary.add("eigen.full_solves", full_solves);
    summary.add("eigen.reduced_solves", reduced_solves);
    summary.add("eigen.reduced_refusals", reduced_refusals);
    summary.add("eigen.reduced_root_trials", reduced_trials);
    summary.add("eigen.undamped_anchors", undamped_served);
    summary.add("eigen.undamped_anchors_refused", undamped_refused);
    summary.add("eigen.undamped_anchors_on_tie_updates", updated_anchors);
    summary.add("eigen.tie_update_anchors_refused", updated_anchors_refused);
    // (an undamped anchor's speed is a reduced solve with the same checks)
    const bool any_reduced = reduced_solves + undamped_served > 0;
    if (any_reduced)
      {
        summary.add("eigen.reduced_worst_error_estimate", reduced_worst, 12);
        summary.add("eigen.reduced_worst_product_mismatch", reduced_worst_products, 12);
        summary.add("eigen.product_checks_skipped", product_checks_skipped);
        summary.add("eigen.estimate_gram_matrices", gram_builds);
        summary.add("eigen.estimate_gram_worst_difference", gram_worst_difference, 12);
        summary.add("eigen.residual_norm_gram_worst_difference", gram_norms_worst_difference, 12);
        summary.add("eigen.residual_norms_from_gram", gram_norm_speeds);
      }
    summary.add("eigen.workspace_retries", eigensolver.linear_solver().n_workspace_retries());
    summary.add("eigen.factorizations", eigensolver.linear_solver().n_factorizations());
    summary.add("eigen.factorizations_on_earlier_analysis",
                eigensolver.linear_solver().n_reused_analyses());
    log << "Eigenproblem: " << speeds_done << " speeds (" << full_solves << " full, "
        << reduced_solves << " on the reduced model, " << reduced_refusals
        << " refused by it; " << undamped_served << " on undamped anchors (" << updated_anchors
        << " on tie updates of an earlier LDL^T), "
        << undamped_refused << " refused by them; " << reduced_trials
        << " unchecked root-solve trials on it), "
        << eigensolver.linear_solver().n_factorizations()
        << " factorisations (LU of Q(sigma) or LDL^T of K_t + sigma^2 M), worst backward error "
        << worst_backward_error
        << (any_reduced ? ", largest estimated error of a reduced mode " : "");
    if (any_reduced)
      log << reduced_worst;
    log << '\n';
  }

  void
  PrestressedEigenproblem::warn_far_shift(const EigenSolution &solution, const double rpm)
  {
    // shift-invert orders the spectrum by |lambda - sigma|: far above the
    // lowest modes the wanted eigenvalues crowd together and ARPACK can
    // miss a member of a doublet (doc/limits.md)
    const double sigma_hz = eigensolver.shift() / (2 * M_PI);
    if (!shift_warned && !solution.elastic.empty() &&
        sigma_hz > std::abs(solution.elastic.front().lambda.imag()) / (2 * M_PI))
      {
        shift_warned = true;
        log << "Warning: Eigenproblem/Shift = " << sigma_hz
            << " Hz lies above the lowest elastic frequency found at " << rpm
            << " r/min (" << std::abs(solution.elastic.front().lambda.imag()) / (2 * M_PI)
            << " Hz): the shift-inverted eigenvalues crowd together and modes can be missed; "
               "keep the Shift below the lowest frequency of interest.\n";
      }
  }
} // namespace rotorfit
