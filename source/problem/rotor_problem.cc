#include <rotorfit/base/format.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/base/resources.h>
#include <rotorfit/base/run_control.h>
#include <rotorfit/mesh/section_mesh.h>
#include <rotorfit/problem/case_checks.h>
#include <rotorfit/problem/rotor_problem.h>

#include <deal.II/base/mpi.h>

#include <cmath>
#include <iomanip>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    /// (paused while a crossing's shapes are written from within it)
    const std::string root_solve_section = "critical speeds (root solve)";
  } // namespace

  RotorProblem::RotorProblem(const MPI_Comm comm, Log &log)
    : comm(comm)
    , log(log)
    , timer(timer_stream, TimerOutput::never, TimerOutput::wall_times)
    , model(comm, log)
    , statics(model, log, timer)
    , eigen(model, log, timer)
    , modal(log)
    , onsets(log)
    , response(model, log)
    , results(comm, log)
  {}

  void
  RotorProblem::declare_parameters(ParameterHandler &prm, const CaseNames &names)
  {
    Discretization::declare_parameters(prm);
    SpeedSchedule::declare_parameters(prm);
    StaticProblem::declare_parameters(prm);
    PrestressedEigenproblem::declare_parameters(prm);
    ModalAnalysis::declare_parameters(prm);
    Results::declare_parameters(prm);
    MeshRefinement::declare_parameters(prm);
    HarmonicProblem::declare_parameters(prm);
    Bodies::declare_parameters(prm, names.bodies);
    SectionMesh::declare_body_parameters(prm, names.bodies);
    ContactInterfaces::declare_parameters(prm, names.interfaces);
    Bearings::declare_parameters(prm, names.bearings);
    UnbalanceResponse::declare_lists(prm);
    UnbalanceResponse::declare_parameters(prm, names.unbalances, names.probes);
    prm.enter_subsection("Contact");
    prm.declare_entry("On loss of fit",
                      "continue",
                      Patterns::Selection("continue|stop"),
                      "What the sweep does once every interface is fully "
                      "open: 'continue' (loose bodies held by their "
                      "cylindrical supports) or 'stop'.");
    prm.leave_subsection();
  }

  void
  RotorProblem::parse_parameters(ParameterHandler  &prm,
                                 const std::string &prm_directory,
                                 const std::string &output_override)
  {
    this->prm_directory = prm_directory;
    model.parse_parameters(prm, prm_directory);
    speeds.parse_parameters(prm);
    statics.parse_parameters(prm);
    eigen.parse_parameters(prm, prm_directory, statics.spin_softening_on());
    modal.parse_parameters(prm);
    response.parse_parameters(prm, eigen.enabled());
    results.parse_parameters(prm, output_override);
    results.check_speeds(speeds.speeds_rpm());
    refinement.parse_parameters(prm, model.mesh().hexahedral());
    prm.enter_subsection("Contact");
    on_loss_of_fit =
      prm.get("On loss of fit") == "stop" ? OnLossOfFit::stop : OnLossOfFit::continue_sweep;
    prm.leave_subsection();
    case_checks::surface_use(model, eigen.bearing_list(), log);
    if (model.mesh().axisymmetric_model())
      {
        harmonic = std::make_unique<HarmonicProblem>(comm, log, timer);
        harmonic->parse_parameters(prm);
      }
  }

  void
  RotorProblem::setup()
  {
    // what the parsers accepted but found suspect, now that the log is open
    for (const auto *list : {&model.bodies().warnings(), &speeds.warnings()})
      for (const auto &w : *list)
        log << "Warning: " << w << ".\n";
    if (harmonic)
      {
        harmonic->setup(model, eigen.bearing_list(), response);
        return;
      }
    model.setup(timer);
    case_checks::tip_speed(model, speeds.speeds_rpm().back(), log);
    eigen.setup();
    if (eigen.enabled())
      modal.setup(model);
    if (eigen.enabled() && model.element_order() == 1)
      log << "Warning: Geometry/Element order = 1: linear elements lock in bending (a "
             "free-free cylinder's first bending frequency comes out 8 % high on hexahedra, "
             "13 % on tetrahedra) and, under the quadratic geometry, miss rigid motions on "
             "curved cells (spurious modes far below the first bending mode); set it to 2 "
             "for the eigenproblem (doc/limits.md).\n";
    response.setup(eigen.bearing_list());
    case_checks::resources(model, eigen, comm, log);
  }

  // The story of a run, as the command line (app/application.cc) calls it:
  // refine_mesh() where Mesh refinement/Cycles asks for it, setup() (mesh,
  // pairs, supports, the input checks), then run_and_finish(): run() below
  // and finish() (summary.txt, the pictures). Each phase keeps its own timer.
  void
  RotorProblem::run()
  {
    if (harmonic)
      {
        run_harmonic();
        return;
      }
    assemble_speed_independent_matrices();
    start_sweep();
    const auto &rpm = speeds.speeds_rpm();
    for (unsigned int k = 0; k < rpm.size(); ++k)
      {
        run_control::stop_if_interrupted(comm, "before " + format_number(rpm[k]) + " r/min");
        current_step = k;

        const StaticState &state = solve_statics(k);
        if (eigen.enabled())
          solve_modes(state);

        finished_steps = k + 1;
        log_speed(state);
        if (on_loss_of_fit == OnLossOfFit::stop && statics.every_fit_open())
          {
            log << "Every fit is fully open: the sweep stops here (Contact/On "
                   "loss of fit = stop).\n";
            break;
          }
      }
  }

  void
  RotorProblem::run_harmonic()
  {
    const auto &rpm = speeds.speeds_rpm();
    harmonic->start(results.directory(), std::pow(SpeedSchedule::rpm_to_rad_per_s(rpm.back()), 2));
    results.draw_harmonic_tables(!model.interfaces().list().empty(), response.enabled());
    if (collect_indicators)
      {
        refinement.reset_meridian(harmonic->meridian_model());
        harmonic->collect_indicators(refinement);
      }
    assembled   = true;
    sweep_start = std::chrono::steady_clock::now();
    for (unsigned int k = 0; k < rpm.size(); ++k)
      {
        run_control::stop_if_interrupted(comm, "before " + format_number(rpm[k]) + " r/min");
        current_step             = k;
        const auto [solution, shapes]                   = results.paraview_files(k, rpm[k]);
        const auto [critical_solution, critical_shapes] = results.critical_files();
        const StaticState &state =
          harmonic->solve_speed(k, rpm[k], {solution, shapes, critical_solution, critical_shapes});
        finished_steps           = k + 1;
        log_speed(state);
        if (on_loss_of_fit == OnLossOfFit::stop && harmonic->every_fit_open())
          {
            log << "Every fit is fully open: the sweep stops here (Contact/On "
                   "loss of fit = stop).\n";
            break;
          }
      }
  }

  void
  RotorProblem::start_sweep()
  {
    if (eigen.enabled())
      // the static factorisation would otherwise be held next to every
      // eigen factorisation, the run's memory peak
      statics.solve_ahead(speeds.speeds_rpm());
    if (collect_indicators)
      refinement.reset(model);
  }

  const StaticState &
  RotorProblem::solve_statics(const unsigned int k)
  {
    const StaticState &state = statics.solve(speeds.speeds_rpm()[k], k);
    if (collect_indicators)
      refinement.add_static(model, state);
    TimerOutput::Scope t(timer, "output (tables, ParaView)");
    results.write_static_state(state);
    return state;
  }

  void
  RotorProblem::solve_modes(const StaticState &state)
  {
    // the eigenproblem's LU needs the memory more than the next active-set
    // change needs the static one (at most one more factorisation per speed
    // where the contact changes)
    statics.release_factorization();
    EigenSolution solution = eigen.solve(state);
    if (collect_indicators)
      refinement.add_modes(model, solution);
    if (response.enabled())
      solve_response(state, solution);
    analyse_modes(std::move(solution));
    // after the response: the trials replace the speed's matrices
    solve_critical_speeds(state);
    write_modes(state);
    ++modal_steps;
    find_stability_onsets(state);
  }

  void
  RotorProblem::solve_response(const StaticState &state, const EigenSolution &solution)
  {
    TimerOutput::Scope t(timer, "unbalance response");
    results.write_response(response.solve(state, eigen.operators(), solution.elastic));
  }

  void
  RotorProblem::analyse_modes(EigenSolution &&solution)
  {
    TimerOutput::Scope t(timer, "modal analysis + output");
    modal.analyse(std::move(solution));
  }

  void
  RotorProblem::solve_critical_speeds(const StaticState &state)
  {
    TimerOutput::Scope t(timer, root_solve_section);
    modal.solve_crossings(state, eigen, [&](const unsigned int i, EigenSolution &&s) {
      if (results.shapes_at_critical_speeds())
        write_critical_shapes(state, i, std::move(s));
    });
  }

  void
  RotorProblem::write_modes(const StaticState &state)
  {
    TimerOutput::Scope t(timer, "modal analysis + output");
    results.write_modes(state, modal.last_result());
  }

  void
  RotorProblem::find_stability_onsets(const StaticState &state)
  {
    // a damping ratio that changed sign: root solve in the speed
    TimerOutput::Scope t(timer, "stability onsets");
    results.write_stability_onsets(onsets.find(modal.last_result(), state, eigen));
  }

  int
  RotorProblem::run_and_finish()
  {
    try
      {
        run_control::stop_if_interrupted(comm, "before the first speed");
        run();
      }
    catch (const InputError &)
      {
        throw;
      }
    catch (const Interrupted &e)
      {
        const std::string where = progress();
        log << "rotorfit: " << e.what() << "; stopped " << where << ". The finished speeds are in "
            << output_directory() << ".\n";
        finish("interrupted", exit_code::interrupted, where, e.what());
        return exit_code::interrupted;
      }
    catch (const std::exception &e)
      {
        const std::string where = progress();
        log << "rotorfit: failure during the solve (" << where << "): " << e.what()
            << "\nThe speeds already done are in " << output_directory() << ".\n";
        finish("failed", exit_code::solver, where, e.what());
        return exit_code::solver;
      }
    finish("completed", exit_code::success);
    return exit_code::success;
  }

  int
  RotorProblem::refine_mesh(const CaseReader &read_case)
  {
    if (refinement.cycles() == 0)
      return exit_code::success;

    std::string list;
    for (const double s : refinement.speeds())
      list += (list.empty() ? "" : ", ") + format_number(s);
    SectionMesh::Refinement nodes;
    int                     code = exit_code::success;
    for (unsigned int c = 0; c < refinement.cycles(); ++c)
      {
        RotorProblem cycle(comm, log);
        cycle.start_refinement_cycle(*this, read_case, c, list, nodes);
        cycle.setup();
        code = cycle.run_and_finish();
        if (code != exit_code::success)
          break;
        const auto n_dofs =
          cycle.harmonic ? cycle.harmonic->max_harmonic_dofs() : cycle.model.dofs().n_dofs();
        if (refinement.dof_target() > 0 && n_dofs >= refinement.dof_target())
          {
            log << "Mesh refinement: " << n_dofs << " DOFs reach the DOF target "
                << refinement.dof_target() << "; no further cycle.\n";
            break;
          }
        nodes = cycle.harmonic ? cycle.refinement.refine_meridian(cycle.model.mesh().sections(),
                                                                  cycle.harmonic->meridian_model(),
                                                                  log) :
                                 cycle.refinement.refine(cycle.model, log);
      }
    // this run on the refined mesh; its log continues after the cycles'
    model.set_mesh_refinement(nodes);
    results.reopen_log();
    return code;
  }

  void
  RotorProblem::start_refinement_cycle(const RotorProblem            &main,
                                       const CaseReader              &read_case,
                                       const unsigned int             c,
                                       const std::string             &list,
                                       const SectionMesh::Refinement &nodes)
  {
    // the case at the indicator speeds, without the files only the final
    // run needs; its parameters.prm records these entries
    ParameterHandler prm;
    read_case(prm);
    struct Entry
    {
      const char *section, *name;
      std::string value;
    };
    for (const Entry &e : {Entry{"Speeds", "Mode", "list"},
                           Entry{"Speeds", "List", list},
                           Entry{"Output", "Write ParaView files", "false"},
                           Entry{"Eigenproblem", "Write mode shapes", "false"},
                           Entry{"Output", "Pictures", "false"},
                           Entry{"Mesh refinement", "Cycles", "0"}})
      {
        prm.enter_subsection(e.section);
        prm.set(e.name, e.value);
        prm.leave_subsection();
      }
    parse_parameters(prm,
                     main.prm_directory,
                     main.output_directory() + "/cycle_" + std::to_string(c));
    prepare_output(prm);
    model.set_mesh_refinement(nodes);
    collect_indicators = true;
    log << "Mesh refinement: cycle " << c << " of " << main.refinement.cycles() << " at " << list
        << " r/min, results in " << output_directory() << '\n';
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
        results.write_critical_shapes(trial, modal.classify(solution.elastic.empty() ?
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
    results.open(model, {eigen.enabled(), response.enabled(), statics.speed_path()});
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
    if (harmonic && assembled)
      {
        harmonic->finish(summary);
        response.finish(summary);
        results.write_response_peaks(response.peaks());
      }
    else if (assembled)
      {
        statics.finish(summary);
        eigen.finish(summary);
        if (modal_steps > 0)
          {
            modal.finish(summary);
            onsets.finish(summary);
          }
        response.finish(summary);
        results.write_response_peaks(response.peaks());
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
    results.finish(summary, harmonic ? harmonic->modes_written() : modal_steps > 0);
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
