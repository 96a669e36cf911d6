#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/eigen/eigen_solution.h>
#include <rotorfit/eigen/mode_classifier.h>
#include <rotorfit/eigen/speed_tangent.h>
#include <rotorfit/eigen/undamped_anchor.h>
#include <rotorfit/model/discretization.h>
#include <rotorfit/statics/static_state.h>

#include <deal.II/base/timer.h>

#include <vector>

namespace rotorfit
{
  /**
   * The damped eigenproblem of a speed solved in full (doc/theory.md 5):
   * shift-invert Arnoldi on the LU of Q(sigma), the eigenpairs sorted into
   * elastic modes and what is set apart. A speed whose modes do not all
   * converge is solved once more on the same factorisation with twice the
   * Krylov space (and room for the modes that were missing); then the run
   * stops (SolverFailure): a Campbell diagram with a missing line is wrong.
   */
  class FullSolve
  {
  public:
    /// Full solves of @p operators with @p eigensolver.
    FullSolve(const Discretization   &model,
              SpeedTangent           &operators,
              DampedEigensolver      &eigensolver,
              const ModeClassifier   &classifier,
              Log                    &log,
              dealii::TimerOutput    &timer);

    /// The modes of @p state for @p nev eigenvalues into @p solution;
    /// where @p anchor is given, its converged eigenvectors become an anchor
    /// of the reduced model (@p lasting: with the directions). Returns the
    /// largest backward error.
    double
    solve(const StaticState       &state,
          const std::vector<bool> &loose_body,
          unsigned int             nev,
          UndampedAnchor          *anchor,
          const bool               lasting,
          EigenSolution           &solution);

    unsigned int solves = 0;         ///< speeds solved in full
    unsigned int retried_speeds = 0; ///< speeds solved a second time (eigen retry)

  private:
    /// What did not converge, for the retry's log line and the failure.
    std::string
    describe_failure(const StaticState                   &state,
                     const EigenSolution                 &solution,
                     const DampedEigensolver::Statistics &stats,
                     const unsigned int                   unconverged,
                     const double                         worst) const;
    void
    log_speed(const EigenSolution                 &solution,
              const DampedEigensolver::Statistics &stats,
              const double                         worst) const;

    const Discretization &model;
    SpeedTangent         &operators;
    DampedEigensolver    &eigensolver;
    const ModeClassifier &classifier;
    Log                  &log;
    dealii::TimerOutput  &timer;
  };
} // namespace rotorfit
