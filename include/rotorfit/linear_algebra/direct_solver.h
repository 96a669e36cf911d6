#pragma once

#include <deal.II/base/parameter_handler.h>

#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/petsc_vector.h>

#include <petscksp.h>

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace rotorfit
{
  /**
   * Sparse direct solve through PETSc + MUMPS, distributed over the MPI
   * ranks. factorize() once, then solve() any number of right-hand sides
   * with back-substitutions only (Uzawa steps, load cases). Symmetric
   * matrices use LDL^T (Cholesky mode, about half the time and memory of LU).
   *
   * Parameters: subsection "Linear solver".
   */
  class DirectSolver
  {
  public:
    /// The factorisation: LDL^T or LU.
    enum class Type
    {
      mumps_cholesky,
      mumps_lu
    };

    DirectSolver() = default;
    ~DirectSolver();
    DirectSolver(const DirectSolver &) = delete;
    DirectSolver &
    operator=(const DirectSolver &) = delete;

    /// The entries of subsection "Linear solver".
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Reads the entries of declare_parameters().
    void
    parse_parameters(dealii::ParameterHandler &prm);

    /// Factorise @p matrix (kept referenced until the next factorize()).
    /// The same matrix object again, with the same nonzero pattern and
    /// type, is factorised on MUMPS's earlier analysis (its fill-reducing
    /// ordering, about 0.4 s on TS's benchmark mesh, is not repeated).
    void
    factorize(const dealii::PETScWrappers::MPI::SparseMatrix &matrix);

    /// Free the factorisation (counters are kept).
    void
    release()
    {
      destroy();
    }

    /// x = A^{-1} b with the current factorisation.
    void
    solve(dealii::PETScWrappers::MPI::Vector       &x,
          const dealii::PETScWrappers::MPI::Vector &b) const;

    /// X = A^-1 B for a block of right-hand sides (PETSc dense matrices with
    /// the row layout of A): one pass over the factors for all columns, so
    /// a column costs a fraction of a single back-substitution.
    void
    solve(Mat X, Mat B) const;

    /// X = A^-1 B with B given transposed as a sparse AIJ matrix @p Bt (one
    /// row per right-hand side): MUMPS then skips the zeros of the forward
    /// substitution. One MPI rank only (PETSc 3.18 hands MUMPS a sparse
    /// right-hand side only there); X dense as above.
    void
    solve_sparse(Mat X, Mat Bt) const;

    /// A factorisation is at hand.
    bool
    factorized() const
    {
      return ksp != nullptr;
    }

    /// Factorisations made (numeric phases alone included).
    unsigned int
    n_factorizations() const
    {
      return factorizations;
    }

    /// Factorisations made on an earlier analysis (numeric phase only).
    unsigned int
    n_reused_analyses() const
    {
      return reused_analyses;
    }

    /// Factorisations repeated with more MUMPS workspace (INFOG(1) -8, -9, ...).
    unsigned int
    n_workspace_retries() const
    {
      return workspace_retries;
    }

    /// Right-hand sides back-substituted.
    unsigned int
    n_solves() const
    {
      return solves;
    }

    /// The solver's name for the log.
    std::string
    name() const;

    /// One column u of a low-rank change A + sum_i s_i u_i u_i^T: its
    /// nonzeros (global row, value), the spring s, and a key naming it, so
    /// that A^-1 u is kept between updates of the same factorisation.
    struct UpdateColumn
    {
      unsigned int                                        key = 0;
      std::vector<std::pair<PetscInt, double>>            entries;
      double                                              spring = 0;
    };
    /// From now on (until the next factorize()) every solve applies
    /// (A + U diag(s) U^T)^-1 by the Woodbury identity: x = t - Z c with
    /// t = A^-1 b, Z = A^-1 U (back-substituted here for the keys the last
    /// update did not have) and (diag(1/s) + U^T Z) c = U^T t. An empty
    /// list returns to A. Returns false (and the solves stay on A) if the
    /// capacitance matrix is singular.
    bool
    update(const std::vector<UpdateColumn> &columns);
    /// Columns of the current update (0: the factorised matrix itself).
    std::size_t
    n_update_columns() const
    {
      return update_columns.size();
    }
    /// Memory of the update: local rows x columns of A^-1 U.
    std::size_t
    update_memory() const
    {
      return update_z.capacity() * sizeof(double);
    }
    /// Changes with every factorisation and every update: what cached
    /// back-substitutions were made with.
    unsigned int
    n_operators() const
    {
      return operators;
    }

    /// Override the parsed type (unsymmetric matrices need LU).
    void
    set_type(const Type t)
    {
      type = t;
    }

  private:
    void
    destroy();
    /// The numeric phase alone on the analysis made for @p A: false (and
    /// a workspace retry counted) where MUMPS ran out of room.
    bool
    refactorize_on_analysis(Mat A);
    /// A new KSP with MUMPS's analysis and factorisation of @p A, retried
    /// with more workspace where the delayed pivots need it.
    void
    analyse_and_factorize(Mat A, MPI_Comm comm);
    /// @p order: the update's columns, those of the last update it keeps
    /// first (their columns of Z moved to the front of update_z); returns
    /// their number.
    std::size_t
    keep_update_columns(const std::vector<UpdateColumn> &columns,
                        std::vector<UpdateColumn>       &order);
    /// Z = A^-1 U for the columns of @p order after the @p retained first.
    void
    back_substitute_update(const std::vector<UpdateColumn> &order, std::size_t retained);
    /// The LU of the capacitance matrix diag(1/s) + U^T Z; the update
    /// becomes @p order's, or false (and no update) if it is singular.
    bool
    factorize_capacitance(std::vector<UpdateColumn> &&order);
    /// @p row is one of this rank's
    bool
    owns(const PetscInt row) const
    {
      return row >= row_begin && row < row_begin + local_rows;
    }
    /// x -= Z c for the @p k local columns of @p x (leading dimension
    /// @p lda), c from the capacitance system (the current update).
    void
    apply_update(double *x, PetscInt k, PetscInt lda) const;
    /// x -= Z c on the local rows of a dense PETSc matrix.
    void
    apply_update(Mat X) const;

    Type                 type = Type::mumps_cholesky;
    KSP                  ksp  = nullptr;
    /// what the analysis behind @p ksp was made for
    Mat                  analysed_matrix = nullptr;
    Type                 analysed_type   = Type::mumps_cholesky;
    PetscObjectState     analysed_pattern = 0;
    unsigned int         factorizations = 0;
    unsigned int         reused_analyses = 0;
    unsigned int         workspace_retries = 0;
    mutable unsigned int solves         = 0;
    unsigned int         operators      = 0;
    /// the update: its columns, Z = A^-1 U on the local rows (column-major;
    /// the next update keeps the columns of keys it still has), the LU of
    /// diag(1/s) + U^T Z
    std::vector<UpdateColumn> update_columns;
    std::vector<double>       update_z;
    std::vector<double>       capacitance;
    std::vector<int>          pivots;
    PetscInt row_begin = 0, local_rows = 0, global_rows = 0;
    MPI_Comm                                      comm      = MPI_COMM_NULL;
  };
} // namespace rotorfit
