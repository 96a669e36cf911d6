#include <rotorfit/harmonic/fourier_basis.h>
#include <rotorfit/harmonic/harmonic_waves.h>


#include <cmath>

namespace rotorfit
{
  using namespace dealii;

  std::vector<std::complex<double>>
  HarmonicWaves::expand(const HarmonicAssembler::Harmonic &h, const ComplexVector &phi) const
  {
    const auto                       &expansion = h.free.expansion;
    std::vector<std::complex<double>> value(expansion.size());
    for (unsigned int i = 0; i < expansion.size(); ++i)
      for (const auto &[I, w] : expansion[i])
        value[i] += w * std::complex<double>(phi.re[I], phi.im[I]);
    return value;
  }

  ComplexVector
  HarmonicWaves::turned(const HarmonicAssembler::Harmonic &h, const ComplexVector &phi) const
  {
    // u(theta - 90/n deg): a' = -b, b' = a, c' = d, d' = -c, e' = -f, f' = e
    // (u_r = a cos + b sin, u_t = c cos - d sin, u_z = e cos + f sin)
    const unsigned int source[FourierBasis::n_fields] = {FourierBasis::b, FourierBasis::c,
                                                          FourierBasis::f, FourierBasis::a,
                                                          FourierBasis::d, FourierBasis::e};
    const double       sign[FourierBasis::n_fields]   = {-1, -1, -1, 1, 1, 1};
    const auto    value = expand(h, phi); // the axis relations included
    ComplexVector out;
    out.re.reinit(h.free.n_free);
    out.im.reinit(h.free.n_free);
    for (unsigned int I = 0; I < h.free.n_free; ++I)
      {
        const auto  dof  = h.free.dof[I];
        const auto &node = meridian.nodes()[meridian.node_of(dof)];
        for (unsigned int k = 0; k < FourierBasis::n_fields; ++k)
          if (node[k] == dof)
            {
              const std::complex<double> v = sign[k] * value[node[source[k]]];
              out.re[I]                    = v.real();
              out.im[I]                    = v.imag();
            }
      }
    return out;
  }

  void
  HarmonicWaves::wave_amplitudes(const HarmonicAssembler::Harmonic &h,
                                   const ComplexVector               &phi,
                                   std::vector<std::complex<double>> &forward,
                                   std::vector<std::complex<double>> &backward) const
  {
    // per node the cos and sin coefficients (C, S) of u_r, u_t, u_z; a wave
    // travelling forward has S = -i C: C + i S is its amplitude, C - i S
    // the backward wave's
    std::vector<std::complex<double>> value(meridian.dofs().n_dofs());
    for (unsigned int I = 0; I < h.free.n_free; ++I)
      value[h.free.dof[I]] = {phi.re[I], phi.im[I]};
    const auto at = [&](const types::global_dof_index dof) { return value[dof]; };
    const std::complex<double> i(0., 1.);
    forward.clear();
    backward.clear();
    for (const auto &node : meridian.nodes())
      {
        const std::complex<double> C[3] = {at(node[FourierBasis::a]), at(node[FourierBasis::c]),
                                           at(node[FourierBasis::e])};
        const std::complex<double> S[3] = {at(node[FourierBasis::b]), -at(node[FourierBasis::d]),
                                           at(node[FourierBasis::f])};
        for (unsigned int k = 0; k < 3; ++k)
          {
            forward.push_back(C[k] + i * S[k]);
            backward.push_back(C[k] - i * S[k]);
          }
      }
  }

  void
  HarmonicWaves::split(const HarmonicAssembler::Harmonic &h,
                                    EigenPair                         &a,
                                    EigenPair                         &b) const
  {
    // x^H F x / x^H T x over x in span(a, b), F the forward share, T the
    // whole: its two stationary points (det(F - mu T) = 0) are the waves
    std::vector<std::complex<double>> fa, ba, fb, bb;
    wave_amplitudes(h, a.phi, fa, ba);
    wave_amplitudes(h, b.phi, fb, bb);
    const auto dot = [](const std::vector<std::complex<double>> &x,
                        const std::vector<std::complex<double>> &y) {
      std::complex<double> sum = 0;
      for (unsigned int k = 0; k < x.size(); ++k)
        sum += std::conj(x[k]) * y[k];
      return sum;
    };
    const double               F11 = dot(fa, fa).real(), F22 = dot(fb, fb).real();
    const std::complex<double> F12 = dot(fa, fb);
    const double               T11 = F11 + dot(ba, ba).real(), T22 = F22 + dot(bb, bb).real();
    const std::complex<double> T12 = F12 + dot(ba, bb);
    // mu^2 det T - mu (F11 T22 + F22 T11 - 2 Re(conj(F12) T12)) + det F = 0
    const double qa = T11 * T22 - std::norm(T12);
    const double qb = -(F11 * T22 + F22 * T11 - 2 * (std::conj(F12) * T12).real());
    const double qc = F11 * F22 - std::norm(F12);
    const double d  = std::sqrt(std::max(0., qb * qb - 4 * qa * qc));
    if (!(qa > 0))
      return; // (dependent vectors: left as they are)
    const auto combine = [&](const double mu) {
      // a null vector of F - mu T, from the row of larger entries
      std::complex<double> x1 = F12 - mu * T12, x2 = -(F11 - mu * T11);
      const std::complex<double> y1 = F22 - mu * T22, y2 = -std::conj(F12 - mu * T12);
      if (std::norm(y1) + std::norm(y2) > std::norm(x1) + std::norm(x2))
        x1 = y1, x2 = y2;
      EigenPair p = a;
      for (auto [out, in_a, in_b] : {std::make_tuple(&p.phi, &a.phi, &b.phi),
                                     std::make_tuple(&p.m_phi, &a.m_phi, &b.m_phi)})
        for (unsigned int k = 0; k < out->re.size(); ++k)
          {
            const std::complex<double> v = x1 * std::complex<double>(in_a->re[k], in_a->im[k]) +
                                           x2 * std::complex<double>(in_b->re[k], in_b->im[k]);
            out->re[k] = v.real();
            out->im[k] = v.imag();
          }
      const double norm = std::sqrt(p.phi.re.norm_sqr() + p.phi.im.norm_sqr());
      for (auto *v : {&p.phi.re, &p.phi.im, &p.m_phi.re, &p.m_phi.im})
        *v /= norm;
      p.backward_error = std::max(a.backward_error, b.backward_error);
      return p;
    };
    EigenPair backward = combine((-qb - d) / (2 * qa)), forward = combine((-qb + d) / (2 * qa));
    backward.lambda = a.lambda;
    forward.lambda  = b.lambda;
    a = std::move(backward);
    b = std::move(forward);
  }

  double
  HarmonicWaves::forward_fraction(const HarmonicAssembler::Harmonic &h,
                                    const ComplexVector               &phi) const
  {
    std::vector<std::complex<double>> f, b;
    wave_amplitudes(h, phi, f, b);
    double forward = 0, backward = 0;
    for (unsigned int k = 0; k < f.size(); ++k)
      {
        forward += std::norm(f[k]);
        backward += std::norm(b[k]);
      }
    return forward + backward > 0 ? forward / (forward + backward) : 0.5;
  }

} // namespace rotorfit
