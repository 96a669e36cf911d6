#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/contact/contact_solver.h>
#include <rotorfit/model/discretization.h>
#include <rotorfit/base/summary.h>
#include <rotorfit/fit/fit_assessment.h>
#include <rotorfit/statics/fit_history.h>
#include <rotorfit/statics/static_state.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/timer.h>

#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/petsc_vector.h>

#include <exception>
#include <memory>
#include <vector>

namespace rotorfit
{
  /**
   * The static problem of the assembly: elasticity under the interference
   * of the fits and the centrifugal load, with node-to-node frictionless
   * contact whose closed set is found anew at every speed (doc/theory.md,
   * sections 2, 6 and 7). solve() continues from the previous speed's
   * active set and returns the state the rest of the run reads.
   *
   * Parameters: subsections "Contact" (solver), "Linear solver", "Physics".
   */
  class StaticProblem
  {
  public:
    StaticProblem(const Discretization &model, Log &log, dealii::TimerOutput &timer);

    static void
    declare_parameters(dealii::ParameterHandler &prm);

    void
    parse_parameters(dealii::ParameterHandler &prm);

    bool
    spin_softening_on() const
    {
      return spin_softening;
    }

    /// Assemble K and the unit centrifugal load, set up the contact solver;
    /// @p w_max is the largest Omega^2 of the run [rad^2/s^2].
    void
    assemble(const double w_max);

    /// The contact state at @p rpm (the @p index-th speed of the run). Stops
    /// with SolverFailure on NaN or Inf.
    const StaticState &
    solve(const double rpm, const unsigned int index);

    /**
     * Exact path: follow it now through all speeds @p rpm of the run (pair
     * space; two back-substitutions per segment met at a speed), keep each
     * speed's state and free the static factorisation, so that it is not
     * held next to the eigenproblem's. solve() then hands out the kept
     * states in order (a failure on the way is thrown there, at its speed).
     * The laws kept are capped at half the factorisation's size: past the
     * cap the path goes on as the speeds come, on the factorisation.
     */
    void
    solve_ahead(const std::vector<double> &rpm);

    /// Free the factorisation (its next use factorises again): the owner
    /// of the run calls this when a larger factorisation needs the memory.
    void
    release_factorization()
    {
      contact.release_factorization();
    }

    /// How the contact state follows the speed: the exact path in Omega^2
    /// (events), or sampled at each speed.
    ContactSolver::Path
    speed_path() const
    {
      return contact.path();
    }

    /// Every fit fully open.
    bool
    every_fit_open() const
    {
      return history.every_fit_open();
    }

    /// Log the totals and add the static entries to @p summary (masses, the
    /// fits' opening speeds, solver counts).
    void
    finish(Summary &summary);

  private:
    void
    setup_system();
    void
    assemble_system();
    /// NaN or Inf in @p state (a factorisation that lost its digits).
    void
    check_finite(const StaticState &state) const;
    /// The contact solve at @p rpm, with its law (no bookkeeping).
    StaticState
    contact_state(const double rpm, const unsigned int index);

    const Discretization &model;
    Log                  &log;
    dealii::TimerOutput  &timer;
    MPI_Comm              comm;

    bool spin_softening = false;

    ContactSolver                  contact;
    FitHistory                     history;
    FitAssessment                  assessment;
    StaticState                    state;
    /// solve_ahead(): each speed's state, or the failure met there
    struct Ahead
    {
      StaticState        state;
      std::exception_ptr failure;
    };
    std::vector<Ahead>                                   ahead;

    dealii::PETScWrappers::MPI::SparseMatrix stiffness;
    dealii::PETScWrappers::MPI::SparseMatrix spin_softening_matrix;
    dealii::PETScWrappers::MPI::Vector       unit_centrifugal_load;
    dealii::Vector<double>                   stiffness_diagonal;
    std::vector<double>                      mass, polar; ///< per body [kg], [kg m^2]
    unsigned int                             uzawa_iterations = 0;
    unsigned int                             contact_events   = 0; ///< exact path, all speeds
  };
} // namespace rotorfit
