#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/linear_algebra/replicated_vectors.h>
#include <rotorfit/eigen/stress_self_check.h>

#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>

#include <functional>
#include <iomanip>
#include <sstream>

namespace rotorfit
{
  using namespace dealii;

  StressSelfCheck::StressSelfCheck(const Discretization &model, Log &log)
    : model(model)
    , log(log)
  {}

  std::vector<Vector<double>>
  StressSelfCheck::fields() const
  {
    const auto &points = model.support_points();
    const auto &fe     = model.dofs().get_fe();
    std::vector<unsigned int> component(points.size());
    {
      std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
      for (const auto &cell : model.dofs().active_cell_iterators())
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
    const Vector<double> tilt  = field([](const Point<3> &x) { return Tensor<1, 3>({0., -x[2], x[1]}); });
    const Vector<double> twist = field([](const Point<3> &x) { return Tensor<1, 3>({-x[1], x[0], 0.}); });
    const Vector<double> y_in_x = field([](const Point<3> &x) { return Tensor<1, 3>({x[1], 0., 0.}); });
    return {tilt, twist, y_in_x};
  }

  void
  StressSelfCheck::record_convective(const RotorMatrices &matrices)
  {
    const auto f      = fields();
    const auto energy = [&](const Vector<double> &v) {
      Vector<double> Av;
      replicated_vmult(matrices.convective, v, Av);
      return v * Av;
    };
    theta_tilt  = energy(f[0]);
    theta_twist = energy(f[1]);
  }

  void
  StressSelfCheck::check(const StaticState &state, const SpeedTangent &operators)
  {
    // On linear fields (exact in the FE space) the virial identity
    // int sigma dV = Omega^2 int rho P x (x) x dV makes w^T K_sigma w equal
    // Omega^2 int rho y^2 for the tilt w = e_x (x) x and Omega^2 w^T K_theta w
    // for the twist w = e_z x x, to round-off with reaction-free supports;
    // the tilt cancellation against Omega^2 K_theta is exact only on
    // rotationally symmetric meshes (doc/theory.md 10e-3/4).
    const double w             = state.w();
    const auto  &decomposition = state.decomposition();
    if (!decomposition.affine || !operators.stiffening_moves())
      return;
    // K_sigma(u_I + w u_C) of its own (the stiffness holds it summed with K)
    PETScWrappers::MPI::SparseMatrix k_sigma;
    {
      const MPI_Comm             comm  = model.mpi_communicator();
      const auto                &owned = model.locally_owned_dofs();
      PETScWrappers::MPI::Vector u(owned, comm);
      u = decomposition.u_I;
      u.add(w, decomposition.u_C);
      PETScWrappers::MPI::Vector ghosted(owned, complete_index_set(model.dofs().n_dofs()), comm);
      ghosted = u;
      operators.speed_independent().assemble_stress_stiffness(
        model.dofs(), model.mesh().mapping(), model.mesh().cell_quadrature(), model.bodies(),
        ghosted, k_sigma);
    }

    const auto energy = [&](const PETScWrappers::MPI::SparseMatrix &A, const Vector<double> &v) {
      Vector<double> Av;
      replicated_vmult(A, v, Av);
      return v * Av;
    };
    const auto            f    = fields();
    const Vector<double> &tilt = f[0], &twist = f[1], &y_in_x = f[2];
    const double s_tilt = energy(k_sigma, tilt), t_tilt = theta_tilt;
    const double s_twist = energy(k_sigma, twist), t_twist = theta_twist;
    const double yy = energy(operators.mass(), y_in_x);
    values.emplace_back("check.speed_rpm", state.rpm);
    values.emplace_back("check.tilt_virial", s_tilt / (w * yy));
    values.emplace_back("check.twist_virial", s_twist / (w * t_twist));
    values.emplace_back("check.tilt_cancellation", (s_tilt - w * t_tilt) / (w * t_tilt));
    // formatted apart: the precisions must not stay on the log's streams
    std::ostringstream line;
    line << "  self-check at " << state.rpm << " r/min: w^T K_sigma w / (Omega^2 int rho y^2) = "
         << std::setprecision(12) << values[1].second << " (tilt), " << values[2].second
         << " (twist, against Omega^2 w^T K_theta w); tilt "
         << "cancellation error " << std::setprecision(3) << values[3].second << '\n';
    log << line.str();
  }
} // namespace rotorfit
