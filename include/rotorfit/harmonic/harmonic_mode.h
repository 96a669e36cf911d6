#pragma once

#include <complex>
#include <string>

namespace rotorfit
{
  /// One mode of the harmonic model at one speed: a row of campbell.csv.
  struct HarmonicMode
  {
    unsigned int         harmonic = 0; ///< n: nodal diameters (1: whirl)
    unsigned int         index    = 0; ///< 1, 2, ... by frequency within the harmonic
    /// the line of the Campbell diagram (numbered over all harmonics)
    unsigned int         tracked_id = 0;
    std::complex<double> lambda;       ///< [rad/s], Im >= 0
    /// as in the 3D model: "forward" or "backward" for n = 1 (the lateral
    /// whirl), "non-lateral" otherwise (a station's mean lateral motion is 0)
    std::string whirl;
    /// n >= 1: the direction the wave of n nodal diameters travels about
    /// the axis ("forward": with the spin), "-" for n = 0
    std::string travel;
    double      forward_fraction = 0; ///< 1: purely forward, 0: purely backward
    double      backward_error   = 0;

    double
    frequency_hz() const
    {
      return lambda.imag() / (2 * M_PI);
    }
  };
} // namespace rotorfit
