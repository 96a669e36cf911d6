#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/bearing/bearings.h>
#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/eigen/reduced_estimates.h>
#include <rotorfit/eigen/reduced_model.h>
#include <rotorfit/eigen/speed_tangent.h>
#include <rotorfit/eigen/tie_update.h>
#include <rotorfit/model/discretization.h>
#include <rotorfit/statics/static_state.h>

#include <deal.II/base/timer.h>

#include <chrono>
#include <string>
#include <vector>

namespace rotorfit
{
  /**
   * The anchors of the reduced model (doc/theory.md 8.6, 8.7): the vectors
   * a new basis is built from. An undamped anchor takes the lowest modes of
   * K_t phi = omega^2 M phi (block Lanczos on an LDL^T of S = K_t + sigma^2 M,
   * or on the last one with a low-rank update of the ties that changed)
   * with each mode's directions; a damped anchor takes the converged
   * eigenvectors of a full solve. Each anchor also records the radius about
   * the shift inside which its solve found every eigenvalue.
   */
  class UndampedAnchor
  {
  public:
    /// Anchors of @p reduced, with the factorisations of @p eigensolver.
    UndampedAnchor(const Discretization &model,
                   ReducedModel         &reduced,
                   ReducedEstimates     &estimates,
                   TieUpdate            &ties,
                   SpeedTangent         &operators,
                   DampedEigensolver    &eigensolver,
                   const Bearings       &bearings,
                   Log                  &log,
                   dealii::TimerOutput  &timer);

    /// A new anchor from the undamped modes of @p state with the ties
    /// @p tied and their directions, for @p nev eigenvalues of which
    /// @p n_wanted elastic ones; false (and @p why) where Lanczos fell short
    /// or the tie update failed. A @p lasting anchor (a contact state
    /// expected to hold over several speeds) also gets the directions other
    /// speeds need. With @p on_update the anchor solves on the last LDL^T of
    /// S with a low-rank update for the ties that changed since, without a
    /// factorisation of its own.
    bool
    make(const StaticState       &state,
         const std::vector<bool> &tied,
         const unsigned int       nev,
         const unsigned int       n_wanted,
         const bool               lasting,
         std::string             &why,
         const bool               on_update);

    /// A full solve's converged eigenvectors @p pairs at @p rpm into the
    /// basis (a damped anchor).
    void
    add_damped(const double rpm, const std::vector<EigenPair> &pairs, const bool lasting);

  private:
    using Clock = std::chrono::steady_clock;

    /// Each of @p parts' first-order change with the speed, solved with the
    /// latest factorisation (Q(sigma) or S) into the basis: S^-1 G x,
    /// S^-1 K_t2 x (where stress stiffening moves with the speed) and, with
    /// @p bearing_damping, S^-1 C_b x.
    void
    add_directions(const std::vector<const dealii::Vector<double> *> &parts,
                   const bool                                         bearing_damping,
                   const bool                                         gyroscopic = true);
    /// The low-rank update of the last LDL^T for the ties of @p state;
    /// false (and @p why) where it failed.
    bool
    update_ties(const StaticState       &state,
                const std::vector<bool> &tied,
                const Clock::time_point  t0,
                std::size_t             &springs,
                double                  &seconds,
                std::string             &why);
    /// The undamped modes and the record of the factorisation they were
    /// solved on.
    std::vector<DampedEigensolver::UndampedMode>
    solve_modes(const StaticState             &state,
                const std::vector<bool>       &tied,
                const unsigned int             n_modes,
                const bool                     on_update,
                const double                   update_seconds,
                DampedEigensolver::Statistics &stats);
    /// The @p found converged modes and their directions into the basis.
    void
    add_modes(const std::vector<DampedEigensolver::UndampedMode> &modes,
              const std::size_t                                   found,
              const bool                                          lasting,
              const bool                                          on_update);
    /// S^-1 C phi and S^-1 M S^-1 C phi of each mode with this speed's C
    /// (the first only where not @p lasting).
    void
    add_damping_terms(const std::vector<const dealii::Vector<double> *> &parts,
                      const bool                                         lasting);
    void
    log_anchor(const DampedEigensolver::Statistics &stats,
               const std::size_t                    found,
               const double                         top_mu,
               const double                         residual,
               const bool                           on_update,
               const std::size_t                    springs,
               const Clock::time_point              t0) const;

    const Discretization &model;
    ReducedModel         &reduced;
    ReducedEstimates     &estimates;
    TieUpdate            &ties;
    SpeedTangent         &operators;
    DampedEigensolver    &eigensolver;
    const Bearings       &bearings;
    Log                  &log;
    dealii::TimerOutput  &timer;

    /// An anchor's directions are made for this many modes at a time: the
    /// products, their back-substitutions and MUMPS's copies for a whole
    /// anchor (78 columns on TS's benchmark mesh) were a run's memory peak.
    static constexpr std::size_t modes_per_block = 8;
  };
} // namespace rotorfit
