#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/base/summary.h>
#include <rotorfit/bearing/bearings.h>
#include <rotorfit/contact/contact_solver.h>
#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/harmonic/harmonic_assembler.h>
#include <rotorfit/harmonic/harmonic_mode.h>
#include <rotorfit/harmonic/meridian_model.h>
#include <rotorfit/model/discretization.h>
#include <rotorfit/output/tables.h>
#include <rotorfit/statics/fit_history.h>
#include <rotorfit/statics/static_state.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/timer.h>

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
   * DampedEigensolver. Writes contact.csv, pair_openings.csv,
   * contact_events.csv and campbell.csv (with the harmonic of each mode),
   * and adds its keys to summary.txt.
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
    /// @p bearings; refuses what the model cannot represent.
    void
    setup(const Discretization &model, const Bearings &bearings);

    /// Assemble, open the tables in @p directory; @p w_max: the largest
    /// Omega^2 of the run.
    void
    start(const std::string &directory, const double w_max);

    /// The static state and the modes of speed @p k, @p rpm; tables written.
    const StaticState &
    solve_speed(const unsigned int k, const double rpm);

    bool
    every_fit_open() const
    {
      return history && history->every_fit_open();
    }

    void
    finish(Summary &summary) const;

  private:
    /// The modes of every harmonic at @p state.
    std::vector<HarmonicMode>
    solve_modes(const StaticState &state);

    /// Forward share of an eigenvector of harmonic @p h.
    double
    forward_fraction(const HarmonicAssembler::Harmonic &h, const ComplexVector &phi) const;

    MPI_Comm             comm;
    Log                 &log;
    dealii::TimerOutput &timer;
    MeridianModel        meridian;
    std::unique_ptr<HarmonicAssembler> assembler;
    const Bearings      *bearings   = nullptr;
    const ContactInterfaces *interfaces = nullptr;
    dealii::IndexSet     owned;
    std::vector<Station> stations;

    // settings
    std::vector<unsigned int> harmonics;
    unsigned int              modes_per_harmonic = 6;
    bool                      compute_modes      = true;
    bool                      spin_softening     = false;
    bool                      prestress = true, centrifugal_prestress = true, convective = true;
    double                    tie_scale       = 1000;
    double                    rigid_threshold = 1;

    // statics
    HarmonicAssembler::StaticSystem system;
    ContactSolver                   contact;
    std::unique_ptr<FitHistory>     history; ///< made by start(): it needs the pairs
    StaticState                     state;

    // dynamics
    std::vector<HarmonicAssembler::Harmonic> matrices;
    /// per harmonic: M, and the matrices K, C are filled into (same pattern
    /// at every speed)
    std::vector<dealii::PETScWrappers::MPI::SparseMatrix> petsc_m, petsc_c, petsc_k;
    /// K_sigma is linear in the static displacement u = u_I + w u_C: per
    /// harmonic K_sigma(u_I) and K_sigma(u_C) of the law they were made for
    std::shared_ptr<const ContactSolver::Decomposition> prestress_law;
    std::vector<std::unique_ptr<dealii::SparseMatrix<double>>> k_sigma_I, k_sigma_C;
    unsigned int                                        prestress_assemblies = 0;
    DampedEigensolver                        eigensolver;
    DampedEigensolver::Statistics            statistics;
    unsigned int                             n_unconverged = 0, n_modes_written = 0;
    unsigned int eigen_solves = 0, unconverged_slots = 0, restarts = 0;
    double       factor_seconds = 0, arnoldi_seconds = 0, check_seconds = 0;
    double                                   worst_backward_error = 0;

    // tables
    ContactTable          contact_table;
    PairOpeningTable      opening_table;
    ContactEventTable     event_table;
    HarmonicCampbellTable campbell_table;

  };
} // namespace rotorfit
