#pragma once

#include <rotorfit/linear_algebra/complex_vector.h>
#include <rotorfit/linear_algebra/direct_solver.h>

#include <deal.II/base/index_set.h>

#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/petsc_vector.h>
#include <deal.II/lac/vector.h>

#include <cstddef>

// Single vectors replicated on every rank (ARPACK's, the reduced model's)
// against distributed matrices and factorisations.

namespace rotorfit
{
  /// Copy entries [offset, offset + n) of the replicated @p x into the
  /// locally owned part of the distributed @p v.
  void
  replicated_scatter(const dealii::Vector<double>     &x,
                     const std::size_t                 offset,
                     dealii::PETScWrappers::MPI::Vector &v);

  /// Gather the distributed @p v on every rank into entries
  /// [offset, offset + n) of the replicated @p x.
  void
  replicated_gather(const dealii::PETScWrappers::MPI::Vector &v,
                    dealii::Vector<double>                   &x,
                    const std::size_t                         offset);

  /// Three work vectors in a matrix's row layout: where replicated vectors
  /// are scattered to for a distributed product or solve.
  struct DistributedWork
  {
    explicit DistributedWork(const dealii::PETScWrappers::MPI::SparseMatrix &A)
      : owned(A.locally_owned_range_indices())
      , comm(A.get_mpi_communicator())
      , a(owned, comm)
      , b(owned, comm)
      , c(owned, comm)
    {}
    dealii::IndexSet                   owned; ///< the matrix's locally owned rows
    MPI_Comm                           comm;  ///< the matrix's communicator
    dealii::PETScWrappers::MPI::Vector a, b, c; ///< free for the caller's use
  };

  /// y = A x (or A^T x) for replicated vectors (x, y of full size), A distributed.
  void
  replicated_vmult(const dealii::PETScWrappers::MPI::SparseMatrix &A,
                   const dealii::Vector<double>                   &x,
                   dealii::Vector<double>                         &y,
                   const bool                                      transpose = false);

  /// Complex y = A x (or A^T x), A real.
  void
  replicated_vmult(const dealii::PETScWrappers::MPI::SparseMatrix &A,
                   const ComplexVector                            &x,
                   ComplexVector                                  &y,
                   const bool                                      transpose = false);

  /// x = A^{-1} b for replicated vectors with @p solver's factorisation of
  /// A (@p layout: a matrix with A's row distribution).
  void
  replicated_solve(const DirectSolver                             &solver,
                   const dealii::PETScWrappers::MPI::SparseMatrix &layout,
                   const dealii::Vector<double>                   &b,
                   dealii::Vector<double>                         &x);
} // namespace rotorfit
