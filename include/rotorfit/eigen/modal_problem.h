#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/bearing/bearings.h>
#include <rotorfit/eigen/campbell.h>
#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/eigen/rotor_matrices.h>
#include <rotorfit/statics/static_problem.h>

#include <deal.II/base/parameter_handler.h>

#include <deal.II/lac/petsc_sparse_matrix.h>

#include <string>
#include <vector>

namespace rotorfit
{
  /**
   * The pre-stressed damped eigenproblem at every speed of the sweep (THEORY
   * 3-5, 7.4, 8, 9), on top of the static state of StaticProblem:
   *
   *   M q'' + (C_b + Omega G) q' + (K + K_sigma - Omega^2 K_theta + K_c + K_b) q = 0
   *
   * in the stationary frame, with the contact of the eigenproblem chosen per
   * run (bonded, frictionless, fixed, frozen) and the stress stiffening from
   * the static displacement. Rigid-body and loose-body modes are listed in
   * rigid_modes.csv; elastic modes are classified (forward / backward whirl
   * from the orbits of cross-section averages), tracked by MAC and written to
   * campbell.csv; crossings with the excitation orders go to
   * critical_speeds.csv; campbell.png is drawn at the end.
   *
   * Parameters: subsection "Eigenproblem", "Bearings" and "Bearing <name>".
   */
  class ModalProblem
  {
  public:
    enum class ContactModel
    {
      bonded,
      frictionless,
      fixed,
      frozen
    };
    enum class StressStiffening
    {
      off,
      interference,
      full
    };

    ModalProblem(StaticProblem &statics, Log &log);

    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// After StaticProblem::parse_parameters() (output directory, spin softening).
    void
    parse_parameters(dealii::ParameterHandler &prm,
                     const std::string        &prm_directory);

    bool
    enabled() const
    {
      return compute;
    }

    const Bearings &
    bearing_list() const
    {
      return bearings;
    }

    /// Vectors of length 2 n the eigensolver may hold at once (Krylov space
    /// of a retry and the eigenvectors), for the memory estimate.
    double
    state_vectors_needed(const double n_dofs) const
    {
      return std::min<double>(2 * n_dofs, eigensolver.krylov_size(max_nev, 2)) + max_nev + 1;
    }

    /// Bearing faces, sparsity, whirl stations (after StaticProblem::setup()).
    void
    setup();

    /// Eigen solve at one speed of the sweep (the static callback).
    void
    solve_speed(const unsigned int          step,
                const double                rpm,
                const ContactSolver::State &state);

    /// Log a summary and draw campbell.png (also after a failed speed).
    void
    finish();

  private:
    struct Classified
    {
      std::vector<WhirlMode> elastic;
      unsigned int           rigid = 0, loose = 0, overdamped = 0;
    };

    void
    assemble_constant_matrices();
    void
    matrix_checks(const double rpm);
    void
    assemble_tangent(const double rpm, const std::vector<bool> &tied);
    unsigned int
    expected_zero_modes(const std::vector<bool> &tied,
                        std::vector<bool>       &loose_body) const;
    void
    station_values(const ComplexVector        &phi,
                   std::vector<std::complex<double>> &X,
                   std::vector<std::complex<double>> &Y) const;
    void
    classify_whirl(WhirlMode &mode) const;
    void
    separate_degenerate_pairs(std::vector<WhirlMode> &modes) const;
    void
    write_modes(const unsigned int step, const double rpm,
                const std::vector<WhirlMode> &modes, const std::vector<bool> &tied);

    StaticProblem &statics;
    Log           &log;
    MPI_Comm       comm;
    bool           root = false;

    // parameters
    bool                      compute       = true;
    unsigned int              n_modes       = 12;
    ContactModel              contact_model = ContactModel::bonded;
    double                    contact_scale = 1000;
    StressStiffening          stiffening    = StressStiffening::full;
    double                    rigid_threshold_hz = 1;
    unsigned int              n_stations    = 10;
    double                    mac_threshold = 0.8;
    std::vector<unsigned int> orders{1};
    bool                      write_shapes  = true;
    bool                      plot          = true;
    bool                      self_check    = false;
    bool                      convective_term = true;
    std::vector<std::pair<std::string, double>> checks;

    Bearings          bearings;
    DampedEigensolver eigensolver;
    dealii::DynamicSparsityPattern sparsity;
    RotorMatrices     matrices;
    Campbell          campbell;

    dealii::PETScWrappers::MPI::SparseMatrix bearing_k, bearing_c, k_sigma_I,
      k_sigma_C, tangent, damping, shifted;
    unsigned int k_sigma_serial = 0;

    std::vector<unsigned int> body_of_dof;
    /// whirl stations: per slice (x DoF, y DoF, weight) with sum weight = 1
    struct StationEntry
    {
      dealii::types::global_dof_index x, y;
      double                          weight;
    };
    std::vector<std::vector<StationEntry>> stations;
    std::vector<bool>                       frozen_active;
    std::vector<std::pair<double, std::string>> pvd_records;
    unsigned int speeds_done = 0;
    unsigned int retried_speeds = 0; ///< speeds solved a second time (eigen retry)
    unsigned int max_nev     = 0; ///< eigenvalues asked at the most tied state
    double       worst_backward_error = 0;
    bool         announced_loose      = false;
  };
} // namespace rotorfit
