#pragma once

#include <rotorfit/eigen/backward_error.h>
#include <rotorfit/eigen/eigensolver_statistics.h>
#include <rotorfit/linear_algebra/complex_vector.h>
#include <rotorfit/linear_algebra/direct_solver.h>

#include <deal.II/base/parameter_handler.h>

#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/vector.h>

#include <complex>
#include <string>
#include <vector>

namespace rotorfit
{
  /// One eigenpair of the quadratic problem (lambda^2 M + lambda C + K) phi = 0.
  struct EigenPair
  {
    std::complex<double> lambda; ///< [rad/s]; Im >= 0 member of a pair
    ComplexVector        phi;    ///< displacement part of the state vector, |phi| = 1
    ComplexVector        m_phi;  ///< M phi (from the backward error, reused for MAC/energies)
    double               backward_error = 0;
    /// estimated relative error of lambda (reduced solves; 0 for full ones)
    double error_estimate = 0;
  };

  /**
   * Damped eigenvalues of M q'' + C q' + K q = 0 (doc/theory.md 8): first companion
   * linearisation of size 2n, shift-invert with a real shift sigma > 0 and
   * ARPACK (dnaupd mode 3, B = diag(I, M)); one sparse LU of
   * Q(sigma) = sigma^2 M + sigma C + K per call. A positive shift keeps Q
   * regular for free-free rotors and loose bodies (doc/theory.md P13), and the
   * eigenvalues come ordered by |lambda - sigma|, lowest frequencies first.
   *
   * The Arnoldi vectors are replicated on every MPI rank (identical work,
   * deterministic start vector); the factorisation and the products with M,
   * C, K are distributed.
   *
   * Parameters: subsection "Eigenproblem" (solver entries).
   */
  class DampedEigensolver
  {
  public:
    /// The solver entries of subsection "Eigenproblem".
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Reads the entries of declare_parameters().
    void
    parse_parameters(dealii::ParameterHandler &prm);

    /// What a solve did (kept under this name for the callers).
    using Statistics = EigensolverStatistics;

    /**
     * The @p n_eigenvalues eigenvalues closest to the shift (conjugate pairs
     * count twice), each pair once with Im lambda >= 0, sorted by |lambda|.
     * Q(sigma) is factorised in @p K's storage, which is given back
     * unchanged up to rounding (factorize()). @p attempt > 0 is a
     * retry on the same matrices: the factorisation is reused and the
     * Krylov space and restart cap grow by 2^attempt. Unconverged ARPACK
     * slots are dropped and counted in @p statistics.
     */
    std::vector<EigenPair>
    solve(const dealii::PETScWrappers::MPI::SparseMatrix &M,
          const dealii::PETScWrappers::MPI::SparseMatrix &C,
          dealii::PETScWrappers::MPI::SparseMatrix       &K,
          const unsigned int                              n_eigenvalues,
          Statistics                                     &statistics,
          const unsigned int                              attempt = 0);

    /// Factorise Q = K + sigma C + sigma^2 M (solve() does it too), formed
    /// in @p K's own storage and taken out again after the factorisation:
    /// MUMPS keeps its own copy of the entries, and a matrix of the full
    /// pattern less is 58 MB on TS's benchmark mesh. K comes back equal to
    /// rounding (a few units in the last place of its entries).
    void
    factorize(const dealii::PETScWrappers::MPI::SparseMatrix &M,
              const dealii::PETScWrappers::MPI::SparseMatrix &C,
              dealii::PETScWrappers::MPI::SparseMatrix       &K);

    /// A mode of the undamped problem K phi = mu M phi (mu = omega^2).
    struct UndampedMode
    {
      double                 mu = 0;
      dealii::Vector<double> phi;
      /// |K phi - mu M phi| / ((|mu| |M| + |K|) |phi|), Frobenius norms
      double residual = 0;
    };

    /**
     * The @p n_modes lowest modes of K phi = mu M phi (K symmetric: no
     * gyroscopic or damping term), ascending in mu: symmetric Lanczos
     * (Anasazi's block Krylov-Schur, or ARPACK dsaupd mode 3 for
     * Lanczos block size 1 and where the block method comes short) about
     * mu = -sigma^2 on an LDL^T of
     * S = K + sigma^2 M, which is positive definite wherever K is positive
     * semi-definite, rigid motions included, formed in @p K's storage as
     * in factorize(); the factorisation stays for linear_solver()
     * (doc/theory.md 8.7). ARPACK's
     * convergence is not reported through deal.II: every mode carries its
     * residual, for the caller to judge. With @p factorize false the
     * current operator is used as it is: the last LDL^T of S with the
     * low-rank update of update_factorization().
     */
    std::vector<UndampedMode>
    solve_undamped(const dealii::PETScWrappers::MPI::SparseMatrix &M,
                   dealii::PETScWrappers::MPI::SparseMatrix       &K,
                   const unsigned int                              n_modes,
                   Statistics                                     &statistics,
                   bool                                            factorize = true);

    /// The operator of the solves becomes the factorised matrix plus
    /// U diag(s) U^T (DirectSolver::update); false if that failed.
    bool
    update_factorization(const std::vector<DirectSolver::UpdateColumn> &columns)
    {
      return solver.update(columns);
    }

    /// Arnoldi vectors for @p nev eigenvalues at Krylov growth @p growth.
    unsigned int
    krylov_size(const unsigned int nev, const double growth = 1) const;

    /// The shift sigma [rad/s] (parameter "Shift", given in Hz).
    double
    shift() const
    {
      return sigma;
    }

    /// Largest backward error of a converged mode (parameter "Backward
    /// error limit").
    double
    backward_error_limit() const
    {
      return max_backward_error;
    }

    /// The factorisation of the last solve: Q(sigma) after solve() or
    /// factorize(), S after solve_undamped().
    const DirectSolver &
    linear_solver() const
    {
      return solver;
    }

  private:
    /// The LDL^T of S = K + sigma^2 M, formed in @p K's storage as in
    /// factorize().
    void
    factorize_shifted_stiffness(const dealii::PETScWrappers::MPI::SparseMatrix &M,
                                dealii::PETScWrappers::MPI::SparseMatrix       &K);

    /// The @p nev largest eigenvalues of S^-1 M as @p mu (K phi = mu M phi)
    /// with their vectors @p z, on the current factorisation of S: the
    /// block Krylov-Schur method where the Lanczos block size and the
    /// problem's size allow it, ARPACK otherwise or where it comes short.
    void
    undamped_lanczos(const dealii::PETScWrappers::MPI::SparseMatrix &M,
                     const unsigned int                              nev,
                     const unsigned int                              ncv,
                     Statistics                                     &statistics,
                     std::vector<dealii::Vector<double>>            &z,
                     std::vector<std::complex<double>>              &mu) const;

    /// Anasazi's block Krylov-Schur for undamped_lanczos(); false (and
    /// the reason in statistics.fallback) where it found fewer than @p nev.
    bool
    undamped_block_krylov_schur(const dealii::PETScWrappers::MPI::SparseMatrix &M,
                                const unsigned int                              nev,
                                const unsigned int                              ncv,
                                Statistics                                     &statistics,
                                std::vector<dealii::Vector<double>>            &z,
                                std::vector<std::complex<double>>              &mu) const;

    /// ARPACK's single-vector Lanczos (dsaupd mode 3) for undamped_lanczos().
    void
    undamped_arpack(const dealii::PETScWrappers::MPI::SparseMatrix &M,
                    const unsigned int                              nev,
                    const unsigned int                              ncv,
                    Statistics                                     &statistics,
                    std::vector<dealii::Vector<double>>            &z,
                    std::vector<std::complex<double>>              &mu) const;

    double       sigma               = 2 * M_PI * 10;
    double       tolerance           = 1e-10;
    double       krylov_factor       = 2;
    unsigned int max_restarts        = 300;
    unsigned int lanczos_block       = 6;
    double       lanczos_tolerance   = 1e-6;
    double       max_backward_error  = 1e-6;
    DirectSolver solver;
  };
} // namespace rotorfit
