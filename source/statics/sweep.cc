#include <rotorfit/base/input_error.h>
#include <rotorfit/base/run_control.h>
#include <rotorfit/statics/static_problem.h>

#include <deal.II/base/mpi.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    constexpr double inf = std::numeric_limits<double>::infinity();

    /// Speed [r/min] at which a pair with p = p_I + w p_C reaches p = 0.
    double
    opening_rpm(const double n_i, const double n_c)
    {
      if (!(n_c < 0))
        return inf;
      if (!(n_i > 0))
        return 0;
      return SpeedSchedule::rad_per_s_to_rpm(std::sqrt(-n_i / n_c));
    }

    /// Speed [r/min] at which the total force sum_A (N_I + w N_C) of the
    /// closed pairs @p ids of an interface vanishes: the loss of fit of that
    /// active set. Robust where single pairs are noisy (THEORY 9).
    double
    total_force_zero_rpm(const std::vector<unsigned int> &ids,
                         const std::vector<bool>         &active,
                         const std::vector<double>       &n_i,
                         const std::vector<double>       &n_c)
    {
      double sum_i = 0, sum_c = 0;
      for (const auto i : ids)
        if (active[i])
          {
            sum_i += n_i[i];
            sum_c += n_c[i];
          }
      return opening_rpm(sum_i, sum_c);
    }

    /// Above this ContactPairs::asymmetry() the stationary-frame
    /// eigenproblem (a rotationally symmetric rotor) no longer holds.
    constexpr double asymmetry_warning = 0.5;

    std::string
    format(const double x)
    {
      std::ostringstream s;
      s << std::setprecision(8) << x;
      return s.str();
    }
  } // namespace

  void
  StaticProblem::sweep(const SpeedCallback &after_speed)
  {
    const bool         root = Utilities::MPI::this_mpi_process(comm) == 0;
    const auto        &rpm  = speeds.speeds_rpm();
    const auto        &list = pairs.pairs();
    const unsigned int n_if = pairs.n_interfaces();

    std::ofstream table, openings;
    if (root)
      {
        table.open(output_dir + "/contact.csv");
        table << "speed_rpm,interface,closed_pairs,total_pairs,contact_fraction,"
                 "mean_pressure_Pa,max_pressure_Pa,constraint_error,"
                 "active_set_iterations,uzawa_iterations,factorizations,"
                 "low_rank_updates,converged,first_opening_rpm,loss_of_fit_rpm,"
                 "asymmetry,status\n"
              << std::setprecision(8) << std::flush;
        openings.open(output_dir + "/pair_openings.csv");
        openings << "interface,x_m,y_m,z_m,opening_rpm,from_rpm,to_rpm\n"
                 << std::setprecision(8) << std::flush;
      }

    std::vector<double> first_open(n_if, nan), loss_of_fit(n_if, nan);
    std::vector<bool>   fully_open(n_if, false);
    std::vector<double> mean_p0(n_if, nan), max_p0(n_if, nan), worst_error(n_if, 0.);
    std::vector<double> worst_asymmetry(n_if, 0.);
    unsigned int        unconverged_speeds = 0;
    std::vector<bool>   prev_active;
    std::vector<double> prev_I, prev_C, prev_force_I, prev_force_C;
    unsigned int        total_uzawa = 0;
    const auto          start       = std::chrono::steady_clock::now();
    unsigned int        steps_done  = 0;

    // when a fit never opened in the sweep, its loss of fit is extrapolated
    // from the last active set's affine law (or tangent): the same law as
    // the loss_of_fit_rpm column of the last row of contact.csv
    // after a failure, the last finished speed's laws (prev_*), never those
    // of the speed that failed
    const auto write_summary = [&](const bool failed) {
      std::ofstream summary;
      if (root)
        summary.open(output_dir + "/summary.txt", std::ios::app);
      summary << std::setprecision(8);
      const auto &d      = contact.decomposition();
      const bool  have   = failed ? !prev_active.empty() : d.valid;
      const auto &active = failed ? prev_active : d.active;
      const auto &f_I = failed ? prev_force_I : d.force_I, &f_C = failed ? prev_force_C : d.force_C;
      const auto &p_I = failed ? prev_I : d.pressure_I, &p_C = failed ? prev_C : d.pressure_C;
      for (unsigned int f = 0; f < n_if; ++f)
        {
          const std::string key = "interface." + interfaces.list()[f].name + ".";
          double            lof = loss_of_fit[f], first = first_open[f];
          if (!fully_open[f] && have)
            {
              double firstp = inf;
              for (const auto i : pairs.pairs_of(f))
                if (active[i])
                  firstp = std::min(firstp, opening_rpm(p_I[i], p_C[i]));
              lof = total_force_zero_rpm(pairs.pairs_of(f), active, f_I, f_C);
              if (std::isnan(first))
                first = firstp;
            }
          else if (!fully_open[f])
            lof = first = nan;
          summary << key << "pairs " << pairs.pairs_of(f).size() << '\n'
                  << key << "mean_pressure_first_speed_Pa " << mean_p0[f] << '\n'
                  << key << "max_pressure_first_speed_Pa " << max_p0[f] << '\n'
                  << key << "constraint_error_max " << worst_error[f] << '\n'
                  << key << "asymmetry_max " << worst_asymmetry[f] << '\n'
                  << key << "first_opening_rpm " << first << '\n'
                  << key << "loss_of_fit_rpm " << lof << '\n'
                  << key << "loss_of_fit_within_sweep " << (fully_open[f] ? 1 : 0) << '\n';
          log << "Interface " << interfaces.list()[f].name << ": first opening "
              << format(first) << " r/min, loss of fit " << format(lof) << " r/min"
              << (fully_open[f] ? "" :
                  d.affine        ? " (extrapolated beyond the sweep)" :
                                    " (extrapolated beyond the sweep along the last "
                                    "speed's tangent: a first-order estimate)")
              << '\n';
        }
      summary << "static.factorizations " << contact.n_factorizations() << '\n'
              << "static.low_rank_updates " << contact.n_low_rank_updates() << '\n'
              << "static.influence_columns " << contact.n_influence_columns() << '\n'
              << "static.uzawa_iterations " << total_uzawa << '\n'
              << "static.speeds " << steps_done << '\n'
              << "static.unconverged_speeds " << unconverged_speeds << '\n'
              << "static.workspace_retries " << contact.linear_solver().n_workspace_retries() << '\n';
    };

    try
    {
    for (unsigned int k = 0; k < rpm.size(); ++k)
      {
        run_control::stop_if_interrupted(comm, "before " + format(rpm[k]) + " r/min");
        current_step = k;
        const double               w = std::pow(SpeedSchedule::rpm_to_rad_per_s(rpm[k]), 2);
        ContactSolver::State       state;
        std::vector<double>        pressure;
        {
          TimerOutput::Scope t(*timer, "contact solve");
          state    = contact.solve(w);
          pressure = state.pressure;
        }
        // NaN or Inf (a factorisation that lost its digits, an extreme
        // penalty) must never reach a result file
        {
          unsigned int bad = 0;
          for (unsigned int i = 0; i < list.size(); ++i)
            bad += !(std::isfinite(state.force[i]) && std::isfinite(state.gap[i]) &&
                     std::isfinite(pressure[i]));
          if (bad > 0)
            throw SolverFailure(rpm[k],
                                "the static contact solve at " + format(rpm[k]) +
                                  " r/min gave non-finite forces, gaps or pressures "
                                  "(NaN or Inf) at " + std::to_string(bad) +
                                  " pairs: the factorisation lost its digits; lower "
                                  "Contact/Penalty scale (now " + format(contact.penalty_scale()) + ")");
        }
        total_uzawa += state.uzawa_iterations;
        const auto &d = contact.decomposition();

        std::ostringstream progress;
        bool               row_failed = false;
        std::string        asymmetric;
        for (unsigned int f = 0; f < n_if; ++f)
          {
            const auto  &ids = pairs.pairs_of(f);
            unsigned int closed = 0;
            double       force = 0, p_max = 0, error = 0;
            double       pred_last = 0;
            for (const auto i : ids)
              if (state.active[i])
                {
                  ++closed;
                  force += state.force[i];
                  p_max = std::max(p_max, pressure[i]);
                  error = std::max(error, std::abs(state.gap[i]) / list[i].interference);
                }
            pred_last = total_force_zero_rpm(ids, state.active, d.force_I, d.force_C);
            if (closed == 0)
              pred_last = nan;
            const double asymmetry = pairs.asymmetry(f, state.active);
            worst_asymmetry[f]     = std::max(worst_asymmetry[f], asymmetry);
            state.asymmetry        = std::max(state.asymmetry, asymmetry);
            std::string status = state.converged ? "ok" : state.reason;
            if (!(error <= contact.constraint_error_limit()))
              {
                status = (status == "ok" ? "" : status + "; ") + "constraint error " +
                         format(error) + " above " + format(contact.constraint_error_limit());
                row_failed = true;
              }
            if (asymmetry > asymmetry_warning)
              asymmetric += " " + interfaces.list()[f].name + " " + format(asymmetry);
            const double area    = pairs.closed_area(f, state.active);
            // total normal force over the closed area (exact for uniform p)
            const double p_mean  = closed > 0 ? force / area : 0.;
            const double fraction = area / pairs.area(f);
            worst_error[f] = std::max(worst_error[f], error);
            if (k == 0)
              {
                mean_p0[f] = p_mean;
                max_p0[f]  = p_max;
              }

            // pairs that opened since the previous speed: their opening speed
            // from the previous active set's affine law (exact for the first;
            // with spin softening the tangent at the previous speed: a Newton
            // step, first order)
            if (k > 0)
              {
                double first_now = inf, last_now = 0;
                for (const auto i : ids)
                  if (prev_active[i] && !state.active[i])
                    {
                      double o = opening_rpm(prev_I[i], prev_C[i]);
                      if (!std::isnan(o))
                        o = std::min(std::max(o, rpm[k - 1]), rpm[k]);
                      first_now = std::min(first_now, o);
                      last_now  = std::max(last_now, o);
                      if (root)
                        openings << interfaces.list()[f].name << ','
                                 << list[i].position[0] << ',' << list[i].position[1]
                                 << ',' << list[i].position[2] << ',' << o << ','
                                 << rpm[k - 1] << ',' << rpm[k] << '\n';
                    }
                if (std::isnan(first_open[f]) && first_now < inf)
                  first_open[f] = first_now;
                if (closed == 0 && !fully_open[f])
                  {
                    fully_open[f] = true;
                    double lof    = total_force_zero_rpm(ids, prev_active,
                                                         prev_force_I, prev_force_C);
                    if (!std::isnan(lof))
                      lof = std::min(std::max(lof, rpm[k - 1]), rpm[k]);
                    loss_of_fit[f] = lof;
                    log << "Interface " << interfaces.list()[f].name
                        << ": the fit is fully open between " << rpm[k - 1]
                        << " and " << rpm[k] << " r/min (loss of fit at "
                        << format(loss_of_fit[f]) << " r/min from the total "
                        << "contact force; last pair at " << format(last_now)
                        << " r/min)\n";
                  }
              }
            else if (closed < ids.size())
              log << "Interface " << interfaces.list()[f].name << ": "
                  << ids.size() - closed
                  << " pairs are already open at the first speed\n";

            if (root)
              table << rpm[k] << ',' << interfaces.list()[f].name << ',' << closed
                    << ',' << ids.size() << ',' << fraction << ',' << p_mean << ','
                    << p_max << ',' << error << ',' << state.active_set_iterations
                    << ',' << state.uzawa_iterations << ',' << state.factorizations
                    << ',' << state.low_rank_updates << ',' << (status == "ok" ? 1 : 0) << ',' << first_open[f]
                    << ',' << (fully_open[f] ? loss_of_fit[f] : pred_last) << ','
                    << asymmetry << ',' << status << '\n';
            progress << ' ' << interfaces.list()[f].name << ' ' << closed << '/'
                     << ids.size() << " closed, p_mean " << std::setprecision(4)
                     << p_mean / 1e6 << " MPa, error " << std::setprecision(2)
                     << error << ';';
          }
        if (root)
          {
            table << std::flush;
            openings << std::flush;
          }
        if (!state.converged)
          log << "Warning: the static contact state at " << rpm[k]
              << " r/min is not converged: " << state.reason
              << " (the last active set is kept, and may hold pairs in tension); its "
                 "rows have converged = 0, and so do its eigen rows.\n";
        if (row_failed)
          {
            log << "Warning: the constraint error at " << rpm[k]
                << " r/min exceeds its limit " << contact.constraint_error_limit()
                << " (see contact.csv, status); its rows have converged = 0.\n";
            state.reason += std::string(state.reason.empty() ? "" : "; ") + "constraint error";
            state.converged = false;
          }
        if (!state.converged)
          ++unconverged_speeds;
        if (!asymmetric.empty())
          log << "Warning: the closed set at " << rpm[k]
              << " r/min is not rotationally symmetric (asymmetry" << asymmetric << " > "
              << asymmetry_warning
              << "): the stationary-frame eigenproblem assumes a symmetric rotor; "
                 "treat this speed's modes with care.\n";

        if (write_paraview)
          {
            TimerOutput::Scope t(*timer, "output (ParaView)");
            write_vtu(k, rpm[k], state, pressure);
          }

        if (after_speed)
          {
            // the eigenproblem's LU needs the memory more than the next
            // active-set change needs this factor (at most one more
            // factorisation per speed where the contact changes)
            contact.release_factorization();
            after_speed(k, rpm[k], state);
          }

        ++steps_done;
        finished_steps = steps_done;
        const double elapsed =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const double eta = elapsed / steps_done * (rpm.size() - k - 1);
        log << '[' << k + 1 << '/' << rpm.size() << "] " << rpm[k] << " r/min:"
            << progress.str() << " iterations " << state.active_set_iterations
            << '/' << state.uzawa_iterations << '/' << state.factorizations
            << '/' << state.low_rank_updates
            << " (active set/Uzawa/factorisations/low-rank updates); " << std::fixed
            << std::setprecision(1) << elapsed << " s, ETA " << eta << " s"
            << std::defaultfloat << std::setprecision(6) << '\n';

        prev_active = state.active;
        prev_I       = d.pressure_I;
        prev_C       = d.pressure_C;
        prev_force_I = d.force_I;
        prev_force_C = d.force_C;

        if (stop_on_loss_of_fit && n_if > 0 &&
            std::all_of(fully_open.begin(), fully_open.end(), [](bool b) { return b; }))
          {
            log << "Every fit is fully open: the sweep stops here (Contact/On "
                   "loss of fit = stop).\n";
            break;
          }
      }

    }
    catch (...)
    {
      // the speeds already done keep their summary
      write_summary(true);
      throw;
    }
    write_summary(false);
    log << "Static sweep: " << steps_done << " speeds, "
        << contact.n_factorizations() << " factorisations, "
        << contact.n_low_rank_updates() << " low-rank updates ("
        << contact.n_influence_columns() << " influence columns), "
        << contact.linear_solver().n_solves()
        << " back-substitutions (influence columns included); "
        << std::fixed << std::setprecision(1) << contact.timing().factorize
        << " s factorising, " << contact.timing().columns
        << " s influence columns, " << contact.timing().solves
        << " s load-case back-substitutions" << std::defaultfloat
        << std::setprecision(6) << '\n';
  }

  std::string
  StaticProblem::progress() const
  {
    if (current_step < 0)
      return "during set-up";
    const auto &rpm = speeds.speeds_rpm();
    if (finished_steps == static_cast<unsigned int>(current_step) + 1)
      return "after " + format(rpm[current_step]) + " r/min (" + std::to_string(finished_steps) +
             " of " + std::to_string(rpm.size()) + " speeds finished)";
    return "at " + format(rpm[current_step]) + " r/min (speed " +
           std::to_string(current_step + 1) + " of " + std::to_string(rpm.size()) + "; " +
           std::to_string(finished_steps) + " speeds finished)";
  }

  void
  StaticProblem::print_timing(std::ostream &out) const
  {
    if (timer)
      {
        timer->print_summary();
        out << timer_stream.str();
      }
  }
} // namespace rotorfit
