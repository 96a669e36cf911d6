#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/eigen/prestressed_eigenproblem.h>
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
#include <sstream>
#include <string>
#include <vector>

namespace rotorfit
{
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
  /// The names a .prm lists; each has its own subsection.
  struct CaseNames
  {
    std::vector<std::string> bodies, interfaces, bearings, unbalances, probes;
  };

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

    /// Mesh, DoFs, pairs, supports, bearings: every input check that needs
    /// the mesh, and the memory estimate.
    void
    setup();

    /// The speed sweep.
    void
    run();

    /// Adaptive refinement (Mesh refinement): its parameters.
    const MeshRefinement &
    mesh_refinement() const
    {
      return refinement;
    }

    /// A refinement cycle: this mesh's added nodes, and collect the
    /// indicators during run().
    void
    start_refinement_cycle(const SectionMesh::Refinement &r)
    {
      model.set_mesh_refinement(r);
      collect_indicators = true;
    }

    /// The final run on the refined mesh; its log continues.
    void
    use_refinement(const SectionMesh::Refinement &r)
    {
      model.set_mesh_refinement(r);
      results.reopen_log();
    }

    /// After a cycle's run(): the nodes of the next mesh.
    SectionMesh::Refinement
    refine() const
    {
      return refinement.refine(model, log);
    }

    /// DoFs of the mesh after setup().
    dealii::types::global_dof_index
    n_dofs() const
    {
      return model.dofs().n_dofs();
    }

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
    /// Mode shapes (and static state) at crossing @p i found at @p state's
    /// speed, of its root solve's @p solution (solved here if empty); called
    /// from within the root solve's timer section.
    void
    write_critical_shapes(const StaticState &state, unsigned int i, EigenSolution &&solution);
    /// The log line of a finished speed (contact state, iterations, ETA).
    void
    log_speed(const StaticState &state);

    /// One physical surface carrying two features (two fits, a bearing on
    /// a fit) counts it twice.
    void
    check_surface_use() const;
    /// The rim speed at the last speed against what any rotor survives
    /// (refused), and each body's against the burst range of metal disks
    /// (warned).
    void
    check_tip_speed() const;
    /// Memory of the run's largest phase against the machine's.
    void
    check_resources() const;

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
    bool                    collect_indicators = false;
    bool                    stop_on_loss_of_fit = false;

    // where the sweep is (progress(), finish())
    bool         assembled      = false;
    bool         finished       = false;
    int          current_step   = -1;
    unsigned int finished_steps = 0;
    unsigned int modal_steps    = 0;
    std::chrono::steady_clock::time_point sweep_start;
  };
} // namespace rotorfit
