#pragma once

#include <rotorfit/bearing/bearings.h>
#include <rotorfit/eigen/speed_tangent.h>
#include <rotorfit/linear_algebra/direct_solver.h>
#include <rotorfit/model/discretization.h>
#include <rotorfit/statics/static_state.h>

#include <optional>
#include <vector>

namespace rotorfit
{
  /**
   * The ties of the last LDL^T of S = K_t + sigma^2 M and the tie springs
   * that changed since (doc/theory.md 8.7): where a fit opens pair by pair,
   * an undamped anchor solves on that factorisation with a low-rank
   * (Woodbury) update of the changed springs instead of a new one.
   *
   * Parameter: "Reduced anchor tie updates" (ReducedBasis::tie_update_limit).
   */
  class TieUpdate
  {
  public:
    /// The ties of @p model's pairs as @p operators makes them.
    TieUpdate(const Discretization &model, const Bearings &bearings, const SpeedTangent &operators);

    /// The LDL^T @p solver has just made (its n_factorizations()) holds
    /// the ties @p tied of @p state.
    void
    record(const DirectSolver &solver, const StaticState &state, const std::vector<bool> &tied);

    /// The tie springs that changed between the last LDL^T of S and the
    /// ties @p tied of @p state (+eps for a pair tied since, -eps for one
    /// released; one column per pair, three for bonded fits): false where
    /// @p solver holds no such factorisation or more than @p limit springs
    /// changed.
    bool
    columns(const DirectSolver                      &solver,
            const StaticState                       &state,
            const std::vector<bool>                 &tied,
            const unsigned int                       limit,
            std::vector<DirectSolver::UpdateColumn> &columns) const;

    /// The speed of the last LDL^T of S [r/min] (0 before the first).
    double
    factorized_rpm() const
    {
      return factored ? factored->rpm : 0.;
    }

    /// anchors made on a tie update, and those refused (then a new LDL^T)
    unsigned int anchors = 0, anchors_refused = 0;

  private:
    const Discretization &model;
    const Bearings       &bearings;
    const SpeedTangent   &operators;

    /// The ties of the last LDL^T of S (each pair's spring, 0 where
    /// untied), its speed and the factorisation count it was made at.
    struct FactorTies
    {
      unsigned int        factorizations = 0;
      double              rpm            = 0;
      std::vector<double> eps;
    };
    std::optional<FactorTies> factored;
  };
} // namespace rotorfit
