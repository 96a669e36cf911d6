#include <rotorfit/base/format.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/base/resources.h>
#include <rotorfit/base/run_control.h>
#include <rotorfit/problem/rotor_problem.h>

#include <deal.II/base/mpi.h>

#include <cmath>
#include <iomanip>
#include <sstream>

// RotorProblem, part 1: the run. Part 2 (parameters, set-up and the input
// checks that need the mesh): rotor_problem_setup.cc.

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    /// (paused while a crossing's shapes are written from within it)
    const std::string root_solve_section = "critical speeds (root solve)";
  } // namespace

  // The story of a run: setup() (mesh, pairs, supports, the input checks),
  // run() below, then finish() (summary.txt, the pictures); the command
  // line (app/application.cc) calls the three.
  void
  RotorProblem::run()
  {
    assemble_speed_independent_matrices();
    if (eigen.enabled())
      // the static factorisation would otherwise be held next to every
      // eigen factorisation, the run's memory peak
      statics.solve_ahead(speeds.speeds_rpm());
    if (collect_indicators)
      refinement.reset(model);
    const auto &rpm = speeds.speeds_rpm();
    for (unsigned int k = 0; k < rpm.size(); ++k)
      {
        run_control::stop_if_interrupted(comm, "before " + format_number(rpm[k]) + " r/min");
        current_step = k;

        const StaticState &state = statics.solve(rpm[k], k);
        if (collect_indicators)
          refinement.add_static(model, state);
        {
          TimerOutput::Scope t(timer, "output (tables, ParaView)");
          results.add(state);
        }
        if (eigen.enabled())
          {
            // the eigenproblem's LU needs the memory more than the next
            // active-set change needs the static one (at most one more
            // factorisation per speed where the contact changes)
            statics.release_factorization();
            EigenSolution solution = eigen.solve(state);
            if (collect_indicators)
              refinement.add_modes(model, solution);
            if (response.enabled())
              {
                TimerOutput::Scope t(timer, "unbalance response");
                results.add(response.solve(state, eigen.operators(), solution.elastic));
              }
            {
              TimerOutput::Scope t(timer, "modal analysis + output");
              modal.analyse(std::move(solution));
            }
            {
              // after the response: the trials replace the speed's matrices
              TimerOutput::Scope t(timer, root_solve_section);
              modal.solve_crossings(state, eigen, [&](const unsigned int i, EigenSolution &&s) {
                if (results.shapes_at_critical_speeds())
                  write_critical_shapes(state, i, std::move(s));
              });
            }
            {
              TimerOutput::Scope t(timer, "modal analysis + output");
              results.add(state, modal.last_result());
            }
            ++modal_steps;
            {
              // a damping ratio that changed sign: root solve in the speed
              TimerOutput::Scope t(timer, "stability onsets");
              results.add(onsets.find(modal.last_result(), state, eigen));
            }
          }

        finished_steps = k + 1;
        log_speed(state);
        if (stop_on_loss_of_fit && statics.every_fit_open())
          {
            log << "Every fit is fully open: the sweep stops here (Contact/On "
                   "loss of fit = stop).\n";
            break;
          }
      }
  }

  void
  RotorProblem::write_critical_shapes(const StaticState &state,
                                      const unsigned int i,
                                      EigenSolution    &&solution)
  {
    // crossing i since the previous speed, solved at its own speed on this
    // speed's contact law (as the stability onsets are); its time is its own,
    // not the root solve's it is called from (whose call count then counts
    // one more per crossing)
    struct Pause
    {
      TimerOutput       &timer;
      const std::string  name;
      Pause(TimerOutput &t, const std::string &section)
        : timer(t)
        , name(section)
      {
        timer.leave_subsection(name);
      }
      ~Pause()
      {
        try
          {
            timer.enter_subsection(name);
          }
        catch (...) // (the table's time only; never terminate on unwinding)
          {}
      }
    } pause(timer, root_solve_section);
    TimerOutput::Scope t(timer, "mode shapes at critical speeds");
    StaticState        trial = state;
    trial.rpm                = modal.last_result().crossings[i].rpm;
    try
      {
        // the root solve's checked solve at that speed, else a new one
        results.add_critical(trial, modal.classify(solution.elastic.empty() ?
                                                     eigen.solve(trial) :
                                                     std::move(solution)));
      }
    catch (const SolverFailure &e)
      {
        log << "Warning: no mode shapes at the critical speed " << format_number(trial.rpm)
            << " r/min: the eigensolver failed there (" << e.what() << ").\n";
      }
  }

  void
  RotorProblem::assemble_speed_independent_matrices()
  {
    statics.assemble(std::pow(SpeedSchedule::rpm_to_rad_per_s(speeds.speeds_rpm().back()), 2));
    assembled = true; // from here on summary.txt has the static entries
    eigen.assemble_speed_independent_matrices();
    results.open(model, eigen.enabled(), response.enabled(), statics.exact_path());
    sweep_start = std::chrono::steady_clock::now();
  }

  void
  RotorProblem::log_speed(const StaticState &state)
  {
    const auto &c = state.contact;
    std::ostringstream line;
    for (const auto &row : state.interfaces)
      line << ' ' << row.name << ' ' << row.closed_pairs << '/' << row.total_pairs
           << " closed, p_mean " << std::setprecision(4) << row.mean_pressure / 1e6
           << " MPa, error " << std::setprecision(2) << row.constraint_error << ';';
    const std::size_t n_speeds = speeds.speeds_rpm().size();
    const double      elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - sweep_start).count();
    const double eta = elapsed / finished_steps * (n_speeds - finished_steps);
    log << '[' << finished_steps << '/' << n_speeds << "] " << state.rpm << " r/min:"
        << line.str() << " iterations " << c.active_set_iterations << '/' << c.uzawa_iterations
        << '/' << c.factorizations << '/' << c.low_rank_updates
        << " (active set/Uzawa/factorisations/low-rank updates); " << std::fixed
        << std::setprecision(1) << elapsed << " s, ETA " << eta << " s" << std::defaultfloat
        << std::setprecision(6) << '\n';
  }

  void
  RotorProblem::finish(const std::string &status,
                       const int          exit_code,
                       const std::string &where,
                       const std::string &message)
  {
    // once only, and never throwing: it runs on the way out of a failure
    if (finished)
      return;
    finished = true;
    try
      {
        write_summary(status, exit_code, where, message);
      }
    catch (const std::exception &e)
      {
        log << "rotorfit: summary.txt could not be completed: " << e.what() << '\n';
      }
  }

  void
  RotorProblem::write_summary(const std::string &status,
                              const int          exit_code,
                              const std::string &where,
                              const std::string &message)
  {
    Summary summary;
    if (assembled)
      {
        statics.finish(summary);
        eigen.finish(summary);
        if (modal_steps > 0)
          {
            modal.finish(summary);
            onsets.finish(summary);
          }
        response.finish(summary);
        results.add(response.peaks());
      }
    summary.add("run.status", status);
    summary.add("run.exit_code", exit_code);
    if (!where.empty())
      summary.add("run.stopped_at", where);
    if (!message.empty())
      summary.add("run.message", message);
    // the job's memory: every rank's peak resident set, added (Linux)
    const double peak = Utilities::MPI::sum(resources::resident_bytes(true), comm);
    summary.add("run.peak_memory_gb", peak / 1e9);
    log << "Peak memory: " << resources::gigabytes(peak) << " (resident, all ranks)\n";
    results.finish(summary, modal_steps > 0);
    if (assembled)
      {
        timer.print_summary();
        log << timer_stream.str();
      }
  }

  std::string
  RotorProblem::progress() const
  {
    if (current_step < 0)
      return "during set-up";
    const auto &rpm = speeds.speeds_rpm();
    if (finished_steps == static_cast<unsigned int>(current_step) + 1)
      return "after " + format_number(rpm[current_step]) + " r/min (" + std::to_string(finished_steps) +
             " of " + std::to_string(rpm.size()) + " speeds finished)";
    return "at " + format_number(rpm[current_step]) + " r/min (speed " +
           std::to_string(current_step + 1) + " of " + std::to_string(rpm.size()) + "; " +
           std::to_string(finished_steps) + " speeds finished)";
  }
} // namespace rotorfit
