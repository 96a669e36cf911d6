#include <rotorfit/linear_algebra/direct_solver.h>

#include <deal.II/base/exceptions.h>

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
    // (a matrix object may carry a symmetric and then an unsymmetric
    // operator: the eigenproblem's S, then Q(sigma))
    check(MatSetOption(A, MAT_SYMMETRIC, type == Type::mumps_cholesky ? PETSC_TRUE : PETSC_FALSE),
          "MatSetOption");
    PetscObjectState pattern = 0;
    check(MatGetNonzeroState(A, &pattern), "MatGetNonzeroState");
    if (ksp != nullptr && A == analysed_matrix && type == analysed_type &&
        pattern == analysed_pattern)
      {
        // new values on the same pattern: PETSc's PCSetUp sees the same
        // nonzero state and runs MUMPS's numeric phase alone. A failure
        // (delayed pivots beyond the analysis's workspace) starts afresh.
        check(KSPSetOperators(ksp, A, A), "KSPSetOperators");
        check(PetscPushErrorHandler(PetscReturnErrorHandler, nullptr), "PetscPushErrorHandler");
        const PetscErrorCode code = KSPSetUp(ksp);
        PetscPopErrorHandler();
        if (code == 0)
          {
            ++factorizations;
            ++reused_analyses;
            return;
          }
        ++workspace_retries;
      }
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
    analysed_matrix  = A;
    analysed_type    = type;
    analysed_pattern = pattern;
  }

  void
  DirectSolver::solve(PETScWrappers::MPI::Vector       &x,
                      const PETScWrappers::MPI::Vector &b) const
  {
    Assert(ksp != nullptr, ExcMessage("factorize() first"));
    check(KSPSolve(ksp, b, x), "back-substitution (KSPSolve)");
    ++solves;
  }

  void
  DirectSolver::solve(Mat X, Mat B) const
  {
    check(MatMatSolve(factor_of(ksp), B, X), "block back-substitution (MatMatSolve)");
    PetscInt columns;
    check(MatGetSize(B, nullptr, &columns), "MatGetSize");
    solves += columns;
  }

  void
  DirectSolver::solve_sparse(Mat X, Mat Bt) const
  {
    check(MatMatTransposeSolve(factor_of(ksp), Bt, X),
          "sparse block back-substitution (MatMatTransposeSolve)");
    PetscInt columns;
    check(MatGetSize(Bt, &columns, nullptr), "MatGetSize");
    solves += columns;
  }
} // namespace rotorfit
