#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/eigen/eigen_solution.h>
#include <rotorfit/eigen/speed_eigenproblem.h>
#include <rotorfit/modal/mode_tracker.h>
#include <rotorfit/modal/whirl.h>
#include <rotorfit/model/discretization.h>
#include <rotorfit/base/summary.h>
#include <rotorfit/statics/static_state.h>

#include <deal.II/base/parameter_handler.h>

#include <functional>

#include <vector>

namespace rotorfit
{
  /// The modes of one speed, classified and tracked.
  struct ModalResult
  {
    double                     rpm   = 0;
    unsigned int               index = 0; ///< position in the speed list
    std::vector<WhirlMode>     modes;     ///< elastic, lowest first
    std::vector<RigidMode>     rigid;
    std::vector<CriticalSpeed> crossings; ///< since the previous speed
    std::vector<bool>          tied;      ///< pairs the eigenproblem tied
    bool isotropic_supports = true; ///< kxx = kyy, kxy = -kyx (and damping alike)
  };

  /**
   * What an engineer reads off the eigenpairs of a speed: the whirl
   * direction of each mode (degenerate pairs at rest rotated into circular
   * orbits first), the line of the Campbell diagram it continues and the
   * crossings of the lines with the excitation orders.
   *
   * Parameters: "Whirl stations", "MAC threshold", "Excitation orders" of
   * subsection "Eigenproblem".
   */
  class ModalAnalysis
  {
  public:
    explicit ModalAnalysis(Log &log)
      : log(log)
    {}

    static void
    declare_parameters(dealii::ParameterHandler &prm);

    void
    parse_parameters(dealii::ParameterHandler &prm);

    /// The whirl stations on the mesh.
    void
    setup(const Discretization &model);

    /// Classify and track the elastic modes of @p solution (moved from).
    const ModalResult &
    analyse(EigenSolution &&solution);

    /// The crossings of the last analyse() solved for their speed: a root
    /// of f - k rpm / 60 of the line, by solve_line_root on @p state's law
    /// (the eigenproblem's matrices are those of the last trial afterwards).
    /// @p solved gets crossing i's checked eigen solve at its speed as soon
    /// as it is found (empty if the root solve had none there), to write and
    /// let go: one crossing's mode vectors are held at a time (TS: two
    /// crossings kept for the end of the step were its memory peak). What
    /// it solves itself (an empty one) runs before the next crossing's root
    /// solve, which starts from the same contact law and basis either way.
    void
    solve_crossings(const StaticState                                         &state,
                    SpeedEigenproblem                             &eigen,
                    const std::function<void(unsigned int, EigenSolution &&)> &solved = {});

    /// The modes of a solution off the sweep (a critical speed): whirl
    /// classified, not tracked, no crossings.
    ModalResult
    classify(EigenSolution &&solution) const;

    /// The result of the last analyse().
    const ModalResult &
    last_result() const
    {
      return result;
    }

    /// Log and add the number of critical speeds to @p summary.
    void
    finish(Summary &summary) const;

  private:
    /// At rest on isotropic bearings: every lateral mode below the highest
    /// has its doublet partner, or the run fails (SolverFailure).
    void
    check_doublets() const;
    Log                      &log;
    unsigned int              n_stations = 10;
    WhirlStations             stations;
    ModeTracker               tracker;
    ModalResult               result;
    unsigned int              n_critical = 0, n_unsolved = 0;
    /// largest error estimate of a reduced mode at a speed of the sweep (the
    /// root solves' checked solves apart: at a crossing two lines may lie
    /// within each other's damping, where the estimate holds the pair's
    /// condition, doc/theory.md 8.6)
    double sweep_worst_estimate = 0;
    bool                      linear_elements = false; ///< Element order 1: locking may split doublets
  };
} // namespace rotorfit
