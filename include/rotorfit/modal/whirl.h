#pragma once

#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/model/discretization.h>

#include <complex>
#include <string>
#include <vector>

namespace rotorfit
{
  /// An elastic whirl mode at one speed, as the Campbell diagram sees it.
  struct WhirlMode : EigenPair
  {
    std::string  whirl;           ///< forward, backward, mixed, non-lateral
    double       whirl_ratio = 0; ///< -1 (backward) .. +1 (forward)
    unsigned int tracked_id  = 0; ///< set by ModeTracker::track

    WhirlMode() = default;
    explicit WhirlMode(EigenPair &&pair)
      : EigenPair(std::move(pair))
    {}

    double
    frequency_hz() const
    {
      return lambda.imag() / (2 * M_PI);
    }
  };

  /**
   * Forward and backward whirl from the orbits of axial slices
   * (doc/theory.md 9.2): each station is the mass-weighted average of the
   * lateral displacement (x, y) of one slice, X = sum w_i phi_x(i). An orbit
   * x + i y = a_f e^{i beta t} + conj(a_b) e^{-i beta t} whirls forward when
   * |a_f| > |a_b|, and |a_f|^2 - |a_b|^2 = -Im(conj(X) Y); the whirl ratio
   * is its sum over the stations divided by that of |a_f|^2 + |a_b|^2.
   */
  class WhirlStations
  {
  public:
    /// One DoF pair (x, y) of a slice with its weight; per slice sum w = 1.
    struct Entry
    {
      dealii::types::global_dof_index x, y;
      double                          weight;
    };

    WhirlStations() = default;

    /// Stations given directly (one list of entries per slice).
    explicit WhirlStations(std::vector<std::vector<Entry>> stations)
      : stations(std::move(stations))
    {}

    /// @p n_slices equal axial slices of the mesh, mass-weighted.
    void
    build(const Discretization &model, const unsigned int n_slices);

    /// Set whirl and whirl_ratio: forward / backward above |ratio| 0.1,
    /// mixed between, non-lateral when no slice moves laterally.
    void
    classify(WhirlMode &mode) const;

    /// Equal-frequency pairs (at rest, say) come as arbitrary mixtures of
    /// forward and backward: rotate each such pair into circular orbits.
    void
    separate_degenerate_pairs(std::vector<WhirlMode> &modes) const;

  private:
    void
    station_values(const ComplexVector               &phi,
                   std::vector<std::complex<double>> &X,
                   std::vector<std::complex<double>> &Y) const;

    std::vector<std::vector<Entry>> stations;
  };
} // namespace rotorfit
