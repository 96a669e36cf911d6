#pragma once

#include <rotorfit/linear_algebra/complex_vector.h>

#include <deal.II/lac/petsc_sparse_matrix.h>

#include <cmath>
#include <complex>

namespace rotorfit
{
  /// Backward error of (lambda, phi) on the quadratic problem:
  /// ||Q(lambda) phi|| / ((|lambda|^2 ||M|| + |lambda| ||C|| + ||K||) ||phi||)
  /// (Frobenius norms), the measure of every mode's convergence.
  class BackwardError
  {
  public:
    /// The error's scale from the Frobenius norms of @p M, @p C and @p K
    /// (kept referenced for the products).
    BackwardError(const dealii::PETScWrappers::MPI::SparseMatrix &M,
                  const dealii::PETScWrappers::MPI::SparseMatrix &C,
                  const dealii::PETScWrappers::MPI::SparseMatrix &K);

    /// Also returns M phi in @p Mp (for MAC and energies) and, if asked,
    /// the residual r = Q(lambda) phi and phi^H Q'(lambda) phi =
    /// phi^H (2 lambda M + C) phi (for the reduced model's error estimate).
    double
    operator()(const std::complex<double> lambda,
               const ComplexVector       &phi,
               ComplexVector             &Mp,
               ComplexVector             *residual   = nullptr,
               std::complex<double>      *derivative = nullptr) const;

    /// The same from M phi, C phi and K phi at hand (the reduced model's
    /// products).
    double
    operator()(const std::complex<double> lambda,
               const ComplexVector       &phi,
               const ComplexVector       &Mp,
               const ComplexVector       &Cp,
               const ComplexVector       &Kp,
               ComplexVector             *residual   = nullptr,
               std::complex<double>      *derivative = nullptr) const;

    /// The same from the residual r = Q(lambda) phi at hand.
    double
    from_residual(const std::complex<double> lambda,
                  const ComplexVector       &phi,
                  const ComplexVector       &residual) const;

    /// The same from |r| and |phi| (a residual's norm known without the
    /// vector: the reduced model's Gram matrix of its blocks).
    double
    from_norm(const std::complex<double> lambda, const double norm_phi, const double norm_r) const
    {
      const double s = scale(lambda) * norm_phi;
      return s > 0 ? norm_r / s : 0.;
    }

    /// max over A = M, C, K of |A phi - Ap| / |A phi| (A^T for
    /// @p transpose): how far products taken elsewhere are from these
    /// matrices' own.
    double
    mismatch(const ComplexVector &phi,
             const ComplexVector &Mp,
             const ComplexVector &Cp,
             const ComplexVector &Kp,
             const bool           transpose = false) const;

    /// |lambda|^2 |M| + |lambda| |C| + |K| (Frobenius norms): a residual
    /// divided by this and |phi| is the backward error.
    double
    scale(const std::complex<double> lambda) const
    {
      return std::norm(lambda) * norm_M + std::abs(lambda) * norm_C + norm_K;
    }

  private:
    /// |r| / ((|lambda|^2 |M| + |lambda| |C| + |K|) |phi|)
    double
    relative(const std::complex<double> lambda, const ComplexVector &phi, const double norm_r) const;

    const dealii::PETScWrappers::MPI::SparseMatrix &M, &C, &K;
    const double                                    norm_M, norm_C, norm_K;
  };
} // namespace rotorfit
