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
    ksp = nullptr;
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
    destroy();
    const Mat A = matrix;
    MPI_Comm  comm;
    check(PetscObjectGetComm(reinterpret_cast<PetscObject>(A), &comm),
          "PetscObjectGetComm");
    check(KSPCreate(comm, &ksp), "KSPCreate");
    if (type == Type::mumps_cholesky)
      check(MatSetOption(A, MAT_SYMMETRIC, PETSC_TRUE), "MatSetOption");
    check(KSPSetOperators(ksp, A, A), "KSPSetOperators");
    check(KSPSetType(ksp, KSPPREONLY), "KSPSetType");
    PC pc;
    check(KSPGetPC(ksp, &pc), "KSPGetPC");
    check(PCSetType(pc, type == Type::mumps_lu ? PCLU : PCCHOLESKY),
          "PCSetType");
    check(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS),
          "PCFactorSetMatSolverType");
    check(KSPSetErrorIfNotConverged(ksp, PETSC_TRUE), "KSPSetErrorIfNotConverged");
    check(KSPSetUp(ksp), "factorisation (KSPSetUp)");
    ++factorizations;
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
    Assert(ksp != nullptr, ExcMessage("factorize() first"));
    PC  pc;
    Mat factor;
    check(KSPGetPC(ksp, &pc), "KSPGetPC");
    check(PCFactorGetMatrix(pc, &factor), "PCFactorGetMatrix");
    check(MatMatSolve(factor, B, X), "block back-substitution (MatMatSolve)");
    PetscInt columns;
    check(MatGetSize(B, nullptr, &columns), "MatGetSize");
    solves += columns;
  }
} // namespace rotorfit
