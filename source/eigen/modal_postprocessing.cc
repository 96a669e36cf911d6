#include <rotorfit/eigen/modal_problem.h>
#include <rotorfit/statics/speed_schedule.h>

#include <deal.II/base/mpi.h>

#include <deal.II/numerics/data_out.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <iomanip>
#include <sstream>

// ModalProblem, part 2: what is done with the eigenpairs of a speed (whirl
// direction, degenerate pairs), mode-shape files, self-checks, the end of the
// run. Part 1 (parameters, matrices, the per-speed solve): modal_problem.cc.

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
  ModalProblem::station_values(const ComplexVector               &phi,
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
  ModalProblem::classify_whirl(WhirlMode &mode) const
  {
    // x + iy = a_f e^{i beta t} + conj(a_b) e^{-i beta t}:
    // |a_f|^2 - |a_b|^2 = -Im(conj(X) Y) (THEORY 9)
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
  ModalProblem::separate_degenerate_pairs(std::vector<WhirlMode> &modes) const
  {
    // equal-frequency pairs (e.g. at zero speed) come as arbitrary mixes of
    // forward and backward: rotate them into circular orbits (THEORY,
    // correction 8) by the extremes of forward / lateral energy
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

  void
  ModalProblem::write_modes(const unsigned int            step,
                            const double                  rpm,
                            const std::vector<WhirlMode> &modes,
                            const std::vector<bool>      &tied)
  {
    const auto &dof_handler = statics.dofs();
    DataOut<3>  data_out;
    data_out.attach_dof_handler(dof_handler);
    const std::vector<DataComponentInterpretation::DataComponentInterpretation>
      vector3(3, DataComponentInterpretation::component_is_part_of_vector);
    for (unsigned int m = 0; m < modes.size(); ++m)
      {
        std::ostringstream name;
        name << "mode_" << std::setw(2) << std::setfill('0') << m + 1;
        data_out.add_data_vector(modes[m].phi.re,
                                 std::vector<std::string>(3, name.str() + "_re"),
                                 DataOut<3>::type_dof_data, vector3);
        data_out.add_data_vector(modes[m].phi.im,
                                 std::vector<std::string>(3, name.str() + "_im"),
                                 DataOut<3>::type_dof_data, vector3);
      }
    Vector<double> tie(dof_handler.n_dofs());
    const auto    &list = statics.contact_pairs().pairs();
    for (unsigned int i = 0; i < list.size(); ++i)
      for (const auto &d : {list[i].shaft_dofs, list[i].hub_dofs})
        for (const auto dof : d)
          tie[dof] = tied[i] ? 1. : 0.;
    data_out.add_data_vector(tie,
                             std::vector<std::string>(3, "contact_tied"),
                             DataOut<3>::type_dof_data, vector3);
    data_out.build_patches(statics.assembly_mesh().mapping(),
                           statics.assembly_mesh().element_order());
    const std::string name =
      data_out.write_vtu_with_pvtu_record(statics.output_directory() + "/", "modes", step, comm, 4, 0);
    pvd_records.emplace_back(rpm, name);
    if (root)
      {
        std::ofstream pvd(statics.output_directory() + "/modes.pvd");
        DataOutBase::write_pvd_record(pvd, pvd_records);
      }
  }

  void
  ModalProblem::matrix_checks(const double rpm)
  {
    // THEORY 10e-3/4 on linear fields (exact in the FE space): the virial
    // identity int sigma dV = Omega^2 int rho P x (x) x dV makes
    // w^T K_sigma w equal Omega^2 int rho y^2 for the tilt w = e_x (x) x and
    // Omega^2 w^T K_theta w for the twist w = e_z x x, to round-off with
    // reaction-free supports; the tilt cancellation against Omega^2 K_theta is
    // exact only on rotationally symmetric meshes.
    const double w = std::pow(SpeedSchedule::rpm_to_rad_per_s(rpm), 2);
    const auto  &decomposition = statics.contact_solver().decomposition();
    if (!decomposition.affine || stiffening != StressStiffening::full)
      return;
    PETScWrappers::MPI::SparseMatrix k_sigma;
    matrices.reinit_like(k_sigma);
    MatCopy(k_sigma_I, k_sigma, SAME_NONZERO_PATTERN);
    MatAXPY(k_sigma, w, k_sigma_C, SAME_NONZERO_PATTERN);

    const auto &points = statics.dof_support_points();
    const auto &fe     = statics.dofs().get_fe();
    std::vector<unsigned int> component(points.size());
    {
      std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
      for (const auto &cell : statics.dofs().active_cell_iterators())
        {
          cell->get_dof_indices(dofs);
          for (unsigned int i = 0; i < dofs.size(); ++i)
            component[dofs[i]] = fe.system_to_component_index(i).first;
        }
    }
    const auto field = [&](const std::function<Tensor<1, 3>(const Point<3> &)> &f) {
      Vector<double> v(points.size());
      for (std::size_t i = 0; i < points.size(); ++i)
        v[i] = f(points[i])[component[i]];
      return v;
    };
    const auto energy = [&](const PETScWrappers::MPI::SparseMatrix &A, const Vector<double> &v) {
      Vector<double> Av;
      replicated_vmult(A, v, Av);
      return v * Av;
    };
    const Vector<double> tilt  = field([](const Point<3> &x) { return Tensor<1, 3>({0., -x[2], x[1]}); });
    const Vector<double> twist = field([](const Point<3> &x) { return Tensor<1, 3>({-x[1], x[0], 0.}); });
    const Vector<double> y_in_x = field([](const Point<3> &x) { return Tensor<1, 3>({x[1], 0., 0.}); });
    const double s_tilt = energy(k_sigma, tilt), t_tilt = energy(matrices.convective, tilt);
    const double s_twist = energy(k_sigma, twist), t_twist = energy(matrices.convective, twist);
    const double yy = energy(matrices.mass, y_in_x);
    checks.emplace_back("check.speed_rpm", rpm);
    checks.emplace_back("check.tilt_virial", s_tilt / (w * yy));
    checks.emplace_back("check.twist_virial", s_twist / (w * t_twist));
    checks.emplace_back("check.tilt_cancellation", (s_tilt - w * t_tilt) / (w * t_tilt));
    log << "  self-check at " << rpm << " r/min: w^T K_sigma w / (Omega^2 int rho y^2) = "
        << std::setprecision(12) << checks[1].second << " (tilt), "
        << checks[2].second << " (twist, against Omega^2 w^T K_theta w); tilt "
        << "cancellation error " << std::setprecision(3) << checks[3].second << '\n';
  }

  void
  ModalProblem::finish()
  {
    if (!compute || speeds_done == 0)
      return;
    if (root)
      {
        std::ofstream summary(statics.output_directory() + "/summary.txt", std::ios::app);
        summary << std::setprecision(12);
        for (const auto &[key, value] : checks)
          summary << key << ' ' << value << '\n';
        summary << "eigen.speeds " << speeds_done << '\n'
                << "eigen.critical_speeds " << campbell.n_critical_speeds() << '\n'
                << "eigen.worst_backward_error " << worst_backward_error << '\n'
                << "eigen.retried_speeds " << retried_speeds << '\n'
                << "eigen.workspace_retries "
                << eigensolver.linear_solver().n_workspace_retries() << '\n';
      }
    log << "Eigenproblem: " << speeds_done << " speeds, "
        << eigensolver.linear_solver().n_factorizations() << " factorisations of Q(sigma), "
        << campbell.n_critical_speeds() << " critical speed(s) in critical_speeds.csv, "
        << "worst backward error " << worst_backward_error << '\n';
    if (plot && root)
      {
        const std::string command = std::string(ROTORFIT_PYTHON) + " " +
                                    ROTORFIT_PLOT_SCRIPT + " '" + statics.output_directory() +
                                    "' > '" + statics.output_directory() + "/plot.log' 2>&1";
        if (std::system(command.c_str()) == 0)
          log << "Campbell diagram: " << statics.output_directory() << "/campbell.png\n";
        else
          log << "Warning: campbell.png could not be drawn (see " << statics.output_directory()
              << "/plot.log; needs python3-matplotlib); campbell.csv is complete.\n";
      }
  }
} // namespace rotorfit
