#pragma once

// Shared by the unit tests that build small distributed PETSc matrices from
// closed-form entries.

#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>

#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/petsc_sparse_matrix.h>

namespace rotorfit_unit
{
  /// Rows [r n / ranks, (r + 1) n / ranks) of an n-row matrix on rank r.
  inline dealii::IndexSet
  owned_rows(const unsigned int n, const MPI_Comm comm)
  {
    const unsigned int ranks = dealii::Utilities::MPI::n_mpi_processes(comm),
                       rank  = dealii::Utilities::MPI::this_mpi_process(comm);
    dealii::IndexSet owned(n);
    owned.add_range(rank * n / ranks, (rank + 1) * n / ranks);
    return owned;
  }

  /// A = (value(i, j)) on the entries where pattern(i, j) holds (n x n,
  /// the rows @p owned on this rank).
  template <typename Pattern, typename Value>
  void
  make_matrix(dealii::PETScWrappers::MPI::SparseMatrix &A, const unsigned int n,
              const dealii::IndexSet &owned, const MPI_Comm comm, const Pattern &pattern,
              const Value &value)
  {
    dealii::DynamicSparsityPattern dsp(n, n, owned);
    for (const auto i : owned)
      for (unsigned int j = 0; j < n; ++j)
        if (pattern(i, j))
          dsp.add(i, j);
    A.reinit(owned, owned, dsp, comm);
    for (const auto i : owned)
      for (unsigned int j = 0; j < n; ++j)
        if (pattern(i, j))
          A.set(i, j, value(i, j));
    A.compress(dealii::VectorOperation::insert);
  }
} // namespace rotorfit_unit
