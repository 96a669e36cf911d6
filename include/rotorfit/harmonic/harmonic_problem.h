#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/base/summary.h>
#include <rotorfit/bearing/bearings.h>
#include <rotorfit/contact/contact_solver.h>
#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/eigen/speed_eigenproblem.h>
#include <rotorfit/fit/fit_assessment.h>
#include <rotorfit/harmonic/harmonic_assembler.h>
#include <rotorfit/harmonic/harmonic_mode.h>
#include <rotorfit/harmonic/harmonic_operators.h>
#include <rotorfit/harmonic/harmonic_reduced_model.h>
#include <rotorfit/harmonic/harmonic_response.h>
#include <rotorfit/harmonic/harmonic_waves.h>
#include <rotorfit/harmonic/meridian_model.h>
#include <rotorfit/harmonic/meridian_output.h>
#include <rotorfit/modal/mode_tracker.h>
#include <rotorfit/modal/stability_onset.h>
#include <rotorfit/model/discretization.h>
#include <rotorfit/output/tables.h>
#include <rotorfit/refinement/mesh_refinement.h>
#include <rotorfit/response/unbalance_response.h>
#include <rotorfit/statics/fit_history.h>
#include <rotorfit/statics/static_state.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/timer.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace rotorfit
{
  /**
   * A run on the axisymmetric harmonic model (Geometry/Model = axisymmetric,
   * doc/theory.md 14): at every speed the static contact state of the fits
   * on the meridian (harmonic 0, ring pairs, the exact path of the 3D model's
   * ContactSolver), then for every listed harmonic the damped eigenproblem
   * of section 4 on that state (pre-stress, -Omega^2 K_theta, gyroscopics,
   * closed rings tied, bearings on harmonic 1), by the 3D model's
   * DampedEigensolver. The modes of each harmonic are tracked into the
   * lines of the Campbell diagram (ModeTracker, lines numbered over all
   * harmonics), their crossings with the excitation orders and the sign
   * changes of their damping are root-solved on the harmonic's own
   * eigenproblem (solve_crossing, StabilityOnsets: the 3D model's code).
   * Writes contact.csv, pair_openings.csv, contact_events.csv,
   * campbell.csv, critical_speeds.csv and stability_onsets.csv (with the
   * harmonic of each line), and adds its keys to summary.txt.
   *
   * Parameters: subsection "Harmonic model"; it reads the entries of
   * "Eigenproblem", "Contact" and "Physics" the 3D model declares.
   */
  class HarmonicProblem
  {
  public:
    HarmonicProblem(const MPI_Comm comm, Log &log, dealii::TimerOutput &timer);

    static void
    declare_parameters(dealii::ParameterHandler &prm);

    void
    parse_parameters(dealii::ParameterHandler &prm);

    /// The meridian of @p model's bodies and interfaces, the stations of
    /// @p bearings and of @p response's unbalances and probes; refuses what
    /// the model cannot represent.
    void
    setup(const Discretization &model, const Bearings &bearings, UnbalanceResponse &response);

    /// Assemble, open the tables in @p directory; @p w_max: the largest
    /// Omega^2 of the run.
    void
    start(const std::string &directory, const double w_max);

    /// Which ParaView files a speed gets (Output/ParaView speeds).
    struct ParaViewFiles
    {
      bool solution = false; ///< the static state on the meridian
      bool modes    = false; ///< the mode shapes, swept around the axis
      /// the same at each critical speed found since the previous speed
      bool critical_solution = false, critical_modes = false;
    };

    /// The static state and the modes of speed @p k, @p rpm; tables and
    /// the ParaView files of @p files written.
    const StaticState &
    solve_speed(const unsigned int k, const double rpm, const ParaViewFiles files);

    /// Feed @p refinement's indicators at every speed (a refinement cycle):
    /// the static displacement and harmonic 1's lowest modes.
    void
    collect_indicators(MeshRefinement &refinement)
    {
      indicators = &refinement;
    }

    const MeridianModel &
    meridian_model() const
    {
      return meridian;
    }

    /// The largest harmonic's DoFs (the DOF target of the refinement).
    unsigned int
    max_harmonic_dofs() const;

    bool
    every_fit_open() const
    {
      return history && history->every_fit_open();
    }

    void
    finish(Summary &summary) const;

    /// Whether campbell.csv is written (its picture can be drawn).
    bool
    modes_written() const
    {
      return compute_modes && eigen_solves > 0;
    }

  private:
    /// One harmonic's damped eigenproblem, for the root solves along its
    /// lines (no reduced model: a trial is the checked solve of a plane
    /// problem).
    class HarmonicEigenproblem : public SpeedEigenproblem
    {
    public:
      HarmonicEigenproblem(HarmonicProblem &problem, const unsigned int k)
        : problem(problem)
        , k(k)
      {}
      EigenSolution
      solve(const StaticState &state) override
      {
        ++problem.root_solves;
        return problem.solve_harmonic(k, state);
      }
      bool
      solve_trial(const StaticState &, EigenSolution &) override
      {
        return false;
      }

    private:
      HarmonicProblem   &problem;
      const unsigned int k;
    };

    /// The modes of every harmonic at @p state, tracked; crossings and
    /// onsets since the previous speed root-solved and written.
    std::vector<HarmonicMode>
    solve_modes(const StaticState &state, std::vector<MeridianOutput::Shape> *shapes);

    /// Mode @p index of harmonic @p k on every DoF of the meridian (the axis
    /// relations included).
    MeridianOutput::Shape
    shape(const unsigned int k, const unsigned int index, const ComplexVector &phi) const;

    /// The ParaView files of crossing @p c (harmonic @p k) at its speed, on
    /// @p state's law, with the root solve's @p solution.
    void
    write_critical_files(const unsigned int   k,
                         const CriticalSpeed &c,
                         const StaticState   &state,
                         const EigenSolution &solution);

    /// The elastic modes of harmonic @p k (index into the list) at
    /// @p state.rpm on @p state's law: lowest first, at most Modes per
    /// harmonic; a degenerate pair turned into its two travelling waves.
    EigenSolution
    solve_harmonic(const unsigned int k, const StaticState &state);

    /// Rigid motions harmonic @p n can have at @p state: 2 per group of
    /// bodies tied by closed pairs (n = 0), 4 per group no bearing holds
    /// (n = 1), none for n >= 2 (an upper bound: the eigensolver asks for
    /// these on top of the modes wanted).
    unsigned int
    rigid_motions(const unsigned int n, const StaticState &state) const;

    /// At rest on isotropic supports every mode of n >= 1 is a doublet, but
    /// a single-vector Arnoldi run may return one member only (a double
    /// eigenvalue converges once): each mode of @p modes without its partner
    /// gets it, the mode turned by 90/n degrees, checked by its backward
    /// error on harmonic @p k's matrices. Returns the number added.
    unsigned int
    add_missing_partners(const unsigned int k, std::vector<EigenPair> &modes) const;

    MPI_Comm             comm;
    Log                 &log;
    dealii::TimerOutput &timer;
    MeridianModel        meridian;
    HarmonicWaves        waves{meridian};
    std::unique_ptr<HarmonicAssembler> assembler;
    const Bearings      *bearings   = nullptr;
    const ContactInterfaces *interfaces = nullptr;
    dealii::IndexSet     owned;
    /// the bearings' stations, then the unbalances' and the probes'
    std::vector<Station> stations;
    UnbalanceResponse   *response = nullptr;

    // settings
    std::vector<unsigned int> harmonics;
    unsigned int              modes_per_harmonic = 6;
    bool                      compute_modes      = true;
    bool                      spin_softening     = false;
    bool                      prestress = true, centrifugal_prestress = true, convective = true;
    double                    tie_scale       = 1000;
    double                    rigid_threshold = 1;
    ModeTracker               tracker_template; ///< as parsed, before any speed

    // statics
    HarmonicAssembler::StaticSystem system;
    ContactSolver                   contact;
    std::unique_ptr<FitHistory>     history; ///< made by start(): it needs the pairs
    std::unique_ptr<FitAssessment>  assessment; ///< made by start(): it needs the pairs
    std::unique_ptr<MeridianOutput> paraview; ///< made by start()
    ParaViewFiles                   files_now;  ///< of the speed being solved
    MeshRefinement                 *indicators = nullptr;
    std::vector<unsigned int>       bearing_bodies; ///< bodies a bearing acts on
    unsigned int                    n_critical_files = 0;
    StaticState                     state;

    // dynamics
    std::unique_ptr<HarmonicOperators> operators; ///< made by start() (with modes)
    std::unique_ptr<HarmonicResponse>  harmonic_response; ///< made by start() (modes, unbalances)
    /// the harmonics' matrices (none without modes)
    const std::vector<HarmonicAssembler::Harmonic> &
    harmonic_matrices() const
    {
      static const std::vector<HarmonicAssembler::Harmonic> none;
      return operators ? operators->harmonics() : none;
    }
    std::vector<std::size_t> previous_law; ///< per harmonic: the law of its previous solve
    /// the reduced model of each harmonic (Eigenproblem/Reduced model)
    ReducedBasis                                       reduced_settings;
    std::vector<std::unique_ptr<HarmonicReducedModel>> reduced;
    unsigned int reduced_solves = 0, anchors = 0, refusals = 0, transient_solves = 0;
    double       reduced_seconds = 0, anchor_seconds = 0;
    double       sweep_worst_estimate = 0; ///< of the sweep's speeds (root solves left out)
    DampedEigensolver                        eigensolver; ///< the settings
    std::vector<std::unique_ptr<DampedEigensolver>> solvers; ///< per harmonic
    // the lines: a tracker and onset finder per harmonic; (harmonic, its
    // tracker's id) -> the line's number over all harmonics
    std::vector<ModeTracker>                      trackers;
    std::vector<std::unique_ptr<StabilityOnsets>> onsets;
    std::map<std::pair<unsigned int, unsigned int>, unsigned int> line_ids;
    unsigned int n_critical = 0, n_unsolved = 0, root_solves = 0;
    DampedEigensolver::Statistics            statistics;
    unsigned int                             n_unconverged = 0, n_modes_written = 0;
    unsigned int eigen_solves = 0, unconverged_slots = 0, restarts = 0;
    double       factor_seconds = 0, arnoldi_seconds = 0, check_seconds = 0, matrix_seconds = 0;
    double                                   worst_backward_error = 0;

    // tables
    ContactTable          contact_table;
    PairOpeningTable      opening_table;
    ContactEventTable     event_table;
    FitTable              fit_table;
    BodyStressTable       body_stress_table;
    HarmonicCampbellTable campbell_table;
    CriticalSpeedTable    critical_table;
    RigidModeTable        rigid_table;
    StabilityOnsetTable   onset_table;
    ResponseTable         response_table;

  };
} // namespace rotorfit
