#include <rotorfit/linear_algebra/blas.h>
#include <rotorfit/linear_algebra/direct_solver.h>

#include <deal.II/base/exceptions.h>

#include <petsc/private/petscimpl.h> // PetscObjectStateIncrease

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    void
    check(const PetscErrorCode code, const char *what)
    {
      if (code != 0)
        throw std::runtime_error(std::string("PETSc/MUMPS failed in ") + what +
                                 " (error " + std::to_string(code) +
                                 "). If this is a factorisation, the matrix "
                                 "may be singular: is every body held?");
    }

    /// MUMPS's factor behind @p ksp (for the block back-substitutions).
    Mat
    factor_of(KSP ksp)
    {
      Assert(ksp != nullptr, ExcMessage("factorize() first"));
      PC  pc;
      Mat factor;
      check(KSPGetPC(ksp, &pc), "KSPGetPC");
      check(PCFactorGetMatrix(pc, &factor), "PCFactorGetMatrix");
      return factor;
    }
  } // namespace

  DirectSolver::~DirectSolver()
  {
    destroy();
  }

  void
  DirectSolver::destroy()
  {
    if (ksp != nullptr)
      KSPDestroy(&ksp);
    ksp             = nullptr;
    analysed_matrix = nullptr;
    update_columns.clear();
    std::vector<double>().swap(update_z);
  }

  void
  DirectSolver::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Linear solver");
    prm.declare_entry("Type",
                      "MUMPS Cholesky",
                      Patterns::Selection("MUMPS Cholesky|MUMPS LU"),
                      "Sparse direct solver (PETSc + MUMPS, distributed). "
                      "'MUMPS Cholesky' factorises the symmetric stiffness as "
                      "LDL^T; 'MUMPS LU' is the unsymmetric variant (slower, "
                      "kept for comparison).");
    prm.leave_subsection();
  }

  void
  DirectSolver::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Linear solver");
    type = (prm.get("Type") == "MUMPS LU" ? Type::mumps_lu :
                                             Type::mumps_cholesky);
    prm.leave_subsection();
  }

  std::string
  DirectSolver::name() const
  {
    return type == Type::mumps_lu ? "MUMPS LU" : "MUMPS Cholesky (LDL^T)";
  }

  void
  DirectSolver::factorize(const PETScWrappers::MPI::SparseMatrix &matrix)
  {
    const Mat A = matrix;
    MPI_Comm  comm;
    check(PetscObjectGetComm(reinterpret_cast<PetscObject>(A), &comm),
          "PetscObjectGetComm");
    // a new operator: no update, nothing kept of the old one's (its memory
    // too: the factorisation is the peak)
    update_columns.clear();
    std::vector<double>().swap(update_z);
    ++operators;
    {
      PetscInt end = 0;
      check(MatGetOwnershipRange(A, &row_begin, &end), "MatGetOwnershipRange");
      local_rows = end - row_begin;
      check(MatGetSize(A, &global_rows, nullptr), "MatGetSize");
      this->comm = comm;
    }
    // (a matrix object may carry a symmetric and then an unsymmetric
    // operator: the eigenproblem's S, then Q(sigma))
    check(MatSetOption(A, MAT_SYMMETRIC, type == Type::mumps_cholesky ? PETSC_TRUE : PETSC_FALSE),
          "MatSetOption");
    PetscObjectState pattern = 0;
    check(MatGetNonzeroState(A, &pattern), "MatGetNonzeroState");
    if (ksp != nullptr && A == analysed_matrix && type == analysed_type &&
        pattern == analysed_pattern && refactorize_on_analysis(A))
      return;
    analyse_and_factorize(A, comm);
    analysed_matrix  = A;
    analysed_type    = type;
    analysed_pattern = pattern;
  }

  bool
  DirectSolver::refactorize_on_analysis(const Mat A)
  {
    // new values on the same pattern: PETSc's PCSetUp sees the same
    // nonzero state and runs MUMPS's numeric phase alone. A failure
    // (delayed pivots beyond the analysis's workspace) starts afresh.
    // PETSc refactorises only where the matrix's state moved since the
    // last set-up, and sums made on its local blocks (add_subset) do not
    // move it: the caller asks for a factorisation, so one is made
    PetscObjectStateIncrease(reinterpret_cast<PetscObject>(A));
    check(KSPSetOperators(ksp, A, A), "KSPSetOperators");
    check(PetscPushErrorHandler(PetscReturnErrorHandler, nullptr), "PetscPushErrorHandler");
    const PetscErrorCode code = KSPSetUp(ksp);
    PetscPopErrorHandler();
    if (code == 0)
      {
        ++factorizations;
        ++reused_analyses;
        return true;
      }
    ++workspace_retries;
    return false;
  }

  void
  DirectSolver::analyse_and_factorize(const Mat A, const MPI_Comm comm)
  {
    // MUMPS sizes its workspace from the analysis plus ICNTL(14) percent;
    // delayed pivots of LDL^T can exceed it (INFOG(1) = -8, -9: seen on TS
    // with 2 ranks). Such a failure is retried with more room, any other
    // is an error.
    PetscErrorCode code = 0;
    PetscInt       info = 0;
    for (const PetscInt relax : {0, 100, 400})
      {
        destroy();
        check(KSPCreate(comm, &ksp), "KSPCreate");
        check(KSPSetOperators(ksp, A, A), "KSPSetOperators");
        check(KSPSetType(ksp, KSPPREONLY), "KSPSetType");
        PC pc;
        check(KSPGetPC(ksp, &pc), "KSPGetPC");
        check(PCSetType(pc, type == Type::mumps_lu ? PCLU : PCCHOLESKY), "PCSetType");
        check(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS), "PCFactorSetMatSolverType");
        check(PCFactorSetUpMatSolverType(pc), "PCFactorSetUpMatSolverType");
        Mat factor;
        check(PCFactorGetMatrix(pc, &factor), "PCFactorGetMatrix");
        if (relax > 0)
          check(MatMumpsSetIcntl(factor, 14, relax), "MatMumpsSetIcntl");
        check(KSPSetErrorIfNotConverged(ksp, PETSC_TRUE), "KSPSetErrorIfNotConverged");
        check(PetscPushErrorHandler(PetscReturnErrorHandler, nullptr), "PetscPushErrorHandler");
        code = KSPSetUp(ksp);
        PetscPopErrorHandler();
        if (code == 0)
          break;
        info = 0;
        MatMumpsGetInfog(factor, 1, &info);
        if (info != -8 && info != -9 && info != -11 && info != -14 && info != -15)
          break;
        ++workspace_retries;
      }
    if (code != 0)
      throw std::runtime_error("PETSc/MUMPS failed in factorisation (KSPSetUp) (error " +
                               std::to_string(code) + ", MUMPS INFOG(1) = " +
                               std::to_string(info) +
                               "). If INFOG(1) = -10 the matrix is singular: is every "
                               "body held? If it is -13, memory ran out.");
    ++factorizations;
  }

  void
  DirectSolver::solve(PETScWrappers::MPI::Vector       &x,
                      const PETScWrappers::MPI::Vector &b) const
  {
    Assert(ksp != nullptr, ExcMessage("factorize() first"));
    // on the factors themselves: KSPSolve would first set the operator up
    // again wherever the matrix object changed since (the eigenproblem's
    // tangent is made anew at every speed; its factorisation is of S)
    check(MatSolve(factor_of(ksp), b, x), "back-substitution (MatSolve)");
    ++solves;
    if (!update_columns.empty())
      {
        Vec          v = x;
        PetscScalar *a = nullptr;
        check(VecGetArray(v, &a), "VecGetArray");
        apply_update(a, 1, local_rows);
        check(VecRestoreArray(v, &a), "VecRestoreArray");
      }
  }

  void
  DirectSolver::solve(Mat X, Mat B) const
  {
    check(MatMatSolve(factor_of(ksp), B, X), "block back-substitution (MatMatSolve)");
    PetscInt columns;
    check(MatGetSize(B, nullptr, &columns), "MatGetSize");
    solves += columns;
    apply_update(X);
  }

  void
  DirectSolver::solve_sparse(Mat X, Mat Bt) const
  {
    check(MatMatTransposeSolve(factor_of(ksp), Bt, X),
          "sparse block back-substitution (MatMatTransposeSolve)");
    PetscInt columns;
    check(MatGetSize(Bt, &columns, nullptr), "MatGetSize");
    solves += columns;
    apply_update(X);
  }

  bool
  DirectSolver::update(const std::vector<UpdateColumn> &columns)
  {
    if (ksp == nullptr)
      throw std::logic_error("DirectSolver::update() before factorize()");
    ++operators;
    std::vector<UpdateColumn> order;
    const std::size_t         retained = keep_update_columns(columns, order);
    update_columns.clear();
    back_substitute_update(order, retained);
    if (order.empty())
      {
        std::vector<double>().swap(update_z);
        return true;
      }
    return factorize_capacitance(std::move(order));
  }

  std::size_t
  DirectSolver::keep_update_columns(const std::vector<UpdateColumn> &columns,
                                    std::vector<UpdateColumn>       &order)
  {
    const std::size_t rows = local_rows;
    // Z = A^-1 U: the columns of the last update still wanted move to the
    // front (in place), the new ones go behind them
    std::map<unsigned int, std::size_t> had;
    for (std::size_t j = 0; j < update_columns.size(); ++j)
      had[update_columns[j].key] = j;
    std::vector<std::size_t> from;
    for (const auto &u : columns)
      if (had.count(u.key))
        order.push_back(u), from.push_back(had[u.key]);
    std::sort(from.begin(), from.end());
    {
      std::vector<UpdateColumn> kept;
      for (const std::size_t j : from)
        {
          if (j != kept.size())
            std::copy(update_z.begin() + j * rows, update_z.begin() + (j + 1) * rows,
                      update_z.begin() + kept.size() * rows);
          for (const auto &u : order)
            if (u.key == update_columns[j].key)
              kept.push_back(u);
        }
      order = std::move(kept);
    }
    const std::size_t retained = order.size();
    for (const auto &u : columns)
      if (!had.count(u.key))
        order.push_back(u);
    return retained;
  }

  void
  DirectSolver::back_substitute_update(const std::vector<UpdateColumn> &order,
                                       const std::size_t                retained)
  {
    // the new columns of Z after the @p retained ones, 32 at a time (Z's
    // storage grows once, to the new size)
    const std::size_t rows = local_rows;
    update_z.resize(retained * rows);
    update_z.reserve(order.size() * rows);
    constexpr PetscInt chunk = 32;
    for (std::size_t first = retained; first < order.size(); first += chunk)
      {
        const PetscInt m = std::min<std::size_t>(chunk, order.size() - first);
        Mat            B, X;
        check(MatCreateDense(comm, local_rows, PETSC_DECIDE, global_rows, m, nullptr, &B),
              "MatCreateDense");
        check(MatCreateDense(comm, local_rows, PETSC_DECIDE, global_rows, m, nullptr, &X),
              "MatCreateDense");
        PetscScalar *a  = nullptr;
        PetscInt     ld = 0;
        check(MatDenseGetLDA(B, &ld), "MatDenseGetLDA");
        check(MatDenseGetArray(B, &a), "MatDenseGetArray");
        std::fill(a, a + std::size_t(ld) * m, 0.);
        for (PetscInt j = 0; j < m; ++j)
          for (const auto &[row, value] : order[first + j].entries)
            if (owns(row))
              a[row - row_begin + std::size_t(j) * ld] += value;
        check(MatDenseRestoreArray(B, &a), "MatDenseRestoreArray");
        check(MatAssemblyBegin(B, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
        check(MatAssemblyEnd(B, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
        check(MatMatSolve(factor_of(ksp), B, X), "block back-substitution (MatMatSolve)");
        solves += m;
        check(MatDenseGetLDA(X, &ld), "MatDenseGetLDA");
        check(MatDenseGetArray(X, &a), "MatDenseGetArray");
        for (PetscInt j = 0; j < m; ++j)
          update_z.insert(update_z.end(), a + std::size_t(j) * ld, a + std::size_t(j) * ld + rows);
        check(MatDenseRestoreArray(X, &a), "MatDenseRestoreArray");
        MatDestroy(&B);
        MatDestroy(&X);
      }
  }

  bool
  DirectSolver::factorize_capacitance(std::vector<UpdateColumn> &&order)
  {
    const std::size_t rows = local_rows;
    const int         c    = order.size();
    // diag(1/s) + U^T Z
    std::vector<double> F(std::size_t(c) * c, 0.);
    for (int i = 0; i < c; ++i)
      for (const auto &[row, value] : order[i].entries)
        if (owns(row))
          for (int j = 0; j < c; ++j)
            F[i + std::size_t(j) * c] += value * update_z[row - row_begin + std::size_t(j) * rows];
    MPI_Allreduce(MPI_IN_PLACE, F.data(), F.size(), MPI_DOUBLE, MPI_SUM, comm);
    bool finite = true;
    for (int i = 0; i < c; ++i)
      {
        F[i + std::size_t(i) * c] += 1. / order[i].spring;
        finite &= std::isfinite(F[i + std::size_t(i) * c]);
      }
    std::vector<int> p(c);
    int              info = 0;
    dgetrf_(&c, &c, F.data(), &c, p.data(), &info);
    if (info != 0 || !finite)
      {
        std::vector<double>().swap(update_z);
        return false;
      }
    update_columns = std::move(order);
    capacitance    = std::move(F);
    pivots         = std::move(p);
    return true;
  }

  void
  DirectSolver::apply_update(Mat X) const
  {
    if (update_columns.empty())
      return;
    PetscInt     k = 0, ld = 0;
    PetscScalar *a = nullptr;
    check(MatGetSize(X, nullptr, &k), "MatGetSize");
    check(MatDenseGetLDA(X, &ld), "MatDenseGetLDA");
    check(MatDenseGetArray(X, &a), "MatDenseGetArray");
    apply_update(a, k, ld);
    check(MatDenseRestoreArray(X, &a), "MatDenseRestoreArray");
  }

  void
  DirectSolver::apply_update(double *x, const PetscInt k, const PetscInt lda) const
  {
    const int c = update_columns.size(), columns = k;
    if (c == 0 || k == 0)
      return;
    // c = (diag(1/s) + U^T Z)^-1 U^T t, then t - Z c
    std::vector<double> y(std::size_t(c) * k, 0.);
    for (int i = 0; i < c; ++i)
      for (const auto &[row, value] : update_columns[i].entries)
        if (owns(row))
          for (PetscInt j = 0; j < k; ++j)
            y[i + std::size_t(j) * c] += value * x[row - row_begin + std::size_t(j) * lda];
    MPI_Allreduce(MPI_IN_PLACE, y.data(), y.size(), MPI_DOUBLE, MPI_SUM, comm);
    int info = 0;
    dgetrs_("N", &c, &columns, capacitance.data(), &c, pivots.data(), y.data(), &c, &info);
    const int    rows = local_rows, ld = lda;
    const double minus = -1, one = 1;
    if (rows > 0)
      dgemm_("N", "N", &rows, &columns, &c, &minus, update_z.data(), &rows, y.data(), &c, &one, x,
             &ld);
  }
} // namespace rotorfit
