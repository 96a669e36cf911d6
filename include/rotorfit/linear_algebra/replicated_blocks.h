#pragma once

#include <rotorfit/linear_algebra/direct_solver.h>
#include <rotorfit/linear_algebra/replicated_vectors.h>
#include <rotorfit/linear_algebra/row_block.h>

#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/vector.h>

#include <complex>
#include <cstddef>
#include <vector>

// Products, back-substitutions and Gram matrices of blocks of replicated
// columns: every rank holds whole vectors, the matrices and the
// factorisations are distributed. The single vectors' operations come with
// replicated_vectors.h.

namespace rotorfit
{
  /// Pointers to the vectors of @p x (a block's argument list).
  inline std::vector<const dealii::Vector<double> *>
  pointers(const std::vector<dealii::Vector<double>> &x)
  {
    std::vector<const dealii::Vector<double> *> p;
    for (const auto &z : x)
      p.push_back(&z);
    return p;
  }

  /// Y = A X for @p m replicated columns, column-major n x m arrays (one
  /// pass over A for several columns).
  void
  replicated_mmult(const dealii::PETScWrappers::MPI::SparseMatrix &A,
                   const double                                   *x,
                   unsigned int                                    m,
                   double                                         *y);

  /// y_j = A x_j for a block of replicated vectors.
  void
  replicated_mmult(const dealii::PETScWrappers::MPI::SparseMatrix    &A,
                   const std::vector<const dealii::Vector<double> *> &x,
                   std::vector<dealii::Vector<double>>               &y);

  /// X = A^{-1} B for @p m replicated columns, column-major n x m arrays.
  void
  replicated_solve(const DirectSolver                             &solver,
                   const dealii::PETScWrappers::MPI::SparseMatrix &layout,
                   const double                                   *b,
                   unsigned int                                    m,
                   double                                         *x);

  /// x_j = A^{-1} b_j for a block of replicated vectors (one pass over the factors).
  void
  replicated_solve(const DirectSolver                                &solver,
                   const dealii::PETScWrappers::MPI::SparseMatrix    &layout,
                   const std::vector<const dealii::Vector<double> *> &b,
                   std::vector<dealii::Vector<double>>               &x);

  /// A block of replicated_inverse_gram() known without back-substitution:
  /// A^-1 P_target = base + factor A^-1 P_source (source before target).
  struct GramShortcut
  {
    std::size_t                source, target; ///< block indices, source < target
    const std::vector<double> *base;           ///< n x m_target, column-major
    double                     factor;
  };

  /// G = P^T A^-1 P (column-major, the same on every rank) for
  /// the replicated columns of the blocks P = [P_1 .. P_b] (each n x m_k,
  /// dense or by its nonzero rows; the target of @p shortcut dense), A
  /// factorised by @p solver (LDL^T or LU): the inner
  /// products of the columns with A^-1, so that |(P x)^H A^-1 (P x)| =
  /// |x^H G x| needs no back-substitution (inverse_norm_sqr). With
  /// @p shortcut its target block's columns are not back-substituted.
  std::vector<double>
  replicated_inverse_gram(const DirectSolver                             &solver,
                          const dealii::PETScWrappers::MPI::SparseMatrix &layout,
                          const std::vector<const RowBlock *>            &blocks,
                          const GramShortcut                             *shortcut = nullptr);

  /// G = P^T P (column-major, rank 0's on every rank) for the blocks
  /// P = [P_1 .. P_b] of replicated columns (each n x m_k):
  /// |P x|^2 = x^H G x without the n-long vector P x.
  std::vector<double>
  replicated_gram(const std::vector<const RowBlock *> &blocks, MPI_Comm comm);

  /// |x^H G x| for the real G of replicated_inverse_gram().
  double
  inverse_norm_sqr(const std::vector<double> &G, const std::vector<std::complex<double>> &x);
} // namespace rotorfit
