// add_subset (include/rotorfit/linear_algebra/matrix_pattern.h): Y += a X
// for a matrix X whose pattern is a subset of Y's, as the eigenproblem adds
// M, C and K_sigma (one component with itself) into the full-pattern
// tangent. Every entry of Y against y_ij + a x_ij computed entry by entry
// (exact arithmetic, same operations: tolerance 0), on one rank or several
// (then rows of X reach into other ranks' columns: PETSc's off-diagonal
// block, whose columns each matrix numbers its own way). An entry of X
// outside Y's pattern is refused.

#include <rotorfit/linear_algebra/matrix_pattern.h>

#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>

#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/petsc_sparse_matrix.h>

#include <stdexcept>

#include "petsc_matrix.h"
#include "unit_check.h"

using namespace dealii;
using namespace rotorfit_unit;

namespace
{
  constexpr unsigned int n = 24;

  // a fixed, irregular coupling (both patterns symmetric in shape)
  bool
  in_y(const unsigned int i, const unsigned int j)
  {
    return i == j || (i * 7 + j * 7 + i * j) % 3 != 0;
  }
  bool
  in_x(const unsigned int i, const unsigned int j)
  {
    // (columns 3, 8, 13, ... only on the diagonal: the off-diagonal blocks
    // of X and Y then number their columns differently)
    return i == j || (in_y(i, j) && (i + j) % 2 == 0 && j % 5 != 3);
  }
  double
  y_value(const unsigned int i, const unsigned int j)
  {
    return 1.0 + 0.37 * i - 0.11 * j + 1e-3 * i * j;
  }
  double
  x_value(const unsigned int i, const unsigned int j)
  {
    return -2.5 + 0.013 * i * i + 0.7 * j;
  }

  void
  make(PETScWrappers::MPI::SparseMatrix &A, const IndexSet &owned, const MPI_Comm comm,
       bool (*pattern)(unsigned int, unsigned int), double (*value)(unsigned int, unsigned int))
  {
    make_matrix(A, n, owned, comm, pattern, value);
  }
} // namespace

int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const MPI_Comm     comm  = MPI_COMM_WORLD;
  const unsigned int ranks = Utilities::MPI::n_mpi_processes(comm),
                     rank  = Utilities::MPI::this_mpi_process(comm);
  const IndexSet     owned = owned_rows(n, comm);
  Checks             check;

  PETScWrappers::MPI::SparseMatrix Y, X;
  make(Y, owned, comm, in_y, y_value);
  make(X, owned, comm, in_x, x_value);
  const double a = -0.6180339887;
  rotorfit::add_subset(Y, a, X);
  double       worst   = 0;
  unsigned int entries = 0;
  for (const auto i : owned)
    for (unsigned int j = 0; j < n; ++j)
      if (in_y(i, j))
        {
          const double expected = y_value(i, j) + (in_x(i, j) ? a * x_value(i, j) : 0.);
          worst = std::max(worst, std::abs(Y.el(i, j) - expected));
          ++entries;
        }
  worst                      = Utilities::MPI::max(worst, comm);
  const unsigned int added   = X.n_nonzero_elements(); // (collective)
  if (rank == 0)
    std::printf("%u ranks, %u entries of Y on rank 0, %u of X added\n", ranks, entries, added);
  check.error("every entry of Y + a X, against y_ij + a x_ij entry by entry", worst, 0.,
              "exact: the same operations");

  // X with an entry Y has no place for
  PETScWrappers::MPI::SparseMatrix Z;
  make(Z, owned, comm, [](unsigned int i, unsigned int j) { return i == j || !in_y(i, j); },
       x_value);
  bool refused = false;
  try
    {
      rotorfit::add_subset(Y, 1., Z);
    }
  catch (const std::logic_error &)
    {
      refused = true;
    }
  check.equal("an entry outside the target's pattern refused",
              Utilities::MPI::min(refused ? 1 : 0, comm), 1, "exact");
  return check.finish();
}
