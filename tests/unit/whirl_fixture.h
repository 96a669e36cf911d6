#pragma once

// Hand-made whirl stations and mode shapes for the whirl and tracking tests.
// Node k has the DoFs x = 3k, y = 3k + 1, z = 3k + 2. Station s holds nodes
// 2s (weight 0.25) and 2s + 1 (weight 0.75), so a station whose two nodes
// move alike has the nodes' motion as its X, Y. Nodes 2 n_stations and up
// belong to no station.

#include <rotorfit/modal/whirl.h>

#include <cmath>
#include <complex>
#include <vector>

namespace rotorfit_unit
{
  using cplx = std::complex<double>;

  constexpr unsigned int n_stations = 3, n_nodes = 2 * n_stations + 2;
  constexpr double       station_weight[2] = {0.25, 0.75};

  inline rotorfit::WhirlStations
  stations()
  {
    std::vector<std::vector<rotorfit::WhirlStations::Entry>> s(n_stations);
    for (unsigned int k = 0; k < n_stations; ++k)
      for (unsigned int j = 0; j < 2; ++j)
        {
          const unsigned int node = 2 * k + j;
          s[k].push_back({3 * node, 3 * node + 1, station_weight[j]});
        }
    return rotorfit::WhirlStations(s);
  }

  inline rotorfit::ComplexVector
  zero_vector()
  {
    return {dealii::Vector<double>(3 * n_nodes), dealii::Vector<double>(3 * n_nodes)};
  }

  inline void
  set(rotorfit::ComplexVector &phi, const unsigned int dof, const cplx value)
  {
    phi.re[dof] = value.real();
    phi.im[dof] = value.imag();
  }

  inline cplx
  get(const rotorfit::ComplexVector &phi, const unsigned int dof)
  {
    return {phi.re[dof], phi.im[dof]};
  }

  /// Both nodes of station k move with (X[k], Y[k]); z of node i is Z[i].
  inline rotorfit::ComplexVector
  orbits(const std::vector<cplx> &X, const std::vector<cplx> &Y, const std::vector<cplx> &Z = {})
  {
    rotorfit::ComplexVector phi = zero_vector();
    for (unsigned int k = 0; k < n_stations; ++k)
      for (unsigned int j = 0; j < 2; ++j)
        {
          set(phi, 3 * (2 * k + j), X[k]);
          set(phi, 3 * (2 * k + j) + 1, Y[k]);
        }
    for (unsigned int i = 0; i < Z.size(); ++i)
      set(phi, 3 * i + 2, Z[i]);
    return phi;
  }

  /// A mode with M = I (m_phi = phi), unit norm, eigenvalue @p lambda.
  inline rotorfit::WhirlMode
  mode(rotorfit::ComplexVector phi, const cplx lambda = {-1., 2 * M_PI * 100.})
  {
    const double s = std::sqrt(phi.re.norm_sqr() + phi.im.norm_sqr());
    phi.re /= s;
    phi.im /= s;
    rotorfit::WhirlMode m;
    m.lambda = lambda;
    m.phi    = phi;
    m.m_phi  = phi;
    return m;
  }

  /// Station amplitudes of the mode shapes (a bending-like profile).
  inline std::vector<cplx>
  profile()
  {
    return {1.0, std::polar(0.55, 0.4), cplx(0, -0.8)};
  }

  /// Forward (sense = +1: X = s, Y = -i s) or backward (sense = -1) circular orbits.
  inline rotorfit::ComplexVector
  circular(const int sense, const std::vector<cplx> &s = profile(), const std::vector<cplx> &Z = {})
  {
    std::vector<cplx> Y(s.size());
    for (unsigned int k = 0; k < s.size(); ++k)
      Y[k] = cplx(0, -sense) * s[k];
    return orbits(s, Y, Z);
  }

  /// a^H b with M = I.
  inline cplx
  dot(const rotorfit::ComplexVector &a, const rotorfit::ComplexVector &b)
  {
    return {a.re * b.re + a.im * b.im, a.re * b.im - a.im * b.re};
  }

  /// |a^H b|^2 / (|a|^2 |b|^2), written out here (not ModeTracker::mac).
  inline double
  parallel(const rotorfit::ComplexVector &a, const rotorfit::ComplexVector &b)
  {
    return std::norm(dot(a, b)) / (dot(a, a).real() * dot(b, b).real());
  }
} // namespace rotorfit_unit
