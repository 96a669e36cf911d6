#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/eigen/rotor_matrices.h>
#include <rotorfit/eigen/speed_tangent.h>
#include <rotorfit/model/discretization.h>
#include <rotorfit/statics/static_state.h>

#include <deal.II/lac/vector.h>

#include <string>
#include <utility>
#include <vector>

namespace rotorfit
{
  /**
   * The virial checks of K_sigma on rigid tilt and twist and the tilt
   * cancellation with Omega^2 K_theta (doc/theory.md 10e), at the first
   * speed > 0; values for the log and summary.txt.
   *
   * Parameter: "Self-check" of subsection "Eigenproblem".
   */
  class StressSelfCheck
  {
  public:
    /// Checks of @p model, their values also into @p log.
    StressSelfCheck(const Discretization &model, Log &log);

    /// w^T K_theta w of the tilt and twist fields, taken from @p matrices
    /// before K_theta is folded away.
    void
    record_convective(const RotorMatrices &matrices);

    /// Whether the checks are still to be made.
    bool
    pending() const
    {
      return values.empty();
    }

    /// The checks at @p state (full stress stiffening of an affine state
    /// only).
    void
    check(const StaticState &state, const SpeedTangent &operators);

    /// (summary key, value) of the checks made.
    const std::vector<std::pair<std::string, double>> &
    results() const
    {
      return values;
    }

  private:
    /// the fields on the support points: tilt e_x x x, twist e_z x x, and y
    /// in the x component
    std::vector<dealii::Vector<double>>
    fields() const;

    const Discretization &model;
    Log                  &log;
    double                theta_tilt = 0, theta_twist = 0;
    std::vector<std::pair<std::string, double>> values;
  };
} // namespace rotorfit
