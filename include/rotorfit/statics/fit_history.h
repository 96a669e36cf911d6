#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/contact/contact_pairs.h>
#include <rotorfit/contact/contact_solver.h>
#include <rotorfit/base/summary.h>
#include <rotorfit/statics/static_state.h>

#include <vector>

namespace rotorfit
{
  /**
   * What each fit did over the speeds solved so far: per interface the
   * contact fraction and pressures of a static state, the pairs that opened
   * since the previous speed (their opening speeds from the previous active
   * set's affine law, doc/theory.md 2.3 and 9.6), the first opening and the
   * loss of fit (the speed where the total contact force of the last closed
   * set vanishes), and the worst constraint error and asymmetry.
   */
  class FitHistory
  {
  public:
    FitHistory(const ContactPairs &pairs, const ContactInterfaces &interfaces, Log &log);

    /// Fill the rows, openings and fit state of @p state (its active set's
    /// law is @p law); a row above @p error_limit marks the state unconverged.
    void
    record(StaticState &state, const ContactSolver::Decomposition &law, const double error_limit);

    /// Every interface fully open (false without interfaces).
    bool
    every_fit_open() const;

    /// The interface keys (an unopened fit's loss of fit extrapolated from
    /// the last recorded speed's law) and the count of unconverged speeds.
    void
    add_to_summary(Summary &summary) const;

    unsigned int
    n_speeds() const
    {
      return speeds;
    }

  private:
    /// Fill the row of interface @p f; returns false if its constraint
    /// error is above @p error_limit.
    bool
    evaluate_interface(const unsigned int f, StaticState &state,
                       const ContactSolver::Decomposition &law, const double error_limit);

    /// Pairs of interface @p f open at @p state that were closed at the
    /// previous speed: pair_openings.csv rows, first opening, loss of fit.
    void
    find_openings(const unsigned int f, StaticState &state, const unsigned int closed);

    /// The same from the exact path's events (exact speeds; contact_events.csv rows).
    void
    follow_events(const unsigned int f, StaticState &state);

    /// The fit of interface @p f is fully open at @p rpm (found between @p from and @p to).
    void
    mark_fully_open(const unsigned int f, const double rpm, const double from, const double to,
                    const double last_pair);

    const ContactPairs      &pairs;
    const ContactInterfaces &interfaces;
    Log                     &log;

    std::vector<double> first_open, loss_of_fit, mean_p0, max_p0, worst_error, worst_asymmetry;
    /// contact fraction falls through 0.5 (exact path: an event; sampled:
    /// linear between speeds), and the fraction at the last speed
    std::vector<double> half_open, last_fraction;
    std::vector<bool>   fully_open;
    unsigned int        speeds = 0, unconverged = 0;
    double              previous_rpm = 0;
    /// the last recorded speed's active set and affine laws
    std::vector<bool>   last_active;
    std::vector<double> last_p_I, last_p_C, last_f_I, last_f_C;
    bool                last_affine = true;
  };
} // namespace rotorfit
