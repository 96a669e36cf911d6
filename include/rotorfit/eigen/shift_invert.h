#pragma once

#include <rotorfit/linear_algebra/direct_solver.h>
#include <rotorfit/linear_algebra/replicated_vectors.h>

#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/vector.h>

#include <cstddef>

// The operators deal.II's ArpackSolver applies, on vectors replicated on
// every rank (ARPACK's own vectors) with distributed products and solves.

namespace rotorfit
{
  /// B = diag(I, M) on state vectors (x1, x2) of length 2 n: the inner
  /// product of the first companion form.
  class StateMass
  {
  public:
    /// @p n: the size of M (half the state's).
    StateMass(const dealii::PETScWrappers::MPI::SparseMatrix &M, const std::size_t n);

    /// y = B x
    void
    vmult(dealii::Vector<double> &y, const dealii::Vector<double> &x) const;

  private:
    const dealii::PETScWrappers::MPI::SparseMatrix &M;
    std::size_t                                     n;
    mutable DistributedWork                         work;
  };

  /// (A - sigma B)^{-1} r of the first companion form (doc/theory.md 8.2):
  /// y1 = -Q^{-1} [r2 + (C + sigma M) r1], y2 = r1 + sigma y1, with Q(sigma)
  /// factorised by @p Q_inverse.
  class CompanionShiftInvert
  {
  public:
    /// Every application is counted in @p applications.
    CompanionShiftInvert(const dealii::PETScWrappers::MPI::SparseMatrix &M,
                         const dealii::PETScWrappers::MPI::SparseMatrix &C,
                         const DirectSolver                             &Q_inverse,
                         const double                                    sigma,
                         const std::size_t                               n,
                         unsigned int                                   &applications);

    /// y = (A - sigma B)^{-1} r
    void
    vmult(dealii::Vector<double> &y, const dealii::Vector<double> &r) const;

    /// Time spent in the back-substitutions [s].
    mutable double solve_seconds = 0;

  private:
    const dealii::PETScWrappers::MPI::SparseMatrix &M, &C;
    const DirectSolver                             &Q_inverse;
    double                                          sigma;
    std::size_t                                     n;
    mutable DistributedWork                         work;
    unsigned int                                   &applications;
  };

  /// y = M x: the inner product of the undamped problem K phi = mu M phi.
  class ReplicatedMass
  {
  public:
    explicit ReplicatedMass(const dealii::PETScWrappers::MPI::SparseMatrix &M);

    /// y = M x
    void
    vmult(dealii::Vector<double> &y, const dealii::Vector<double> &x) const;

  private:
    const dealii::PETScWrappers::MPI::SparseMatrix &M;
    mutable DistributedWork                         work;
  };

  /// y = S^-1 x with S factorised by @p S_inverse (@p layout: a matrix with
  /// S's row distribution): the shift-invert of the undamped problem.
  class ReplicatedInverse
  {
  public:
    /// Every application is counted in @p applications.
    ReplicatedInverse(const DirectSolver                             &S_inverse,
                      const dealii::PETScWrappers::MPI::SparseMatrix &layout,
                      unsigned int                                   &applications);

    /// y = S^-1 x
    void
    vmult(dealii::Vector<double> &y, const dealii::Vector<double> &x) const;

    /// Time spent in the back-substitutions [s].
    mutable double solve_seconds = 0;

  private:
    const DirectSolver     &S_inverse;
    mutable DistributedWork work;
    unsigned int           &applications;
  };
} // namespace rotorfit
