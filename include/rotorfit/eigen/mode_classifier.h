#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/bearing/bearings.h>
#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/eigen/eigen_solution.h>
#include <rotorfit/eigen/speed_tangent.h>
#include <rotorfit/model/discretization.h>
#include <rotorfit/statics/static_state.h>

#include <vector>

namespace rotorfit
{
  /**
   * What is set apart from the elastic whirl modes of a speed: rigid-body
   * motions, modes of loose bodies (a fit fully open) and overdamped ones
   * (doc/theory.md 5, 7.4); and how many zero eigenvalues the supports and
   * ties leave, which sizes the eigenvalues a speed asks for.
   *
   * Parameters: "Number of modes" and "Rigid-body threshold" of subsection
   * "Eigenproblem", set by PrestressedEigenproblem.
   */
  class ModeClassifier
  {
  public:
    /// The modes of @p model on its @p bearings with the contact model of
    /// @p operators and the Backward error limit of @p eigensolver.
    ModeClassifier(const Discretization           &model,
                   const Bearings                 &bearings,
                   const SpeedTangent::Settings   &operators,
                   const DampedEigensolver        &eigensolver,
                   Log                            &log);

    /// Elastic whirl modes wanted per speed.
    unsigned int n_wanted = 12;
    /// Modes with |lambda| / 2 pi below this [Hz] are rigid-body modes.
    double rigid_threshold_hz = 1;

    /// The body of every DoF (after the mesh is made).
    void
    setup();

    /// Zero eigenvalues the supports leave with the ties @p tied (rigid and
    /// loose-body motions); @p loose_body: the bodies off the main group.
    unsigned int
    expected_zero_modes(const std::vector<bool> &tied, std::vector<bool> &loose_body) const;

    /// Split eigenpairs into elastic and set apart; false if incomplete
    /// (@p unconverged pairs above the Backward error limit, the worst
    /// backward error in @p worst, or fewer elastic modes than wanted).
    bool
    sort_eigenpairs(std::vector<EigenPair>  &pairs,
                    const std::vector<bool> &loose_body,
                    EigenSolution           &solution,
                    unsigned int            &unconverged,
                    double                  &worst) const;

    /// Once per run: the note that a fit is fully open and which body is
    /// loose.
    void
    announce_loose_bodies(const StaticState &state, const std::vector<bool> &loose_body);

  private:
    const Discretization         &model;
    const Bearings               &bearings;
    const SpeedTangent::Settings &operators;
    const DampedEigensolver      &eigensolver;
    Log                          &log;

    std::vector<unsigned int> body_of_dof;
    bool                      announced_loose = false;
  };
} // namespace rotorfit
