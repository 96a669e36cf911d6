#pragma once

#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/linear_algebra/row_block.h>

#include <deal.II/base/parameter_handler.h>

#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/vector.h>

#include <complex>
#include <vector>

namespace rotorfit
{
  /**
   * A reduced model of the damped eigenproblem (doc/theory.md 8.6): an
   * M-orthonormal basis V of the real and imaginary parts of full
   * eigenvectors at anchor speeds, the projections V^T A V of the sparse
   * matrices, and the dense quadratic eigenproblem
   * (lambda^2 V^T M V + lambda V^T C V + V^T K V) y = 0 solved with LAPACK
   * (dgeev on the first companion form, size 2 m). The basis vectors are
   * replicated on every MPI rank, like the Arnoldi vectors.
   *
   * Which speeds it may serve, and how its modes are checked against the
   * full matrices, is ReducedSolve's business (its projections:
   * ReducedModel); this class is the linear algebra.
   *
   * Parameters: the "Reduced ..." entries of subsection "Eigenproblem".
   */
  class ReducedBasis
  {
  public:
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    void
    parse_parameters(dealii::ParameterHandler &prm);

    bool
    enabled() const
    {
      return use;
    }

    /// Estimated relative eigenvalue error a wanted reduced mode must meet.
    double
    tolerance() const
    {
      return max_error;
    }

    /// Extra conjugate pairs an anchor solves beyond those wanted.
    unsigned int
    margin() const
    {
      return extra_modes;
    }

    /// Assumed bound on |d lambda / d Omega| of any line [-].
    double
    slope_bound() const
    {
      return max_slope;
    }

    /// Most tie springs an undamped anchor takes as a low-rank update of the
    /// last LDL^T instead of a new one (0: never).
    unsigned int
    tie_update_limit() const
    {
      return max_tie_updates;
    }

    /// New bases start from undamped modes (else from a damped full solve).
    bool
    undamped_anchors() const
    {
      return undamped;
    }

    /// Largest basis before a new anchor replaces it instead of adding.
    unsigned int
    capacity(const unsigned int anchor_size) const
    {
      return 3 * anchor_size;
    }

    void
    clear();

    unsigned int
    size() const
    {
      return columns;
    }

    /// Changes whenever the basis does (projections are cached against it).
    unsigned int
    version() const
    {
      return serial;
    }

    /// Add @p x, M-orthonormalised against the basis (classical Gram-Schmidt
    /// twice); false if it lies in the span to 1e-10 (then not added).
    bool
    add(const dealii::Vector<double> &x, const dealii::PETScWrappers::MPI::SparseMatrix &M);

    /// Add the block @p x in order, each M-orthonormalised against the basis
    /// and the columns of the block kept before it; the columns in the span
    /// to 1e-10 are left out. Returns how many were added. (Block products
    /// with M: a quarter of the time of one product per column.)
    unsigned int
    add(const std::vector<const dealii::Vector<double> *> &x,
        const dealii::PETScWrappers::MPI::SparseMatrix    &M);

    /// One classical Gram-Schmidt step in the M inner product: v -= V V^T mv
    /// with @p mv = M v (the caller makes the products, for a block at once).
    void
    subtract_projection(dealii::Vector<double> &v, const dealii::Vector<double> &mv) const;
    /// V^T x.
    std::vector<double>
    coefficients(const dealii::Vector<double> &x) const;
    /// V itself (n x m, column-major).
    const std::vector<double> &
    matrix() const
    {
      return flat;
    }
    /// V^T [x_1 .. x_k] (m x k, column-major): one pass over V for all.
    std::vector<double>
    coefficients(const std::vector<const dealii::Vector<double> *> &x) const;

    /// V^T A V; with @p products also A V (by its nonzero rows where few are).
    dealii::FullMatrix<double>
    project(const dealii::PETScWrappers::MPI::SparseMatrix &A,
            RowBlock                                       *products = nullptr) const;

    /// z_c += a P y_c for every column y_c (one dgemm, one pass over P):
    /// P = A V kept by project(), or V itself for P = nullptr; a z_c of
    /// the wrong size is first set to zero of size n.
    void
    multiply(const RowBlock                                       *P,
             const std::vector<std::vector<std::complex<double>>> &y,
             const double                                          a,
             const std::vector<ComplexVector *>                   &z) const;

    /// C += a P^T X for the columns X (n x k, column-major; C m x k, set to
    /// zero first if of another size): one pass over P for all columns.
    void
    apply_transpose(const RowBlock            &P,
                    const std::vector<double> &X,
                    const double               a,
                    std::vector<double>       &C) const;

    /// Eigenvalue, right and left reduced eigenvectors y, w (length m) of
    /// the dense problem: Q_r(lambda) y = 0, w^H Q_r(lambda) = 0.
    struct Pair
    {
      std::complex<double>              lambda;
      std::vector<std::complex<double>> y, w;
    };

    /// Every eigenvalue with Im >= 0 of lambda^2 Mr + lambda Cr + Kr (the
    /// conjugates are implied); false if LAPACK failed.
    bool
    solve(const dealii::FullMatrix<double> &Mr,
          const dealii::FullMatrix<double> &Cr,
          const dealii::FullMatrix<double> &Kr,
          std::vector<Pair>                &pairs) const;

    /// phi = V y.
    ComplexVector
    expand(const std::vector<std::complex<double>> &y) const;

    /// Anchor speeds of this basis and the radius |lambda - sigma| inside
    /// which their full solve found every eigenvalue.
    struct Anchor
    {
      double rpm = 0, radius = 0;
    };
    std::vector<Anchor> anchors;

  private:
    bool         use                = true;
    double       max_error = 1e-7;
    unsigned int extra_modes        = 6;
    double       max_slope          = 2;
    unsigned int max_tie_updates    = 256;
    bool         undamped           = true;

    /// V, n x m column-major (one block: dgemv and dgemm read it directly)
    std::vector<double> flat;
    std::size_t         rows    = 0;
    unsigned int        columns = 0;
    unsigned int        serial  = 0;
  };
} // namespace rotorfit
