#pragma once

#include <rotorfit/base/log.h>
#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/harmonic/harmonic_operators.h>
#include <rotorfit/harmonic/harmonic_reduced_model.h>
#include <rotorfit/response/unbalance_response.h>
#include <rotorfit/statics/static_state.h>

#include <complex>
#include <vector>

namespace rotorfit
{
  /**
   * The unbalance response on the axisymmetric model (doc/theory.md 13,
   * 14.6): the unbalances force harmonic 1 only, (K_t - Omega^2 M + i Omega
   * C) U = F Omega^2 on its free DoFs, solved on harmonic 1's reduced basis
   * where it serves the speed's law, else directly (UMFPACK's complex LU),
   * and read at the probes. The counterpart of the 3D model's
   * UnbalanceResponse solve; the settings, unbalances, probes and the result
   * table stay there.
   */
  class HarmonicResponse
  {
  public:
    /// @p operators' harmonics carry the stations: the @p n_bearings
    /// bearings' first, then the unbalances' and the probes' of @p response.
    HarmonicResponse(HarmonicOperators       &operators,
                     const std::size_t        n_bearings,
                     UnbalanceResponse       &response,
                     Log                     &log);

    /// The unbalances' force on harmonic @p k (harmonic 1) at Omega = 1
    /// (the speed's is Omega^2 times it), complex, free numbering.
    std::vector<std::complex<double>>
    unbalance_load(const unsigned int k) const;

    /// The response of harmonic @p k at @p state, on @p reduced's basis
    /// where it serves (its enrichments with @p solver's kept
    /// factorisation), else directly.
    ResponseAtSpeed
    solve(const unsigned int    k,
          const StaticState    &state,
          HarmonicReducedModel *reduced,
          DampedEigensolver    &solver);

    /// The largest normwise backward error of the direct solves.
    double
    worst_backward_error() const
    {
      return worst_error;
    }

  private:
    HarmonicOperators       &operators; ///< (its law matrices are made on demand)
    const std::size_t        n_bearings;
    UnbalanceResponse       &response;
    Log                     &log;
    double                   worst_error = 0;
  };
} // namespace rotorfit
