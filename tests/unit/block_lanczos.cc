// block_lanczos (include/rotorfit/eigen/block_lanczos.h), the undamped
// anchors' eigensolver: the 20 lowest modes of K z = mu M z for three
// uncoupled fixed-fixed spring chains, two of them identical (every one of
// their modes a double eigenvalue, as the bending pairs of an axisymmetric
// rotor) and one stiffer (single eigenvalues between the pairs). Reference:
// the closed form mu_j = (k / m) (2 - 2 cos(j pi / (N + 1))), both members of
// every double counted; each found mu against it (relative 1e-9) and each
// mode's residual |K z - mu M z| / (|K| |z|) (1e-9), on 1 and 2 ranks.

#include <rotorfit/eigen/block_lanczos.h>
#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/linear_algebra/matrix_pattern.h>
#include <rotorfit/linear_algebra/replicated_blocks.h>

#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>

#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/petsc_sparse_matrix.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "petsc_matrix.h"
#include "unit_check.h"

using namespace dealii;
using namespace rotorfit_unit;

namespace
{
  constexpr unsigned int N = 150;   // masses per chain
  constexpr unsigned int n = 3 * N; // chains 0 and 1 alike, chain 2 stiffer
  constexpr double       mass = 0.8, k_soft = 1.0, k_stiff = 2.3;

  double
  stiffness(const unsigned int chain)
  {
    return chain == 2 ? k_stiff : k_soft;
  }

  /// M (diagonal) or K + shift M (fixed at both ends: 2k on the diagonal,
  /// -k to each neighbour in the same chain)
  void
  make(PETScWrappers::MPI::SparseMatrix &A, const IndexSet &owned, const MPI_Comm comm,
       const bool is_mass, const double shift)
  {
    const auto neighbours = [](unsigned int i, unsigned int j) {
      return i == j || (i / N == j / N && (i + 1 == j || j + 1 == i));
    };
    make_matrix(A, n, owned, comm, neighbours, [&](unsigned int i, unsigned int j) {
      if (i == j)
        return is_mass ? mass : 2 * stiffness(i / N) + shift * mass;
      return is_mass ? 0. : -stiffness(i / N);
    });
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

  const double                     shift = 1e-3; // S = K + shift M
  PETScWrappers::MPI::SparseMatrix M, K, S;
  make(M, owned, comm, true, 0);
  make(K, owned, comm, false, 0);
  make(S, owned, comm, false, shift);
  rotorfit::DirectSolver solver;
  solver.set_type(rotorfit::DirectSolver::Type::mumps_cholesky);
  solver.factorize(S);

  std::vector<double> reference;
  for (unsigned int chain = 0; chain < 3; ++chain)
    for (unsigned int j = 1; j <= N; ++j)
      reference.push_back(stiffness(chain) / mass * (2 - 2 * std::cos(j * M_PI / (N + 1))));
  std::sort(reference.begin(), reference.end());

  const unsigned int                     nev = 20;
  std::vector<double>                    theta;
  std::vector<Vector<double>>            z;
  rotorfit::BlockLanczosStatistics       stats;
  rotorfit::block_lanczos(M, solver, nev, 6, 8, 300, 1e-10, theta, z, stats);
  if (rank == 0)
    std::printf("%u ranks: %zu modes, %u steps, %u columns in %u blocks%s%s\n", ranks, theta.size(),
                stats.iterations, stats.operator_applications, stats.block_solves,
                stats.failure.empty() ? "" : ", ", stats.failure.c_str());
  check.equal("modes returned", static_cast<unsigned int>(theta.size()), nev, "exact: as asked");
  const double norm_K = K.frobenius_norm();
  for (unsigned int j = 0; j < std::min<std::size_t>(nev, theta.size()); ++j)
    {
      const double mu = 1 / theta[j] - shift;
      std::vector<Vector<double>> Kz, Mz;
      rotorfit::replicated_mmult(K, {&z[j]}, Kz);
      rotorfit::replicated_mmult(M, {&z[j]}, Mz);
      Kz[0].add(-mu, Mz[0]);
      const double residual = Kz[0].l2_norm() / (norm_K * z[j].l2_norm());
      if (rank == 0)
        {
          check.relative("mode " + std::to_string(j + 1) + " mu", mu, reference[j], 1e-9,
                         "analytic: spring chain");
          check.error("mode " + std::to_string(j + 1) + " residual", residual, 1e-9,
                      "K z - mu M z, analytic zero");
        }
    }
  return check.finish();
}
