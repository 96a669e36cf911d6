#pragma once

#include <rotorfit/material/bodies.h>

#include <deal.II/base/index_set.h>
#include <deal.II/base/quadrature.h>

#include <deal.II/dofs/dof_handler.h>

#include <deal.II/fe/mapping.h>

#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/petsc_vector.h>

namespace rotorfit
{
  /**
   * The speed-independent matrices of the stationary-frame equations of
   * motion (doc/theory.md 1, 3, 4.3), without the static supports (doc/theory.md P7): mass M,
   * elastic stiffness K, gyroscopic G (skew part only, P4) and the
   * convective stiffness K_theta, all over the rotating bodies with one
   * quadrature rule; and the stress stiffness K_sigma(u) of a static
   * displacement u (linear in u, so K_sigma(u_I + w u_C) is combined from
   * two assembled parts).
   */
  class RotorMatrices
  {
  public:
    /// K gets the pattern of @p sparsity; M, G and K_theta, which couple a
    /// displacement component only with itself, that of @p component
    /// (a third of the entries), or @p sparsity's where it is null.
    void
    reinit(const dealii::IndexSet               &owned,
           const dealii::DynamicSparsityPattern &sparsity,
           const MPI_Comm                        comm,
           const dealii::DynamicSparsityPattern *component = nullptr);

    void
    assemble(const dealii::DoFHandler<3> &dof_handler,
             const dealii::Mapping<3>    &mapping,
             const dealii::Quadrature<3> &quadrature,
             const Bodies                &bodies);

    /// K_sigma of the static displacement @p u (ghosted, all DoFs) into @p k_sigma.
    void
    assemble_stress_stiffness(const dealii::DoFHandler<3>              &dof_handler,
                              const dealii::Mapping<3>                 &mapping,
                              const dealii::Quadrature<3>              &quadrature,
                              const Bodies                             &bodies,
                              const dealii::PETScWrappers::MPI::Vector &u,
                              dealii::PETScWrappers::MPI::SparseMatrix &k_sigma) const;

    /// K_sigma of each displacement @p u[k] into @p k_sigma[k] (zeroed where
    /// it has a pattern, else given M's), in one pass
    /// over the cells (an active set's two parts, u_I and u_C); with a
    /// @p minus[k] (may be null) K_sigma(u[k] - minus[k]) (K_sigma is linear
    /// in u: the change from one static state to the next); with
    /// @p minus_convective[k] also - K_theta, as in assemble() (K_t2 of the
    /// affine law in one matrix).
    void
    assemble_stress_stiffness(const dealii::DoFHandler<3>                                  &dof_handler,
                              const dealii::Mapping<3>                                     &mapping,
                              const dealii::Quadrature<3>                                  &quadrature,
                              const Bodies                                                 &bodies,
                              const std::vector<const dealii::PETScWrappers::MPI::Vector *> &u,
                              const std::vector<dealii::PETScWrappers::MPI::SparseMatrix *> &k_sigma,
                              const std::vector<const dealii::PETScWrappers::MPI::Vector *> &minus = {},
                              const std::vector<bool> &minus_convective = {}) const;

    /// A zero matrix with K's pattern (the full one).
    void
    reinit_like(dealii::PETScWrappers::MPI::SparseMatrix &m) const;

    /// A zero matrix with M's pattern (each component with itself): enough
    /// for M, G, K_theta and K_sigma.
    void
    reinit_like_mass(dealii::PETScWrappers::MPI::SparseMatrix &m) const;

    dealii::PETScWrappers::MPI::SparseMatrix mass, stiffness, gyroscopic, convective;
  };
} // namespace rotorfit
