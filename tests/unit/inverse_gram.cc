// replicated_inverse_gram (include/rotorfit/eigen/damped_eigensolver.h), the
// Gram matrix G = P^T S^-1 P of the reduced model's residual blocks, with the
// shortcut of an undamped anchor: for S = K + sigma^2 M, S^-1 K V = V -
// sigma^2 S^-1 M V, so the block K V needs no back-substitution. A spring
// chain with unequal masses and springs (K tridiagonal, M diagonal), five
// columns V, the blocks [M V, D V, K V] (D diagonal): every entry of G made
// with the shortcut against G made by back-substituting every column
// (consistency of two code paths, 1e-10 of the largest entry), and its
// symmetry (analytic for a symmetric S, 1e-10). On 1 and 2 ranks.

#include <rotorfit/eigen/damped_eigensolver.h>

#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>

#include <deal.II/lac/petsc_sparse_matrix.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "petsc_matrix.h"
#include "unit_check.h"

using namespace dealii;
using namespace rotorfit_unit;

int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const MPI_Comm     comm = MPI_COMM_WORLD;
  const unsigned int rank = Utilities::MPI::this_mpi_process(comm);
  constexpr unsigned int n = 200, m = 5;
  const IndexSet     owned = owned_rows(n, comm);
  Checks             check;

  // sigma^2 of the order of the chain's eigenvalues, so that the term the
  // shortcut adds is not small against V
  const double sigma2 = 0.5;
  const auto   mass   = [](const unsigned int i) { return 1.0 + 0.5 * std::sin(0.1 * i); };
  const auto   spring = [](const unsigned int i) { return 1.0 + 0.3 * std::cos(0.07 * i); };
  const auto   chain  = [](unsigned int i, unsigned int j) { return i == j || i + 1 == j || j + 1 == i; };
  const auto   k_entry = [&](unsigned int i, unsigned int j) {
    return i == j ? spring(i) + spring(i + 1) : -spring(std::max(i, j));
  };
  PETScWrappers::MPI::SparseMatrix M, D, K, S;
  const auto diagonal = [](unsigned int i, unsigned int j) { return i == j; };
  make_matrix(M, n, owned, comm, diagonal, [&](unsigned int i, unsigned int) { return mass(i); });
  make_matrix(D, n, owned, comm, diagonal,
              [&](unsigned int i, unsigned int) { return 0.2 + 0.01 * i; });
  make_matrix(K, n, owned, comm, chain, k_entry);
  make_matrix(S, n, owned, comm, chain, [&](unsigned int i, unsigned int j) {
    return k_entry(i, j) + (i == j ? sigma2 * mass(i) : 0.);
  });
  rotorfit::DirectSolver solver;
  solver.set_type(rotorfit::DirectSolver::Type::mumps_cholesky);
  solver.factorize(S);

  std::vector<double> V(n * m), MV(n * m), DV(n * m), KV(n * m);
  for (unsigned int j = 0; j < m; ++j)
    for (unsigned int i = 0; i < n; ++i)
      V[j * n + i] = std::sin((j + 1) * M_PI * (i + 1) / (n + 1)) + 0.1 * std::cos(0.3 * i * j);
  rotorfit::replicated_mmult(M, V.data(), m, MV.data());
  rotorfit::replicated_mmult(D, V.data(), m, DV.data());
  rotorfit::replicated_mmult(K, V.data(), m, KV.data());
  const std::vector<const std::vector<double> *> blocks{&MV, &DV, &KV};

  const std::vector<double> full = rotorfit::replicated_inverse_gram(solver, M, blocks);
  const rotorfit::GramShortcut shortcut{0, 2, &V, -sigma2};
  const std::vector<double> fast = rotorfit::replicated_inverse_gram(solver, M, blocks, &shortcut);

  const unsigned int b = 3 * m;
  double largest = 0, difference = 0, asymmetry = 0;
  for (unsigned int i = 0; i < b * b; ++i)
    {
      largest    = std::max(largest, std::abs(full[i]));
      difference = std::max(difference, std::abs(fast[i] - full[i]));
    }
  for (unsigned int i = 0; i < b; ++i)
    for (unsigned int j = 0; j < b; ++j)
      asymmetry = std::max(asymmetry, std::abs(fast[i * b + j] - fast[j * b + i]));
  // (every rank checks: G is the same on all of them)
  check.equal("rank " + std::to_string(rank) + " Gram entries",
              static_cast<unsigned int>(fast.size()), b * b, "exact: 15 x 15");
  check.error("rank " + std::to_string(rank) +
                " Gram with the shortcut against every column back-substituted",
              difference / largest, 1e-10, "consistency: two code paths");
  check.error("rank " + std::to_string(rank) + " Gram with the shortcut, symmetry",
              asymmetry / largest, 1e-10, "analytic: P^T S^-1 P for a symmetric S");
  return check.finish();
}
