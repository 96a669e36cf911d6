#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/eigen/prestressed_eigenproblem.h>
#include <rotorfit/harmonic/harmonic_problem.h>
#include <rotorfit/modal/modal_analysis.h>
#include <rotorfit/modal/stability_onset.h>
#include <rotorfit/response/unbalance_response.h>
#include <rotorfit/model/discretization.h>
#include <rotorfit/refinement/mesh_refinement.h>
#include <rotorfit/output/results.h>
#include <rotorfit/statics/speed_schedule.h>
#include <rotorfit/statics/static_problem.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/timer.h>

#include <chrono>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace rotorfit
{
  /// The names a .prm lists; each has its own subsection.
  struct CaseNames
  {
    std::vector<std::string> bodies, interfaces, bearings, unbalances, probes;
  };

  /**
   * A rotorfit run: a shrink-fitted assembly taken through its speeds. At
   * every speed the contact state of the fits is solved anew, then the
   * pre-stressed damped modes on that state; the results of each speed are
   * written before the next begins. run() is the table of contents; each
   * member is one concern:
   *
   * - model: mesh, finite elements, fit pairs, supports (model/);
   * - statics: elasticity with contact under interference and spin (statics/);
   * - eigen: the damped eigenproblem on the static state (eigen/);
   * - modal: whirl, tracking, critical speeds (modal/);
   * - response: the steady unbalance response on the same matrices (response/);
   * - results: the output folder and its files (output/).
   *
   * Parameters: subsections "Speeds" and "Contact/On loss of fit", and
   * those of the members.
   */
  class RotorProblem
  {
  public:
    RotorProblem(const MPI_Comm comm, Log &log);

    /// Every entry; the per-name subsections for the names given.
    static void
    declare_parameters(dealii::ParameterHandler &prm, const CaseNames &names);

    /// @p prm_directory: where relative file names in the .prm start;
    /// @p output_override: the command line's --output (empty: the file's).
    void
    parse_parameters(dealii::ParameterHandler &prm,
                     const std::string        &prm_directory,
                     const std::string        &output_override);

    /// Refuse an output folder that cannot be written (no side effect).
    void
    check_output() const
    {
      results.check_writable();
    }

    /// Create and lock the output folder; from here on finish() leaves
    /// the run's status in it.
    void
    prepare_output(const dealii::ParameterHandler &prm)
    {
      results.prepare_directory(prm);
    }

    const std::string &
    output_directory() const
    {
      return results.directory();
    }
    /// The bodies and interfaces as parsed (before setup(): no mesh yet).
    const Discretization &
    discretization() const
    {
      return model;
    }

    /// Mesh, DoFs, pairs, supports, bearings: every input check that needs
    /// the mesh, and the memory estimate.
    void
    setup();

    /// Reads the case into a fresh handler: its file, then the command
    /// line's --set overrides.
    using CaseReader = std::function<void(dealii::ParameterHandler &)>;

    /**
     * Adaptive refinement (doc/theory.md 1.4), before setup(): Mesh
     * refinement/Cycles runs of the case at its indicator speeds, each in
     * <output>/cycle_<k>/, each refining the section mesh where its
     * indicators are largest; this run then uses the last refinement.
     * Returns the exit code of a cycle that stopped (its results stay in its
     * folder), else exit_code::success. Nothing to do without cycles.
     */
    int
    refine_mesh(const CaseReader &read_case);

    /// The speed sweep.
    void
    run();

    /// run(), then finish() with the run's status: the exit code (a
    /// refusal during the sweep, InputError, is left to the caller).
    int
    run_and_finish();

    /// summary.txt (with @p status: completed, failed, interrupted,
    /// refused, and where and why it stopped), campbell.png and the timing.
    /// Once only; never throws.
    void
    finish(const std::string &status,
           const int          exit_code,
           const std::string &where   = "",
           const std::string &message = "");

    /// Where the sweep is, for a stop message: "at 12000 r/min (speed 13 of
    /// 31; 12 speeds finished)", or "during set-up".
    std::string
    progress() const;

  private:
    void
    write_summary(const std::string &status,
                  const int          exit_code,
                  const std::string &where,
                  const std::string &message);
    void
    assemble_speed_independent_matrices();

    /// Set up as refinement cycle @p c of @p main at the speeds @p list
    /// [r/min], on the mesh with @p nodes added: the case read again, in
    /// main's cycle_<c> folder, collecting indicators, without ParaView
    /// files and pictures.
    void
    start_refinement_cycle(const RotorProblem            &main,
                           const CaseReader              &read_case,
                           const unsigned int             c,
                           const std::string             &list,
                           const SectionMesh::Refinement &nodes);

    // the phases of a speed, each timed on its own
    /// run() on the harmonic model.
    void
    run_harmonic();
    /// Before the first speed: the exact path ahead, the indicators reset.
    void
    start_sweep();
    /// The contact state of the @p k-th speed, and its tables.
    const StaticState &
    solve_statics(const unsigned int k);
    /// The modes, response, critical speeds and stability onsets at
    /// @p state's speed.
    void
    solve_modes(const StaticState &state);
    void
    solve_response(const StaticState &state, const EigenSolution &solution);
    void
    analyse_modes(EigenSolution &&solution);
    /// The crossings since the previous speed, with their mode shapes.
    void
    solve_critical_speeds(const StaticState &state);
    void
    write_modes(const StaticState &state);
    void
    find_stability_onsets(const StaticState &state);
    /// Mode shapes (and static state) at crossing @p i found at @p state's
    /// speed, of its root solve's @p solution (solved here if empty); called
    /// from within the root solve's timer section.
    void
    write_critical_shapes(const StaticState &state, unsigned int i, EigenSolution &&solution);
    /// The log line of a finished speed (contact state, iterations, ETA).
    void
    log_speed(const StaticState &state);

    MPI_Comm                comm;
    Log                    &log;
    std::ostringstream      timer_stream;
    dealii::TimerOutput     timer;
    Discretization          model;
    SpeedSchedule           speeds;
    StaticProblem           statics;
    PrestressedEigenproblem eigen;
    ModalAnalysis           modal;
    StabilityOnsets         onsets;
    UnbalanceResponse       response;
    Results                 results;
    MeshRefinement          refinement;
    /// Geometry/Model = axisymmetric: the run on the meridian (else null)
    std::unique_ptr<HarmonicProblem> harmonic;
    std::string             prm_directory; ///< where the .prm's relative names start
    bool                    collect_indicators = false;
    /// What the sweep does once every fit is fully open (Contact/On loss of fit).
    enum class OnLossOfFit
    {
      continue_sweep,
      stop
    };
    OnLossOfFit on_loss_of_fit = OnLossOfFit::continue_sweep;

    // where the sweep is (progress(), finish())
    bool         assembled      = false;
    bool         finished       = false;
    int          current_step   = -1;
    unsigned int finished_steps = 0;
    unsigned int modal_steps    = 0;
    std::chrono::steady_clock::time_point sweep_start;
  };
} // namespace rotorfit
