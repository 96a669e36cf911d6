#pragma once

#include <rotorfit/linear_algebra/direct_solver.h>

#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/vector.h>

#include <vector>

namespace rotorfit
{
  /// What block_lanczos() did.
  struct BlockLanczosStatistics
  {
    unsigned int iterations = 0; ///< block steps
    unsigned int operator_applications = 0; ///< columns back-substituted
    unsigned int block_solves          = 0; ///< passes over the factors
    double       solve_seconds         = 0;
    bool         converged             = false;
    std::string  failure; ///< Anasazi's exception text, if it threw
  };

  /**
   * The @p nev largest eigenvalues theta of S^-1 M (S factorised by
   * @p S_inverse, M-symmetric) by Anasazi's block Krylov-Schur method in
   * the M inner product, with @p block columns back-substituted at a time
   * (a block costs little more than one column: MUMPS reads the factors
   * once) and a space of @p n_blocks blocks. Runs on replicated vectors on
   * every rank (like ARPACK), the products and solves distributed. Returns
   * the converged pairs (at most nev, perhaps fewer), theta descending;
   * the caller checks every residual on the original pencil.
   */
  void
  block_lanczos(const dealii::PETScWrappers::MPI::SparseMatrix &M,
                const DirectSolver                             &S_inverse,
                unsigned int                                    nev,
                unsigned int                                    block,
                unsigned int                                    n_blocks,
                unsigned int                                    max_restarts,
                double                                          tolerance,
                std::vector<double>                            &theta,
                std::vector<dealii::Vector<double>>            &z,
                BlockLanczosStatistics                         &statistics);
} // namespace rotorfit
