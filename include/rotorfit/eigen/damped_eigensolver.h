#pragma once

#include <rotorfit/linear_algebra/direct_solver.h>
#include <rotorfit/linear_algebra/row_block.h>

#include <deal.II/base/index_set.h>
#include <deal.II/base/parameter_handler.h>

#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/petsc_vector.h>
#include <deal.II/lac/vector.h>

#include <complex>
#include <string>
#include <vector>

namespace rotorfit
{
  /// A complex vector as two real ones (replicated on every rank).
  struct ComplexVector
  {
    dealii::Vector<double> re, im;
  };

  /// Pointers to each of @p list (the output columns of a block product).
  inline std::vector<ComplexVector *>
  column_pointers(std::vector<ComplexVector> &list)
  {
    std::vector<ComplexVector *> z;
    for (auto &x : list)
      z.push_back(&x);
    return z;
  }

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

  /// Backward error of (lambda, phi) on the quadratic problem:
  /// ||Q(lambda) phi|| / ((|lambda|^2 ||M|| + |lambda| ||C|| + ||K||) ||phi||)
  /// (Frobenius norms), the measure of every mode's convergence.
  class BackwardError
  {
  public:
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
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    void
    parse_parameters(dealii::ParameterHandler &prm);

    struct Statistics
    {
      unsigned int requested   = 0; ///< ARPACK nev (conjugates counted twice)
      unsigned int krylov_size = 0;
      unsigned int iterations  = 0; ///< Arnoldi restarts used
      unsigned int max_restarts = 0; ///< cap of this attempt
      /// ARPACK slots left unconverged (deal.II 9.4 returns them as 0 + 0i
      /// with its checks compiled out): never eigenvalues, never rigid modes
      unsigned int unconverged_slots = 0;
      unsigned int operator_applications = 0;
      unsigned int block_size   = 1; ///< columns per back-substitution (undamped)
      unsigned int block_solves = 0; ///< passes over the factors (block Lanczos)
      std::string  fallback;         ///< why the block Lanczos gave way to ARPACK
      double       factorization_seconds = 0, arnoldi_seconds = 0,
                   solve_seconds = 0, check_seconds = 0;
    };

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
     * residual, for the caller to judge.
     */
    /// With @p factorize false the current operator is used as it is: the
    /// last LDL^T of S with the low-rank update of update_factorization().
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

    double
    shift() const
    {
      return sigma;
    }

    double
    backward_error_limit() const
    {
      return max_backward_error;
    }

    const DirectSolver &
    linear_solver() const
    {
      return solver;
    }

  private:
    double       sigma               = 2 * M_PI * 10;
    double       tolerance           = 1e-10;
    double       krylov_factor       = 2;
    unsigned int max_restarts        = 300;
    unsigned int lanczos_block       = 6;
    double       lanczos_tolerance   = 1e-6;
    double       max_backward_error  = 1e-6;
    DirectSolver solver;
  };

  /// y = A x (or A^T x) for replicated vectors (x, y of full size), A distributed.
  void
  replicated_vmult(const dealii::PETScWrappers::MPI::SparseMatrix &A,
                   const dealii::Vector<double>                   &x,
                   dealii::Vector<double>                         &y,
                   const bool                                      transpose = false);

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

  /// x = A^{-1} b for replicated vectors with @p solver's factorisation of
  /// A (@p layout: a matrix with A's row distribution).
  void
  replicated_solve(const DirectSolver                             &solver,
                   const dealii::PETScWrappers::MPI::SparseMatrix &layout,
                   const dealii::Vector<double>                   &b,
                   dealii::Vector<double>                         &x);

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
    std::size_t                source, target;
    const std::vector<double> *base;
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

  /// Complex y = A x (or A^T x), A real.
  void
  replicated_vmult(const dealii::PETScWrappers::MPI::SparseMatrix &A,
                   const ComplexVector                            &x,
                   ComplexVector                                  &y,
                   const bool                                      transpose = false);
} // namespace rotorfit
