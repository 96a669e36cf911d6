#pragma once

#include <rotorfit/eigen/eigen_solution.h>
#include <rotorfit/statics/static_state.h>

namespace rotorfit
{
  /**
   * What a root solve along a Campbell line (critical speed, stability
   * onset; doc/theory.md 9.5, 9.7) needs of an eigenproblem: its modes at a
   * trial speed on the contact law of a given static state. The 3D model's
   * PrestressedEigenproblem and each harmonic of the axisymmetric model
   * serve it, so the root solves are one code for both models.
   */
  class SpeedEigenproblem
  {
  public:
    virtual ~SpeedEigenproblem() = default;

    /// The checked modes at @p state.rpm on @p state's law (SolverFailure
    /// if the eigensolver fails).
    virtual EigenSolution
    solve(const StaticState &state) = 0;

    /// An unchecked, cheaper trial to locate a root (false: none available,
    /// nothing solved); what is reported comes from solve().
    virtual bool
    solve_trial(const StaticState &state, EigenSolution &solution) = 0;
  };
} // namespace rotorfit
