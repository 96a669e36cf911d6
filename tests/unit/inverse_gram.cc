// replicated_inverse_gram (include/rotorfit/linear_algebra/replicated_blocks.h), the
// Gram matrix G = P^T S^-1 P of the reduced model's residual blocks, with the
// shortcut of an undamped anchor: for S = K + sigma^2 M, S^-1 K V = V -
// sigma^2 S^-1 M V, so the block K V needs no back-substitution. A spring
// chain with unequal masses and springs (K tridiagonal, M diagonal), 40
// columns V, the blocks [M V, D V, B V, Z V, B2 V, K V] (D diagonal; B and
// B2 diagonal on 20 of the 200 rows each, 5 of them shared, like bearings'
// damping, so that B V and B2 V are kept by their nonzero rows, RowBlock;
// Z = 0, kept as nothing): every entry of G, with and without the shortcut,
// against G made here column by column from the full vectors (consistency
// of two code paths, 1e-10 of the largest entry), its symmetry (analytic
// for a symmetric S, 1e-10), replicated_gram's P^T P against plain dot
// products (1e-12), and B V and B2 V kept by 20 rows, Z V by none (exact),
// B V again after adding and
// subtracting D V (and equal to B V to rounding, 1e-15). On 1 and 2 ranks.

#include <rotorfit/linear_algebra/replicated_blocks.h>
#include <rotorfit/linear_algebra/replicated_blocks.h>

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
  // 40 columns a block: more than the 32 back-substituted at a time
  constexpr unsigned int n = 200, m = 40;
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
  PETScWrappers::MPI::SparseMatrix M, D, B, B2, K, S;
  // two "bearings" whose rows differ in part (B2 shares 5 of B's 20 rows)
  const auto at_bearing  = [](unsigned int i) { return i < 10 || (i >= 150 && i < 160); };
  const auto at_bearing2 = [](unsigned int i) { return (i >= 5 && i < 15) || (i >= 100 && i < 110); };
  const auto diagonal = [](unsigned int i, unsigned int j) { return i == j; };
  make_matrix(M, n, owned, comm, diagonal, [&](unsigned int i, unsigned int) { return mass(i); });
  make_matrix(D, n, owned, comm, diagonal,
              [&](unsigned int i, unsigned int) { return 0.2 + 0.01 * i; });
  make_matrix(B, n, owned, comm, diagonal,
              [&](unsigned int i, unsigned int) { return at_bearing(i) ? 3.0 + 0.1 * i : 0.; });
  make_matrix(B2, n, owned, comm, diagonal,
              [&](unsigned int i, unsigned int) { return at_bearing2(i) ? 1.0 + 0.05 * i : 0.; });
  make_matrix(K, n, owned, comm, chain, k_entry);
  make_matrix(S, n, owned, comm, chain, [&](unsigned int i, unsigned int j) {
    return k_entry(i, j) + (i == j ? sigma2 * mass(i) : 0.);
  });
  rotorfit::DirectSolver solver;
  solver.set_type(rotorfit::DirectSolver::Type::mumps_cholesky);
  solver.factorize(S);

  std::vector<double> V(n * m), MV(n * m), DV(n * m), BV(n * m), B2V(n * m), KV(n * m),
    ZV(n * m, 0.);
  for (unsigned int j = 0; j < m; ++j)
    for (unsigned int i = 0; i < n; ++i)
      V[j * n + i] = std::sin((j + 1) * M_PI * (i + 1) / (n + 1)) + 0.1 * std::cos(0.3 * i * j);
  rotorfit::replicated_mmult(M, V.data(), m, MV.data());
  rotorfit::replicated_mmult(D, V.data(), m, DV.data());
  rotorfit::replicated_mmult(B, V.data(), m, BV.data());
  rotorfit::replicated_mmult(B2, V.data(), m, B2V.data());
  rotorfit::replicated_mmult(K, V.data(), m, KV.data());
  // (a block zero everywhere, Z V, keeps nothing and has no columns)
  const std::vector<const std::vector<double> *> plain{&MV, &DV, &BV, &B2V, &KV};
  const std::string on_rank = "rank " + std::to_string(rank) + " ";

  // the reference: every column as a full vector, back-substituted alone
  const unsigned int          b = 5 * m;
  std::vector<Vector<double>> columns;
  for (const auto *P : plain)
    for (unsigned int j = 0; j < m; ++j)
      columns.emplace_back(P->begin() + j * n, P->begin() + (j + 1) * n);
  std::vector<const Vector<double> *> rhs;
  for (const auto &c : columns)
    rhs.push_back(&c);
  std::vector<Vector<double>> solved;
  rotorfit::replicated_solve(solver, M, rhs, solved);
  std::vector<double> reference(b * b), plain_gram(b * b);
  for (unsigned int i = 0; i < b; ++i)
    for (unsigned int j = 0; j < b; ++j)
      {
        reference[i + j * b]  = columns[i] * solved[j];
        plain_gram[i + j * b] = columns[i] * columns[j];
      }

  std::vector<rotorfit::RowBlock> kept(6);
  {
    const std::vector<const std::vector<double> *> all{&MV, &DV, &BV, &ZV, &B2V, &KV};
    for (unsigned int k = 0; k < 6; ++k)
      kept[k].assign(std::vector<double>(*all[k]), n);
  }
  check.equal(on_rank + "columns kept of Z V", static_cast<unsigned int>(kept[3].n_columns()), 0u,
              "exact: zero everywhere");
  check.equal(on_rank + "rows kept of B2 V", static_cast<unsigned int>(kept[4].n_rows()), 20u,
              "exact: B2 is nonzero on 20 rows");
  check.equal(on_rank + "rows kept of B V", static_cast<unsigned int>(kept[2].n_rows()), 20u,
              "exact: B is nonzero on 20 rows");
  check.equal(on_rank + "rows kept of M V", static_cast<unsigned int>(kept[0].n_rows()), n,
              "exact: dense");
  {
    // (D V + B V) - D V: dense on the way, kept by B's rows again at the end
    rotorfit::RowBlock sum;
    sum.assign(std::vector<double>(DV), n);
    sum.add(1., kept[2]);
    sum.add(-1., kept[1]);
    double difference = 0, largest_bv = 0;
    for (unsigned int j = 0; j < m; ++j)
      {
        std::vector<double> column(n);
        sum.expand_column(j, column.data());
        for (unsigned int i = 0; i < n; ++i)
          {
            difference = std::max(difference, std::abs(column[i] - BV[j * n + i]));
            largest_bv = std::max(largest_bv, std::abs(BV[j * n + i]));
          }
      }
    check.equal(on_rank + "rows kept of (D V + B V) - D V",
                static_cast<unsigned int>(sum.n_rows()), 20u, "exact: (d + 0) - d = 0");
    check.error(on_rank + "(D V + B V) - D V against B V", difference / largest_bv, 1e-15,
                "rounding of (d + b) - d");
  }
  // dense, row-kept, empty and row-kept with other rows, dense: in the
  // order the chunks must handle
  const std::vector<const rotorfit::RowBlock *> blocks{&kept[0], &kept[1], &kept[2],
                                                       &kept[3], &kept[4], &kept[5]};
  const std::vector<double> full = rotorfit::replicated_inverse_gram(solver, M, blocks);
  const rotorfit::GramShortcut shortcut{0, 5, &V, -sigma2};
  const std::vector<double> fast = rotorfit::replicated_inverse_gram(solver, M, blocks, &shortcut);
  const std::vector<double> gram = rotorfit::replicated_gram(blocks, comm);

  double largest = 0, largest_plain = 0, difference = 0, difference_fast = 0, asymmetry = 0,
         difference_plain = 0;
  for (unsigned int i = 0; i < b * b; ++i)
    {
      largest          = std::max(largest, std::abs(reference[i]));
      largest_plain    = std::max(largest_plain, std::abs(plain_gram[i]));
      difference       = std::max(difference, std::abs(full[i] - reference[i]));
      difference_fast  = std::max(difference_fast, std::abs(fast[i] - reference[i]));
      difference_plain = std::max(difference_plain, std::abs(gram[i] - plain_gram[i]));
    }
  for (unsigned int i = 0; i < b; ++i)
    for (unsigned int j = 0; j < b; ++j)
      asymmetry = std::max(asymmetry, std::abs(fast[i * b + j] - fast[j * b + i]));
  // (every rank checks: G is the same on all of them)
  check.equal(on_rank + "Gram entries", static_cast<unsigned int>(fast.size()), b * b,
              "exact: 200 x 200");
  check.error(on_rank + "Gram against the full columns back-substituted one by one",
              difference / largest, 1e-10, "consistency: two code paths");
  check.error(on_rank + "Gram with the shortcut against the full columns",
              difference_fast / largest, 1e-10, "consistency: two code paths");
  check.error(on_rank + "Gram with the shortcut, symmetry", asymmetry / largest, 1e-10,
              "analytic: P^T S^-1 P for a symmetric S");
  check.error(on_rank + "P^T P against plain dot products", difference_plain / largest_plain, 1e-12,
              "consistency: two code paths");
  return check.finish();
}
