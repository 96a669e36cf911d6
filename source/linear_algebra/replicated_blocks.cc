#include <rotorfit/eigen/damped_eigensolver.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>

#include <algorithm>

// Products and back-substitutions of blocks of replicated columns (every
// rank holds whole vectors; the matrices and factors are distributed).

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    /// Column j of the distributed dense @p Y (its local rows) gathered on
    /// every rank into out(j), a full-length column.
    template <typename Out>
    void
    gather_columns(Mat Y, const PetscInt n_local, const PetscInt columns, const MPI_Comm comm,
                   const Out &out)
    {
      const unsigned int ranks = Utilities::MPI::n_mpi_processes(comm);
      std::vector<int>   counts(ranks), displs(ranks);
      const int          local = n_local;
      MPI_Allgather(&local, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
      for (unsigned int r = 1; r < ranks; ++r)
        displs[r] = displs[r - 1] + counts[r - 1];
      const PetscScalar *a;
      PetscInt           ld;
      MatDenseGetLDA(Y, &ld);
      MatDenseGetArrayRead(Y, &a);
      for (PetscInt j = 0; j < columns; ++j)
        MPI_Allgatherv(a + j * ld, local, MPI_DOUBLE, out(j), counts.data(), displs.data(),
                       MPI_DOUBLE, comm);
      MatDenseRestoreArrayRead(Y, &a);
    }
  } // namespace

  void
  replicated_mmult(const PETScWrappers::MPI::SparseMatrix &A,
                   const double                           *x,
                   const unsigned int                      m,
                   double                                 *y)
  {
    // PETSc's sequential AIJ x dense product reads A once for four columns
    // (TS: 3.1 ms per column against 12 ms per sparse product); its MPI
    // product goes column by column. So each rank multiplies its diagonal
    // and off-diagonal blocks by the rows of the replicated columns they
    // need, and the rows are gathered.
    if (m == 0)
      return;
    const auto     range   = A.local_range();
    const PetscInt n_local = range.second - range.first, n = A.m(), columns = m;
    const MPI_Comm comm    = A.get_mpi_communicator();
    const auto     ok      = [](const PetscErrorCode code) {
      AssertThrow(code == 0, ExcMessage("PETSc sparse x dense product failed"));
    };
    Mat            Ad, Ao;
    const PetscInt *colmap;
    ok(MatMPIAIJGetSeqAIJ(A, &Ad, &Ao, &colmap));
    PetscInt n_ghost;
    ok(MatGetSize(Ao, nullptr, &n_ghost));
    // rows of X: the local ones for Ad, the ghost ones (colmap) for Ao
    const auto dense = [&](const PetscInt rows, const auto &row_of) {
      Mat          X;
      PetscScalar *a;
      ok(MatCreateSeqDense(PETSC_COMM_SELF, rows, columns, nullptr, &X));
      ok(MatDenseGetArray(X, &a));
      for (PetscInt j = 0; j < columns; ++j)
        for (PetscInt i = 0; i < rows; ++i)
          a[j * rows + i] = x[j * n + row_of(i)];
      ok(MatDenseRestoreArray(X, &a));
      ok(MatAssemblyBegin(X, MAT_FINAL_ASSEMBLY));
      ok(MatAssemblyEnd(X, MAT_FINAL_ASSEMBLY));
      return X;
    };
    Mat Xd = dense(n_local, [&](const PetscInt i) { return range.first + i; });
    Mat Yd;
    ok(MatMatMult(Ad, Xd, MAT_INITIAL_MATRIX, PETSC_DEFAULT, &Yd));
    if (n_ghost > 0)
      {
        Mat Xo = dense(n_ghost, [&](const PetscInt i) { return colmap[i]; });
        Mat Yo;
        ok(MatMatMult(Ao, Xo, MAT_INITIAL_MATRIX, PETSC_DEFAULT, &Yo));
        ok(MatAXPY(Yd, 1., Yo, SAME_NONZERO_PATTERN));
        ok(MatDestroy(&Xo));
        ok(MatDestroy(&Yo));
      }
    gather_columns(Yd, n_local, columns, comm, [&](const PetscInt j) { return y + j * n; });
    ok(MatDestroy(&Xd));
    ok(MatDestroy(&Yd));
  }

  void
  replicated_mmult(const PETScWrappers::MPI::SparseMatrix    &A,
                   const std::vector<const Vector<double> *> &x,
                   std::vector<Vector<double>>               &y)
  {
    const std::size_t   n = A.m();
    std::vector<double> flat(n * x.size()), out(n * x.size());
    for (std::size_t j = 0; j < x.size(); ++j)
      std::copy(x[j]->begin(), x[j]->end(), flat.begin() + j * n);
    replicated_mmult(A, flat.data(), x.size(), out.data());
    y.assign(x.size(), Vector<double>(n));
    for (std::size_t j = 0; j < x.size(); ++j)
      std::copy(out.begin() + j * n, out.begin() + (j + 1) * n, y[j].begin());
  }

  void
  replicated_solve(const DirectSolver                          &solver,
                   const PETScWrappers::MPI::SparseMatrix      &layout,
                   const std::vector<const Vector<double> *>   &b,
                   std::vector<Vector<double>>                 &x)
  {
    // one MUMPS pass over the factors for the whole block
    const auto     range   = layout.local_range();
    const PetscInt n_local = range.second - range.first, n = layout.m(), m = b.size();
    const MPI_Comm comm    = layout.get_mpi_communicator();
    x.assign(m, Vector<double>(n));
    if (m == 0)
      return;
    Mat B, X;
    MatCreateDense(comm, n_local, PETSC_DECIDE, n, m, nullptr, &B);
    MatCreateDense(comm, n_local, PETSC_DECIDE, n, m, nullptr, &X);
    PetscScalar *a;
    PetscInt     ld;
    MatDenseGetLDA(B, &ld);
    MatDenseGetArray(B, &a);
    for (PetscInt j = 0; j < m; ++j)
      for (PetscInt i = 0; i < n_local; ++i)
        a[j * ld + i] = (*b[j])[range.first + i];
    MatDenseRestoreArray(B, &a);
    MatAssemblyBegin(B, MAT_FINAL_ASSEMBLY);
    MatAssemblyEnd(B, MAT_FINAL_ASSEMBLY);
    solver.solve(X, B);
    gather_columns(X, n_local, m, comm, [&](const PetscInt j) { return x[j].data(); });
    MatDestroy(&B);
    MatDestroy(&X);
  }

} // namespace rotorfit
