#pragma once

#include <deal.II/base/parameter_handler.h>

namespace rotorfit
{
  /**
   * Settings of the static contact solve: subsection "Contact" (the linear
   * solver's own entries aside, see DirectSolver).
   */
  struct ContactParameters
  {
    /// Enforcement of the contact constraints ("Method").
    enum class Method
    {
      penalty,
      augmented_lagrangian
    };

    /// How the active set follows the speed ("Speed path"): from event to
    /// event in Omega^2 (exact), or settled anew at each requested speed
    /// (sampled).
    enum class Path
    {
      exact,
      sampled
    };

    /// Declare the entries of subsection "Contact".
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Read the entries of subsection "Contact".
    void
    parse_parameters(dealii::ParameterHandler &prm);

    /// Largest constraint error max |g| / delta of the closed pairs that
    /// still counts as converged [-]: 10 x Uzawa tolerance (augmented
    /// Lagrangian), Constraint error limit (penalty).
    double
    constraint_error_limit() const
    {
      return method == Method::penalty ? penalty_error_limit : 10 * uzawa_tolerance;
    }

    Method       method                    = Method::augmented_lagrangian; ///< "Method"
    double       penalty_scale             = 10;   ///< alpha [-], "Penalty scale"
    unsigned int max_active_set_iterations = 30;   ///< "Maximum active set iterations"
    unsigned int max_uzawa_iterations      = 100;  ///< "Maximum Uzawa iterations"
    double       uzawa_tolerance           = 1e-8; ///< [-], "Uzawa tolerance"
    double       update_limit              = 0.25; ///< [-], "Low-rank update limit"
    double       penalty_error_limit       = 0.01; ///< [-], "Constraint error limit"
    Path         path                      = Path::exact; ///< "Speed path"
  };
} // namespace rotorfit
