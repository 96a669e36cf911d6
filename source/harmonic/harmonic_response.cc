#include <rotorfit/base/format.h>
#include <rotorfit/harmonic/harmonic_response.h>
#include <rotorfit/statics/speed_schedule.h>

#include <deal.II/lac/sparse_direct.h>

#include <cmath>
#include <limits>
#include <utility>

namespace rotorfit
{
  using namespace dealii;

  HarmonicResponse::HarmonicResponse(HarmonicOperators       &operators,
                                     const std::size_t        n_bearings,
                                     UnbalanceResponse       &response,
                                     Log                     &log)
    : operators(operators)
    , n_bearings(n_bearings)
    , response(response)
    , log(log)
  {}

  std::vector<std::complex<double>>
  HarmonicResponse::unbalance_load(const unsigned int hk) const
  {
    // F of every unbalance at Omega = 1: F_x = m e e^{i phi} a, F_y = -i F_x
    // (doc/theory.md 13) on the station's weights; stations after the bearings
    const auto                       &h    = operators.harmonic(hk);
    const auto                       &list = response.unbalance_list();
    std::vector<std::complex<double>> f(h.free.n_free);
    for (unsigned int j = 0; j < list.size(); ++j)
      {
        const std::complex<double> fx = list[j].force_x(), fy = std::complex<double>(0, -1) * fx;
        for (const auto &[I, w] : h.station_x[n_bearings + j])
          f[I] += w * fx;
        for (const auto &[I, w] : h.station_y[n_bearings + j])
          f[I] += w * fy;
      }
    return f;
  }

  ResponseAtSpeed
  HarmonicResponse::solve(const unsigned int    hk,
                          const StaticState    &s,
                          HarmonicReducedModel *reduced,
                          DampedEigensolver    &solver)
  {
    const auto  &h     = operators.harmonic(hk);
    const double omega = SpeedSchedule::rpm_to_rad_per_s(s.rpm);
    const unsigned int n = h.free.n_free;
    ResponseAtSpeed    out;
    out.rpm        = s.rpm;
    out.fit_state  = s.fit_state;
    out.basis_size = n; // (solved directly: the harmonic's DoFs)
    const auto  &list  = response.unbalance_list();
    Vector<std::complex<double>> f(n), u(n), r(n);
    {
      const auto f1 = unbalance_load(hk);
      for (unsigned int i = 0; i < n; ++i)
        f[i] = f1[i] * (omega * omega);
    }
    // the probes: the weighted means of the stations after the unbalances'
    const auto read_probes = [&](const auto &U) {
      const auto &probes = response.probe_list();
      for (unsigned int j = 0; j < probes.size(); ++j)
        {
          ProbeResponse p;
          p.probe        = probes[j].name;
          const auto idx = n_bearings + list.size() + j;
          for (const auto &[I, w] : h.station_x[idx])
            p.x += w * U[I];
          for (const auto &[I, w] : h.station_y[idx])
            p.y += w * U[I];
          out.probes.push_back(p);
        }
    };
    // on harmonic 1's reduced basis where it serves this law (doc/theory.md 14.6)
    if (reduced && s.decomposition().affine && reduced->serves(operators.law_matrices(hk, s)))
      {
        HarmonicReducedModel::Speed speed;
        speed.rpm       = s.rpm;
        speed.couplings = operators.bearing_couplings(hk, s.rpm);
        std::vector<std::complex<double>> F(f.begin(), f.end()), U;
        if (reduced->respond(operators.law_operators(hk), speed, F, response.residual_tolerance(),
                                 response.maximum_enrichments(), solver.linear_solver(), U,
                                 out.residual, out.basis_size))
          {
            out.converged = true;
            response.count_reduced_speed();
            read_probes(U);
            return out;
          }
        log << "  response at " << format_number(s.rpm) << " r/min: residual " << out.residual
            << " on the reduced basis (" << out.basis_size << " columns), solved directly\n";
        out.basis_size = n;
      }
    // Z = K_t - Omega^2 M + i Omega C, complex on the harmonic's pattern (K,
    // M, C share it, so entry by entry): half the unknowns of the real 2 x 2
    // block form, and UMFPACK's complex LU is about 3 x faster on it
    SparseMatrix<double> k(h.pattern), c(h.pattern);
    operators.speed_matrices(hk, s, k, c);
    SparseMatrix<std::complex<double>> z(h.pattern);
    double                             z_norm2 = 0; // (Frobenius)
    auto im = h.M.begin();
    auto ic = std::as_const(c).begin();
    auto iz = z.begin();
    for (auto ik = std::as_const(k).begin(); ik != k.end(); ++ik, ++im, ++ic, ++iz)
      {
        const std::complex<double> v(ik->value() - omega * omega * im->value(),
                                     omega * ic->value());
        iz->value() = v;
        z_norm2 += std::norm(v);
      }
    const double f_norm         = f.l2_norm();
    double       backward_error = 0;
    if (f_norm > 0)
      {
        try
          {
            SparseDirectUMFPACK solver;
            solver.factorize(z);
            u = f;
            solver.solve(u);
            z.residual(r, u, f);
            out.residual = r.l2_norm() / f_norm;
            // one step of iterative refinement where the LU left more than
            // the tolerance (a stiff rotor on soft bearings: 1e-8 .. 1e-7)
            if (!(out.residual <= response.residual_tolerance()))
              {
                solver.solve(r);
                u += r;
                z.residual(r, u, f);
                out.residual = r.l2_norm() / f_norm;
              }
            // a direct solve is judged by its normwise backward error
            // ||r|| / (||Z|| ||U|| + ||F||): ||r|| / ||F|| cannot go below
            // round-off times ||Z|| ||U|| / ||F|| (6e-8 on the stiff rigid
            // rotor of the tests, whose backward error is 1e-17)
            backward_error = r.l2_norm() / (std::sqrt(z_norm2) * u.l2_norm() + f_norm);
          }
        catch (const std::exception &e)
          {
            // (UMFPACK throws on a singular matrix: the row is flagged)
            out.residual   = std::numeric_limits<double>::infinity();
            backward_error = std::numeric_limits<double>::infinity();
            u              = 0;
          }
      }
    out.converged = out.residual <= response.residual_tolerance() || backward_error <= 1e-12;
    if (!(backward_error <= worst_error))
      worst_error = backward_error;
    read_probes(u);
    return out;
  }
} // namespace rotorfit
