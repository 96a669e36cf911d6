#pragma once

#include <rotorfit/contact/contact_pairs.h>
#include <rotorfit/contact/contact_state.h>

#include <functional>
#include <set>
#include <vector>

namespace rotorfit
{
  /**
   * The active-set iteration of one speed (doc/theory.md 7): from the
   * current law, the pairs that open (tensile pressure and force) or close
   * (penetration) give the next set, whose law is made and evaluated again,
   * until the set settles. An iteration cap and a cycling guard (pairs that
   * flipped back are held, then changed one at a time) end it otherwise.
   */
  class ActiveSetIteration
  {
  public:
    /// Makes the current law the law of an active set at w.
    using Decompose = std::function<void(const std::vector<bool> &active, const double w)>;

    /// @p pairs (kept referenced); @p max_iterations: "Maximum active set
    /// iterations"; @p on_exact_path: the failure message names the speed.
    void
    initialize(const ContactPairs &pairs, const unsigned int max_iterations,
               const bool on_exact_path);

    /**
     * Settle @p current at @p w: whenever the set changes, @p decompose
     * replaces @p current (the same object) by the new set's law. The
     * iterations, the pairs that flipped back and a failure are added to
     * @p state, and its forces, gaps and pressures are those of the law.
     */
    void
    settle(const double w, ContactState &state, const ContactDecomposition &current,
           const Decompose &decompose) const;

  private:
    /// The pairs closed according to @p state (opening and closing rules).
    std::vector<bool>
    next_active_set(const std::vector<bool> &active, const ContactState &state) const;

    /// The set to try after @p active when @p next is wanted: @p next without
    /// the pairs that flipped back (@p flips), or one pair at a time; false
    /// when every way on leads to a set in @p seen.
    bool
    guard_cycling(const std::vector<bool>           &active,
                  const std::vector<bool>           &next,
                  const ContactState                &state,
                  const std::vector<unsigned int>   &flips,
                  const std::set<std::vector<bool>> &seen,
                  std::vector<bool>                 &proposal) const;

    /// Add the failure to settle after @p iterations at @p w to @p state.
    void
    report_unsettled(const double w, const unsigned int iterations, ContactState &state) const;

    const ContactPairs *pairs          = nullptr;
    unsigned int        max_iterations = 30;
    bool                exact          = false;
  };
} // namespace rotorfit
