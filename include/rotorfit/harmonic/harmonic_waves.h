#pragma once

#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/harmonic/harmonic_assembler.h>
#include <rotorfit/harmonic/meridian_model.h>

#include <complex>
#include <vector>

namespace rotorfit
{
  /**
   * A harmonic's modes as waves around the axis (doc/theory.md 14.5): with
   * the cos and sin coefficients (C, S) of u_r, u_t, u_z on every node, a
   * wave travelling forward (with the spin) has S = -i C. The forward share
   * of a mode, a degenerate pair split into its backward and forward
   * travelling waves, a mode turned by 90/n degrees (the partner of a
   * doublet), a mode on every DoF of the meridian.
   */
  class HarmonicWaves
  {
  public:
    explicit HarmonicWaves(const MeridianModel &meridian)
      : meridian(meridian)
    {}

    /// Mode @p phi of harmonic @p h (free numbering) on every DoF of the
    /// meridian, the axis relations included.
    std::vector<std::complex<double>>
    expand(const HarmonicAssembler::Harmonic &h, const ComplexVector &phi) const;

    /// Mode @p phi of harmonic @p h turned by 90/n degrees about the axis.
    ComplexVector
    turned(const HarmonicAssembler::Harmonic &h, const ComplexVector &phi) const;

    /// Forward share of an eigenvector of harmonic @p h.
    double
    forward_fraction(const HarmonicAssembler::Harmonic &h, const ComplexVector &phi) const;

    /// Turn the degenerate pair @p a, @p b (one eigenvalue) into the
    /// backward (in @p a) and the forward (in @p b) travelling wave.
    void
    split(const HarmonicAssembler::Harmonic &h, EigenPair &a, EigenPair &b) const;

  private:
    /// Per node and component the complex amplitudes of the forward
    /// (C + i S) and backward (C - i S) waves of an eigenvector of @p h.
    void
    wave_amplitudes(const HarmonicAssembler::Harmonic &h, const ComplexVector &phi,
                    std::vector<std::complex<double>> &forward,
                    std::vector<std::complex<double>> &backward) const;

    const MeridianModel &meridian;
  };
} // namespace rotorfit
