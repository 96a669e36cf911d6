#include <rotorfit/linear_algebra/replicated_vectors.h>

#include <deal.II/base/mpi.h>

namespace rotorfit
{
  using namespace dealii;

  void
  replicated_scatter(const Vector<double> &x, const std::size_t offset, PETScWrappers::MPI::Vector &v)
  {
    PetscScalar *a;
    VecGetArray(v, &a);
    const auto range = v.local_range();
    for (auto i = range.first; i < range.second; ++i)
      a[i - range.first] = x[offset + i];
    VecRestoreArray(v, &a);
  }

  void
  replicated_gather(const PETScWrappers::MPI::Vector &v, Vector<double> &x, const std::size_t offset)
  {
    const MPI_Comm     comm  = v.get_mpi_communicator();
    const unsigned int ranks = Utilities::MPI::n_mpi_processes(comm);
    const auto         range = v.local_range();
    const int          local = range.second - range.first;
    std::vector<int>   counts(ranks), displs(ranks);
    MPI_Allgather(&local, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
    for (unsigned int r = 1; r < ranks; ++r)
      displs[r] = displs[r - 1] + counts[r - 1];
    const PetscScalar *a;
    VecGetArrayRead(v, &a);
    MPI_Allgatherv(a, local, MPI_DOUBLE, x.data() + offset, counts.data(), displs.data(),
                   MPI_DOUBLE, comm);
    VecRestoreArrayRead(v, &a);
  }

  void
  replicated_vmult(const PETScWrappers::MPI::SparseMatrix &A,
                   const Vector<double>                   &x,
                   Vector<double>                         &y,
                   const bool                              transpose)
  {
    DistributedWork work(A);
    replicated_scatter(x, 0, work.a);
    if (transpose)
      A.Tvmult(work.b, work.a);
    else
      A.vmult(work.b, work.a);
    y.reinit(x.size(), true);
    replicated_gather(work.b, y, 0);
  }

  void
  replicated_vmult(const PETScWrappers::MPI::SparseMatrix &A,
                   const ComplexVector                    &x,
                   ComplexVector                          &y,
                   const bool                              transpose)
  {
    replicated_vmult(A, x.re, y.re, transpose);
    replicated_vmult(A, x.im, y.im, transpose);
  }

  void
  replicated_solve(const DirectSolver                     &solver,
                   const PETScWrappers::MPI::SparseMatrix &layout,
                   const Vector<double>                   &b,
                   Vector<double>                         &x)
  {
    DistributedWork work(layout);
    replicated_scatter(b, 0, work.a);
    solver.solve(work.b, work.a);
    x.reinit(b.size(), true);
    replicated_gather(work.b, x, 0);
  }
} // namespace rotorfit
