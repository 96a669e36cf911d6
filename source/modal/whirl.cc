#include <rotorfit/modal/whirl.h>

#include <deal.II/base/quadrature_lib.h>

#include <deal.II/fe/fe_values.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    /// y += c x for complex c and vectors.
    void
    add_scaled(ComplexVector &y, const std::complex<double> c, const ComplexVector &x)
    {
      y.re.add(c.real(), x.re, -c.imag(), x.im);
      y.im.add(c.real(), x.im, c.imag(), x.re);
    }

    ComplexVector
    zero_like(const ComplexVector &x)
    {
      return {Vector<double>(x.re.size()), Vector<double>(x.re.size())};
    }
  } // namespace

  void
  WhirlStations::build(const Discretization &model, const unsigned int n_slices)
  {
    const auto &dof_handler = model.dofs();
    const auto &fe          = dof_handler.get_fe();
    std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
    // whirl stations: mass-averaged lateral displacement of axial slices
    double z_min = std::numeric_limits<double>::max(), z_max = -z_min;
    for (const auto &p : model.support_points())
      {
        z_min = std::min(z_min, p[2]);
        z_max = std::max(z_max, p[2]);
      }
    const Quadrature<3>    quadrature = model.mesh().cell_quadrature();
    FEValues<3>            fe_values(model.mesh().mapping(), fe, quadrature,
                          update_values | update_quadrature_points | update_JxW_values);
    std::vector<std::map<types::global_dof_index, std::pair<types::global_dof_index, double>>>
                        weights(n_slices);
    std::vector<double> slice_mass(n_slices, 0.);
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        fe_values.reinit(cell);
        cell->get_dof_indices(dofs);
        const double rho = model.bodies()[cell->material_id()].density;
        for (unsigned int q = 0; q < quadrature.size(); ++q)
          {
            const double z = fe_values.quadrature_point(q)[2];
            const unsigned int k = std::min<unsigned int>(
              n_slices - 1, (z - z_min) / (z_max - z_min) * n_slices);
            slice_mass[k] += rho * fe_values.JxW(q);
            for (unsigned int i = 0; i < dofs.size(); ++i)
              if (fe.system_to_component_index(i).first == 0)
                {
                  auto &e = weights[k][dofs[i]];
                  e.first = dofs[fe.component_to_system_index(
                    1, fe.system_to_component_index(i).second)];
                  e.second += rho * fe_values.shape_value(i, q) * fe_values.JxW(q);
                }
          }
      }
    stations.assign(n_slices, {});
    for (unsigned int k = 0; k < n_slices; ++k)
      for (const auto &[dx, e] : weights[k])
        if (slice_mass[k] > 0)
          stations[k].push_back({dx, e.first, e.second / slice_mass[k]});
  }

  void
  WhirlStations::station_values(const ComplexVector               &phi,
                               std::vector<std::complex<double>> &X,
                               std::vector<std::complex<double>> &Y) const
  {
    X.assign(stations.size(), 0.);
    Y.assign(stations.size(), 0.);
    for (unsigned int k = 0; k < stations.size(); ++k)
      for (const auto &e : stations[k])
        {
          X[k] += e.weight * std::complex<double>(phi.re[e.x], phi.im[e.x]);
          Y[k] += e.weight * std::complex<double>(phi.re[e.y], phi.im[e.y]);
        }
  }

  void
  WhirlStations::classify(WhirlMode &mode) const
  {
    // x + iy = a_f e^{i beta t} + conj(a_b) e^{-i beta t}:
    // |a_f|^2 - |a_b|^2 = -Im(conj(X) Y) (doc/theory.md 9.2)
    std::vector<std::complex<double>> X, Y;
    station_values(mode.phi, X, Y);
    double forward = 0, amplitude = 0, largest_station = 0;
    for (unsigned int k = 0; k < X.size(); ++k)
      {
        forward += -2 * std::imag(std::conj(X[k]) * Y[k]);
        amplitude += std::norm(X[k]) + std::norm(Y[k]);
        largest_station = std::max(largest_station, std::sqrt(std::norm(X[k]) + std::norm(Y[k])));
      }
    double largest_node = 0;
    for (std::size_t i = 0; i < mode.phi.re.size(); ++i)
      largest_node = std::max(largest_node, std::hypot(mode.phi.re[i], mode.phi.im[i]));
    mode.whirl_ratio = amplitude > 0 ? forward / amplitude : 0.;
    // sections that do not move laterally: axial, torsional, ND >= 2
    if (largest_station < 1e-2 * largest_node)
      mode.whirl = "non-lateral";
    else if (mode.whirl_ratio >= 0.1)
      mode.whirl = "forward";
    else if (mode.whirl_ratio <= -0.1)
      mode.whirl = "backward";
    else
      mode.whirl = "mixed";
  }

  void
  WhirlStations::separate_degenerate_pairs(std::vector<WhirlMode> &modes) const
  {
    // equal-frequency pairs (e.g. at zero speed) come as arbitrary mixes of
    // forward and backward: rotate them into circular orbits (doc/theory.md
    // 9.3) by the extremes of forward / lateral energy
    for (unsigned int a = 0; a + 1 < modes.size(); ++a)
      {
        WhirlMode &m1 = modes[a], &m2 = modes[a + 1];
        if (std::abs(m1.lambda - m2.lambda) > 1e-3 * std::abs(m1.lambda))
          continue;
        std::vector<std::complex<double>> X[2], Y[2];
        station_values(m1.phi, X[0], Y[0]);
        station_values(m2.phi, X[1], Y[1]);
        std::complex<double> A[2][2] = {}, B[2][2] = {};
        for (unsigned int k = 0; k < X[0].size(); ++k)
          for (unsigned int p = 0; p < 2; ++p)
            for (unsigned int q = 0; q < 2; ++q)
              {
                A[p][q] += std::complex<double>(0, 1) *
                           (std::conj(X[p][k]) * Y[q][k] - std::conj(Y[p][k]) * X[q][k]);
                B[p][q] += std::conj(X[p][k]) * X[q][k] + std::conj(Y[p][k]) * Y[q][k];
              }
        // det(A - mu B) = 0 (2 x 2 Hermitian pencil, B > 0)
        const double a2 = std::real(B[0][0] * B[1][1] - B[0][1] * B[1][0]);
        const double a1 = -std::real(A[0][0] * B[1][1] + A[1][1] * B[0][0] -
                                     A[0][1] * B[1][0] - A[1][0] * B[0][1]);
        const double a0   = std::real(A[0][0] * A[1][1] - A[0][1] * A[1][0]);
        const double disc = a1 * a1 - 4 * a2 * a0;
        if (!(a2 > 0) || disc < 0)
          continue;
        ComplexVector phi[2], m_phi[2];
        for (unsigned int r = 0; r < 2; ++r)
          {
            const double mu = (-a1 + (r == 0 ? 1 : -1) * std::sqrt(disc)) / (2 * a2);
            std::complex<double> c0 = -(A[0][1] - mu * B[0][1]), c1 = A[0][0] - mu * B[0][0];
            if (std::abs(c0) + std::abs(c1) < 1e-14 * (std::abs(A[0][0]) + std::abs(B[0][0])))
              {
                c0 = A[1][1] - mu * B[1][1];
                c1 = -(A[1][0] - mu * B[1][0]);
              }
            phi[r]   = zero_like(m1.phi);
            m_phi[r] = zero_like(m1.phi);
            add_scaled(phi[r], c0, m1.phi);
            add_scaled(phi[r], c1, m2.phi);
            add_scaled(m_phi[r], c0, m1.m_phi);
            add_scaled(m_phi[r], c1, m2.m_phi);
            const double s = std::sqrt(phi[r].re.norm_sqr() + phi[r].im.norm_sqr());
            for (auto *v : {&phi[r].re, &phi[r].im, &m_phi[r].re, &m_phi[r].im})
              *v /= s;
          }
        // forward (largest mu) takes the higher frequency of the two
        const bool first_higher = m1.lambda.imag() >= m2.lambda.imag();
        WhirlMode &fw = first_higher ? m1 : m2, &bw = first_higher ? m2 : m1;
        fw.phi   = phi[0];
        fw.m_phi = m_phi[0];
        bw.phi   = phi[1];
        bw.m_phi = m_phi[1];
        ++a;
      }
  }

} // namespace rotorfit
