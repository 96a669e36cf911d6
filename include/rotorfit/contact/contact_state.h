#pragma once

#include <deal.II/lac/petsc_vector.h>

#include <string>
#include <vector>

namespace rotorfit
{
  /// A pair that changed state on the exact path.
  struct ContactEvent
  {
    double       w;       ///< Omega^2 at the change [rad^2/s^2]
    unsigned int pair;    ///< index into ContactPairs::pairs()
    bool         opening; ///< true: closed -> open; false: open -> closed
  };

  /**
   * The resultants of the closed pairs' normal forces per interface at a
   * change of the exact path, under the law before and after it: the total
   * normal force sum N_i [N] and its moment about the axis sum N_i r_i
   * [N m]. Between two changes both are affine in Omega^2, so what is
   * built from them (the friction capacity) is known exactly between the
   * speeds of the run.
   */
  struct ResultantKink
  {
    double              w; ///< Omega^2 of the change [rad^2/s^2]
    std::vector<double> force_before, moment_before, force_after, moment_after;
  };

  /// Result of the static contact solve at one speed.
  struct ContactState
  {
    std::vector<bool>   active; ///< closed pairs
    std::vector<double> force; ///< N_i >= 0 on closed pairs [N]
    std::vector<double> gap;   ///< g_i [m]
    std::vector<double> pressure; ///< p_i [Pa], from the surface mass matrix
    unsigned int        active_set_iterations = 0; ///< laws evaluated
    unsigned int        uzawa_iterations      = 0; ///< multiplier updates
    unsigned int        factorizations        = 0; ///< of the static matrix
    unsigned int        low_rank_updates      = 0; ///< active sets solved by Woodbury
    unsigned int        influence_columns     = 0; ///< columns computed
    unsigned int        flipped_back          = 0; ///< pairs that flipped back (cycling)
    bool                converged             = true;
    std::string         reason; ///< why not converged (empty if it is)
    /// largest ContactPairs::asymmetry() over the interfaces (set by the sweep)
    double              asymmetry = 0;
    /// exact path: the changes since the previous speed, in order of w
    std::vector<ContactEvent> events;
    /// exact path: the resultants at each change since the previous speed
    std::vector<ResultantKink> kinks;
  };

  /**
   * The law of one active set: X(w) = X_I + w X_C. Affine (spin softening
   * off): the interference and unit-centrifugal load cases, exact for all
   * w. Otherwise the tangent at w_fixed: exact there, first order around.
   */
  struct ContactDecomposition
  {
    std::vector<bool>   active; ///< the active set (closed pairs)
    std::vector<double> force_I, force_C; ///< N = force_I + w force_C [N]
    std::vector<double> gap_I, gap_C;     ///< g = gap_I + w gap_C [m]
    std::vector<double> pressure_I, pressure_C; ///< p = M_surface^-1 N [Pa]
    /// exact path: the pair loads of the two load cases on the base,
    /// u = K_base^-1 (F + B q) (empty on the sampled path)
    std::vector<double> q_I, q_C;
    /// locally owned; on the exact path made only for the laws of
    /// requested speeds (size 0 until then)
    dealii::PETScWrappers::MPI::Vector u_I, u_C;
    bool   affine  = true; ///< false: a tangent at w_fixed
    double w_fixed = 0; ///< Omega^2 of the tangent [rad^2/s^2]
    bool   valid   = false; ///< false: no law made yet
    bool   uzawa_converged = true; ///< false: a load case hit the Uzawa cap
    /// identity of the law for the callers' caches: changes with every new
    /// decomposition
    unsigned int serial = 0;

    /// Forces, gaps and pressures of @p state at @p w (the other fields of
    /// @p state are left alone).
    void
    evaluate(const double w, ContactState &state) const;

    /// u_I and u_C have been made.
    bool
    has_displacements() const
    {
      return u_I.size() > 0;
    }
  };

  /// Wall time [s] in factorisations, influence columns and the
  /// back-substitutions of the load cases.
  struct ContactTiming
  {
    double factorize = 0, columns = 0, solves = 0;
  };
} // namespace rotorfit
