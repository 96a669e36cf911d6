#pragma once

#include <deal.II/lac/petsc_compatibility.h>
#include <deal.II/lac/petsc_sparse_matrix.h>

namespace rotorfit
{
  /// @p m: a zero matrix with the pattern (and layout) of @p prototype.
  /// PETSc copies the index arrays (MatDuplicate); deal.II's reinit from a
  /// DynamicSparsityPattern walks the pattern entry by entry, about 0.3 s
  /// per matrix on TS's benchmark mesh, where a run makes a dozen of them.
  inline void
  reinit_with_pattern_of(dealii::PETScWrappers::MPI::SparseMatrix       &m,
                         const dealii::PETScWrappers::MPI::SparseMatrix &prototype)
  {
    m.reinit(prototype);
    // what deal.II sets on a matrix made from a pattern (MatDuplicate
    // need not carry the options)
    Mat a = m;
    dealii::PETScWrappers::close_matrix(a);
    dealii::PETScWrappers::set_keep_zero_rows(a);
  }

  /// Y += a X for an assembled X whose pattern is a subset of Y's (same row
  /// layout): one merge of the sorted rows, as fast as MatAXPY on one
  /// pattern (PETSc's SUBSET_NONZERO_PATTERN path sets the values row by
  /// row, about ten times slower). Throws std::logic_error where an entry of
  /// X has no place in Y (a fault of the caller's patterns; Y is then left
  /// partly summed).
  void
  add_subset(Mat Y, const double a, Mat X);
} // namespace rotorfit
