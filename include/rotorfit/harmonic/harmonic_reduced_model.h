#pragma once

#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/eigen/reduced_basis.h>
#include <rotorfit/linear_algebra/direct_solver.h>
#include <rotorfit/linear_algebra/row_block.h>

#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/sparse_matrix.h>

#include <complex>
#include <string>
#include <utility>
#include <vector>

namespace rotorfit
{
  /**
   * The reduced model of one harmonic's damped eigenproblem (doc/theory.md
   * 14.6). On one contact law the harmonic's matrices are affine in the
   * speed: K_t = K_0 + Omega^2 K_2 + K_b, C = Omega G + C_b, with the
   * bearings' K_b, C_b made of the station directions a_p (Coupling). A
   * damped full solve at an anchor speed gives the basis: the real and
   * imaginary parts of its eigenvectors and their first-order changes
   * Q(sigma)^-1 G phi, Q(sigma)^-1 K_2 phi and Q(sigma)^-1 a_p, made
   * M-orthonormal (ReducedBasis, the 3D model's linear algebra). A speed on
   * the same law is solved on the projections, and every kept mode is
   * checked on the full matrices through the kept products A V: backward
   * error, the eigenvalue error estimate of doc/theory.md 8.6 in the
   * Q(sigma)^-1 norm of the latest anchor (its Gram matrix of the residual
   * blocks), and coverage. A speed that fails a check becomes an anchor.
   */
  class HarmonicReducedModel
  {
  public:
    /// K_b += k a_p a_q^T and C_b += c a_p a_q^T.
    struct Coupling
    {
      unsigned int p = 0, q = 0;
      double       k = 0, c = 0;
    };
    /// A station direction a_p: (free index, weight) terms.
    using Direction = std::vector<std::pair<unsigned int, double>>;

    /// The harmonic's matrices on one law (deal.II for the entries of the
    /// norms, PETSc for the block products) and the station directions.
    struct Operators
    {
      const dealii::SparseMatrix<double>             *M = nullptr, *G = nullptr, *K0 = nullptr,
                                         *K2 = nullptr;
      const dealii::PETScWrappers::MPI::SparseMatrix *pM = nullptr, *pG = nullptr,
                                                     *pK0 = nullptr, *pK2 = nullptr;
      const std::vector<Direction>                   *stations = nullptr;
    };

    /// Harmonic @p n with the "Reduced ..." entries of @p settings.
    HarmonicReducedModel(const unsigned int n, const ReducedBasis &settings);

    /// The basis was made on the law numbered @p law (any other starts a
    /// new one; numbers, not addresses: a freed law's address comes back).
    bool
    serves(const std::size_t law) const
    {
      return law == key && basis.size() > 0;
    }

    /**
     * An anchor at @p rpm on @p law: the full solve's @p pairs, which hold
     * every eigenvalue within @p radius of the shift, and their directions
     * with the factorisation @p factors of Q(sigma) at this speed. The
     * basis starts again on another law or where it would outgrow three
     * anchors' worth.
     */
    void
    add_anchor(const Operators                   &op,
               const std::size_t                  law,
               const double                       rpm,
               const std::vector<EigenPair>      &pairs,
               const double                       radius,
               const DirectSolver                &factors,
               const std::vector<dealii::Vector<double>> &loads = {});

    /// What solve() is told of the speed.
    struct Speed
    {
      double                rpm = 0;
      std::vector<Coupling> couplings;
      unsigned int          n_wanted = 0; ///< eigenvalues (a conjugate pair counts twice)
      double                sigma = 0, backward_limit = 0, rigid_hz = 0;
    };

    /// The @p speed.n_wanted eigenvalues nearest the shift, each pair once
    /// (Im >= 0), checked; false with the reason in @p why where a check
    /// fails (nothing returned then).
    bool
    solve(const Operators &op, const Speed &speed, std::vector<EigenPair> &pairs, std::string &why);

    /**
     * The steady response Z(Omega) U = F, Z = K_t - Omega^2 M + i Omega C,
     * by Galerkin on the basis (whose anchors added Q(sigma)^-1 of the
     * loads' shape) and up to @p max_enrichments enrichments by
     * Q(sigma)^-1 of the residual's real and imaginary parts, with the
     * latest anchor's @p factors (doc/theory.md 14.6). The residual
     * ||F - Z U|| / ||F|| comes from the same kept products as the
     * projection. Returns false where it stays above @p tolerance.
     */
    bool
    respond(const Operators                           &op,
            const Speed                               &speed,
            const std::vector<std::complex<double>>   &F,
            const double                               tolerance,
            const unsigned int                         max_enrichments,
            const DirectSolver                        &factors,
            std::vector<std::complex<double>>         &U,
            double                                    &residual,
            unsigned int                              &basis_size) const;

    unsigned int
    size() const
    {
      return basis.size();
    }

    /// Largest error estimate of an accepted reduced solve.
    double worst_estimate = 0;

  private:
    void
    project(const Operators &op, const DirectSolver &factors);

    unsigned int n;
    ReducedBasis basis;
    std::size_t  key = 0;
    /// V^T M V, V^T G V, V^T K_0 V, V^T K_2 V and V^T a_p (m x stations)
    dealii::FullMatrix<double> Mr, Gr, K0r, K2r;
    std::vector<std::vector<double>> station_r;
    /// M V, G V, K_0 V, K_2 V, [a_p]: the residuals' blocks (those not
    /// zero in `used`, the order of the Gram matrix)
    RowBlock mv, gv, k0v, k2v, av;
    std::vector<const RowBlock *> blocks;
    std::vector<double>           gram; ///< blocks^T Q(sigma)^-1 blocks
    /// Frobenius inner products of the law: |M|, |K_0|^2, (K_0, K_2), |K_2|^2, |G|^2
    double m_norm = 0, k00 = 0, k02 = 0, k22 = 0, gg = 0;
  };
} // namespace rotorfit
