#include <rotorfit/eigen/rotor_matrices.h>
#include <rotorfit/linear_algebra/skew_part.h>
#include <rotorfit/linear_algebra/matrix_pattern.h>
#include <rotorfit/material/elasticity.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>

#include <deal.II/fe/fe_values.h>

#include <deal.II/lac/full_matrix.h>

namespace rotorfit
{
  using namespace dealii;

  void
  RotorMatrices::reinit(const IndexSet               &owned,
                        const DynamicSparsityPattern &sparsity,
                        const MPI_Comm                comm,
                        const DynamicSparsityPattern *component)
  {
    stiffness.reinit(owned, owned, sparsity, comm);
    if (component != nullptr)
      mass.reinit(owned, owned, *component, comm);
    else
      reinit_like(mass);
    for (auto *m : {&gyroscopic, &convective})
      reinit_like_mass(*m);
  }

  void
  RotorMatrices::reinit_like(PETScWrappers::MPI::SparseMatrix &m) const
  {
    reinit_with_pattern_of(m, stiffness);
  }

  void
  RotorMatrices::reinit_like_mass(PETScWrappers::MPI::SparseMatrix &m) const
  {
    reinit_with_pattern_of(m, mass);
  }

  void
  RotorMatrices::assemble(const DoFHandler<3> &dof_handler,
                          const Mapping<3>    &mapping,
                          const Quadrature<3> &quadrature,
                          const Bodies        &bodies)
  {
    const auto &fe = dof_handler.get_fe();
    // the same rule as the static solve: the cancellation of K_sigma and
    // Omega^2 K_theta on rigid tilt needs consistent integration (doc/theory.md 0)
    FEValues<3>            fe_values(mapping,
                          fe,
                          quadrature,
                          update_values | update_gradients |
                            update_quadrature_points | update_JxW_values);
    const unsigned int n = fe.n_dofs_per_cell();
    FullMatrix<double> cell_m(n, n), cell_k(n, n), cell_g(n, n), cell_t(n, n);
    std::vector<types::global_dof_index> dofs(n);
    std::vector<unsigned int>            comp(n);
    for (unsigned int i = 0; i < n; ++i)
      comp[i] = fe.system_to_component_index(i).first;
    std::vector<SymmetricTensor<2, 3>> eps(n);
    std::vector<double>                value(n), d_theta(n);

    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          fe_values.reinit(cell);
          cell->get_dof_indices(dofs);
          const Body  &body   = bodies[cell->material_id()];
          const double lambda = body.lambda(), mu = body.mu(), rho = body.density;
          cell_m = 0;
          cell_k = 0;
          cell_g = 0;
          cell_t = 0;
          for (unsigned int q = 0; q < quadrature.size(); ++q)
            {
              const double       JxW = fe_values.JxW(q);
              const Point<3>    &x   = fe_values.quadrature_point(q);
              const Tensor<1, 3> t({-x[1], x[0], 0.}); // e_z x x
              add_elastic_stiffness(fe_values, q, lambda, mu, cell_k, eps);
              for (unsigned int i = 0; i < n; ++i)
                {
                  value[i]   = fe_values.shape_value(i, q);
                  d_theta[i] = fe_values.shape_grad(i, q) * t;
                }
              for (unsigned int i = 0; i < n; ++i)
                for (unsigned int j = 0; j < n; ++j)
                  {
                    if (comp[i] != comp[j])
                      continue;
                    cell_m(i, j) += rho * value[i] * value[j] * JxW;
                    cell_g(i, j) += 2 * rho * value[i] * d_theta[j] * JxW;
                    cell_t(i, j) += rho * d_theta[i] * d_theta[j] * JxW;
                  }
            }
          // cell by cell: the faceted boundary leaves a symmetric part
          keep_skew_part(cell_g);
          mass.add(dofs, cell_m);
          stiffness.add(dofs, cell_k);
          gyroscopic.add(dofs, cell_g);
          convective.add(dofs, cell_t);
        }
    for (auto *m : {&mass, &stiffness, &gyroscopic, &convective})
      m->compress(VectorOperation::add);
  }

  void
  RotorMatrices::assemble_stress_stiffness(const DoFHandler<3>              &dof_handler,
                                           const Mapping<3>                 &mapping,
                                           const Quadrature<3>              &quadrature,
                                           const Bodies                     &bodies,
                                           const PETScWrappers::MPI::Vector &u,
                                           PETScWrappers::MPI::SparseMatrix &k_sigma) const
  {
    assemble_stress_stiffness(dof_handler, mapping, quadrature, bodies, {&u}, {&k_sigma});
  }

  namespace
  {
    /// A vector element's shape functions by their scalar functions:
    /// K_sigma couples a component only with itself, through the same
    /// scalar block sigma grad N_a . grad N_b, so the block is computed once
    /// per scalar pair (a ninth of the work) and copied to the components.
    struct ScalarFunctions
    {
      explicit ScalarFunctions(const FiniteElement<3> &fe)
        : comp(fe.n_dofs_per_cell())
        , base(fe.n_dofs_per_cell())
      {
        const unsigned int n = fe.n_dofs_per_cell();
        for (unsigned int i = 0; i < n; ++i)
          {
            comp[i]  = fe.system_to_component_index(i).first;
            base[i]  = fe.system_to_component_index(i).second;
            n_scalar = std::max(n_scalar, base[i] + 1);
          }
        scalar_dof.resize(n_scalar);
        for (unsigned int i = 0; i < n; ++i)
          if (comp[i] == 0)
            scalar_dof[base[i]] = i;
      }

      /// component and scalar function of each shape function
      std::vector<unsigned int> comp, base;
      unsigned int              n_scalar = 0;
      /// one vector DoF per scalar function
      std::vector<unsigned int> scalar_dof;
    };

    /// The scalar block of K_sigma on the current cell from the strain of
    /// the static displacement at its quadrature points, less K_theta's
    /// where @p minus_convective (@p block zeroed first; @p grad and
    /// @p d_theta: work arrays of one entry per scalar function).
    void
    stress_block(const FEValues<3>                         &fe_values,
                 const Body                                &body,
                 const std::vector<SymmetricTensor<2, 3>> &strain,
                 const bool                                 minus_convective,
                 const ScalarFunctions                     &scalar,
                 std::vector<Tensor<1, 3>>                 &grad,
                 std::vector<double>                       &d_theta,
                 FullMatrix<double>                        &block)
    {
      const unsigned int n_scalar = scalar.n_scalar;
      block                       = 0;
      for (unsigned int q = 0; q < strain.size(); ++q)
        {
          // pre-stress at the quadrature point (no projection, doc/theory.md 3)
          const SymmetricTensor<2, 3> sigma =
            body.lambda() * trace(strain[q]) * unit_symmetric_tensor<3>() + 2 * body.mu() * strain[q];
          const double JxW = fe_values.JxW(q);
          for (unsigned int a = 0; a < n_scalar; ++a)
            grad[a] = fe_values.shape_grad(scalar.scalar_dof[a], q);
          for (unsigned int a = 0; a < n_scalar; ++a)
            {
              const Tensor<1, 3> s_grad = sigma * grad[a];
              for (unsigned int b = 0; b < n_scalar; ++b)
                block(a, b) += (s_grad * grad[b]) * JxW;
            }
          if (minus_convective)
            {
              // - K_theta: rho (d_theta N_a)(d_theta N_b), d_theta = (e_z x x) . grad
              const Point<3>    &x = fe_values.quadrature_point(q);
              const Tensor<1, 3> t({-x[1], x[0], 0.});
              for (unsigned int a = 0; a < n_scalar; ++a)
                d_theta[a] = grad[a] * t;
              for (unsigned int a = 0; a < n_scalar; ++a)
                for (unsigned int b = 0; b < n_scalar; ++b)
                  block(a, b) -= body.density * d_theta[a] * d_theta[b] * JxW;
            }
        }
    }
  } // namespace

  void
  RotorMatrices::assemble_stress_stiffness(
    const DoFHandler<3>                                   &dof_handler,
    const Mapping<3>                                      &mapping,
    const Quadrature<3>                                   &quadrature,
    const Bodies                                          &bodies,
    const std::vector<const PETScWrappers::MPI::Vector *> &u,
    const std::vector<PETScWrappers::MPI::SparseMatrix *> &k_sigma,
    const std::vector<const PETScWrappers::MPI::Vector *> &minus,
    const std::vector<bool>                               &minus_convective) const
  {
    AssertThrow(u.size() == k_sigma.size(), ExcInternalError());
    // a matrix of this pattern is zeroed, not made again (TS: 0.57 of the
    // 1.3 s of an assembly of both parts went into making them)
    for (auto *k : k_sigma)
      if (k->m() == mass.m() && k->n_nonzero_elements() > 0)
        *k = 0;
      else
        reinit_like_mass(*k);
    const auto            &fe = dof_handler.get_fe();
    FEValues<3>            fe_values(mapping,
                          fe,
                          quadrature,
                          update_gradients | update_JxW_values | update_quadrature_points);
    const FEValuesExtractors::Vector disp(0);
    const unsigned int               n = fe.n_dofs_per_cell();
    const ScalarFunctions            scalar(fe);
    FullMatrix<double>                   cell_s(n, n), block(scalar.n_scalar, scalar.n_scalar);
    std::vector<types::global_dof_index> dofs(n);
    std::vector<SymmetricTensor<2, 3>>   strain(quadrature.size()), strain_minus(quadrature.size());
    std::vector<Tensor<1, 3>>            grad(scalar.n_scalar);
    std::vector<double>                  d_theta(scalar.n_scalar);

    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          fe_values.reinit(cell);
          cell->get_dof_indices(dofs);
          const Body &body = bodies[cell->material_id()];
          for (std::size_t k = 0; k < u.size(); ++k)
            {
              fe_values[disp].get_function_symmetric_gradients(*u[k], strain);
              if (k < minus.size() && minus[k] != nullptr)
                {
                  fe_values[disp].get_function_symmetric_gradients(*minus[k], strain_minus);
                  for (unsigned int q = 0; q < quadrature.size(); ++q)
                    strain[q] -= strain_minus[q];
                }
              stress_block(fe_values, body, strain,
                           k < minus_convective.size() && minus_convective[k], scalar, grad,
                           d_theta, block);
              for (unsigned int i = 0; i < n; ++i)
                for (unsigned int j = 0; j < n; ++j)
                  cell_s(i, j) =
                    scalar.comp[i] == scalar.comp[j] ? block(scalar.base[i], scalar.base[j]) : 0.;
              k_sigma[k]->add(dofs, cell_s);
            }
        }
    for (auto *k : k_sigma)
      k->compress(VectorOperation::add);
  }
} // namespace rotorfit
