// DirectSolver::update (include/rotorfit/linear_algebra/direct_solver.h): the
// solves of a factorised S with a low-rank change of its tie springs,
// (S + U diag(s) U^T)^-1 by the Woodbury identity, as an undamped anchor uses
// it where a fit opens pair by pair. S is a spring chain with unequal masses
// (K + sigma^2 M) plus stiff ties (1000 x the chain's springs, as the contact
// penalty) between nodes five apart; the update releases some ties, stiffens
// one and adds two new ones. Its solves (one vector, and a block through
// replicated_solve) against an LDL^T of the changed matrix itself, relative
// 1e-9 (consistency of two code paths); a second update on the same
// factorisation (one released tie more: one back-substitution, the other
// columns kept) the same, and a third (a released tie tied again: its column
// dropped from the middle, the others moved up, no back-substitution); an
// empty update returns to S exactly. On 1 and 2 ranks.

#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/linear_algebra/direct_solver.h>
#include <rotorfit/linear_algebra/replicated_blocks.h>

#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>

#include <deal.II/lac/petsc_sparse_matrix.h>
#include <deal.II/lac/petsc_vector.h>
#include <deal.II/lac/vector.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "petsc_matrix.h"
#include "unit_check.h"

using namespace dealii;
using namespace rotorfit_unit;

namespace
{
  constexpr unsigned int n = 300;
  constexpr double       eps = 1000;

  /// The matrix with the ties @p ties (node pair -> spring).
  void
  make_tied(PETScWrappers::MPI::SparseMatrix                          &A,
            const std::map<std::pair<unsigned int, unsigned int>, double> &ties,
            const IndexSet &owned, const MPI_Comm comm)
  {
    const auto mass   = [](const unsigned int i) { return 1.0 + 0.5 * std::sin(0.1 * i); };
    const auto spring = [](const unsigned int i) { return 1.0 + 0.3 * std::cos(0.07 * i); };
    // the pattern of every tie either matrix may hold
    const auto tie_pattern = [](unsigned int i, unsigned int j) {
      const unsigned int a = std::min(i, j), b = std::max(i, j);
      return (b == a + 5 && a % 10 == 0) || (a == 7 && b == 50) || (a == 100 && b == 150);
    };
    make_matrix(
      A, n, owned, comm,
      [&](unsigned int i, unsigned int j) {
        return i == j || i + 1 == j || j + 1 == i || tie_pattern(i, j);
      },
      [&](unsigned int i, unsigned int j) {
        double v = 0;
        if (i == j)
          v = spring(i) + spring(i + 1) + 0.5 * mass(i);
        else if (i + 1 == j || j + 1 == i)
          v = -spring(std::max(i, j));
        for (const auto &[p, s] : ties)
          {
            if (i == j && (i == p.first || i == p.second))
              v += s;
            if ((i == p.first && j == p.second) || (i == p.second && j == p.first))
              v -= s;
          }
        return v;
      });
  }

  /// The change from @p before to @p after as update columns (e_a - e_b).
  std::vector<rotorfit::DirectSolver::UpdateColumn>
  changes(const std::map<std::pair<unsigned int, unsigned int>, double> &before,
          const std::map<std::pair<unsigned int, unsigned int>, double> &after)
  {
    std::map<std::pair<unsigned int, unsigned int>, double> d;
    for (const auto &[p, s] : after)
      d[p] += s;
    for (const auto &[p, s] : before)
      d[p] -= s;
    std::vector<rotorfit::DirectSolver::UpdateColumn> columns;
    for (const auto &[p, s] : d)
      if (s != 0)
        {
          rotorfit::DirectSolver::UpdateColumn u;
          u.key     = p.first * n + p.second;
          u.spring  = s;
          u.entries = {{PetscInt(p.first), 1.}, {PetscInt(p.second), -1.}};
          columns.push_back(u);
        }
    return columns;
  }
} // namespace

int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const MPI_Comm     comm = MPI_COMM_WORLD;
  const unsigned int rank = Utilities::MPI::this_mpi_process(comm);
  const IndexSet     owned = owned_rows(n, comm);
  Checks             check;
  const std::string  on = "rank " + std::to_string(rank) + ": ";

  std::map<std::pair<unsigned int, unsigned int>, double> ties;
  for (unsigned int a = 0; a + 5 < n; a += 10)
    ties[{a, a + 5}] = eps;
  auto first = ties; // three released, one stiffer, two new
  for (const unsigned int a : {10u, 20u, 30u})
    first.erase({a, a + 5});
  first[{40, 45}] = 1.5 * eps;
  first[{7, 50}] = first[{100, 150}] = eps;
  auto second = first; // one more released
  second.erase({60, 65});
  auto third = second; // one released tie tied again: a column from the middle goes
  third[{20, 25}] = eps;

  PETScWrappers::MPI::SparseMatrix S, S1, S2, S3;
  make_tied(S, ties, owned, comm);
  make_tied(S1, first, owned, comm);
  make_tied(S2, second, owned, comm);
  make_tied(S3, third, owned, comm);
  rotorfit::DirectSolver solver, direct;
  for (auto *s : {&solver, &direct})
    s->set_type(rotorfit::DirectSolver::Type::mumps_cholesky);
  solver.factorize(S);

  // right-hand sides: one vector, and a block of three
  std::vector<double> B(3 * n);
  for (unsigned int j = 0; j < 3; ++j)
    for (unsigned int i = 0; i < n; ++i)
      B[j * n + i] = std::sin(0.05 * (j + 1) * i) + (i == 45 ? 1. : 0.);
  const auto vector_solve = [&](const rotorfit::DirectSolver &d) {
    PETScWrappers::MPI::Vector b(owned, comm), x(owned, comm);
    for (const auto i : owned)
      b(i) = B[i];
    b.compress(VectorOperation::insert);
    d.solve(x, b);
    std::vector<double> out(n, 0.);
    for (const auto i : owned)
      out[i] = x(i);
    MPI_Allreduce(MPI_IN_PLACE, out.data(), n, MPI_DOUBLE, MPI_SUM, comm);
    return out;
  };
  const auto block_solve = [&](const rotorfit::DirectSolver &d) {
    std::vector<double> X(3 * n);
    rotorfit::replicated_solve(d, S, B.data(), 3, X.data());
    return X;
  };
  const auto relative = [](const std::vector<double> &a, const std::vector<double> &b) {
    double d = 0, s = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
      d = std::max(d, std::abs(a[i] - b[i])), s = std::max(s, std::abs(b[i]));
    return d / s;
  };

  const std::vector<double> plain_vector = vector_solve(solver), plain_block = block_solve(solver);
  const unsigned int        operators    = solver.n_operators();
  const auto                compare = [&](const std::string &what,
                           const std::vector<rotorfit::DirectSolver::UpdateColumn> &columns,
                           PETScWrappers::MPI::SparseMatrix &changed) {
    check.equal(on + what + ": update accepted", static_cast<unsigned int>(solver.update(columns)),
                1u, "exact");
    direct.factorize(changed);
    check.error(on + what + ": one vector against the LDL^T of the changed matrix",
                relative(vector_solve(solver), vector_solve(direct)), 1e-9,
                "consistency: two code paths");
    check.error(on + what + ": a block of three against the LDL^T of the changed matrix",
                relative(block_solve(solver), block_solve(direct)), 1e-9,
                "consistency: two code paths");
  };
  compare("first update (6 springs)", changes(ties, first), S1);
  const unsigned int solves = solver.n_solves();
  compare("second update (7 springs, 6 kept)", changes(ties, second), S2);
  // (the comparison's own solves: one vector and a block of three)
  check.equal(on + "back-substitutions of the second update",
              solver.n_solves() - solves - 4, 1u, "exact: its one new spring");
  check.equal(on + "springs of the second update",
              static_cast<unsigned int>(solver.n_update_columns()), 7u, "exact");
  const unsigned int solves_before_third = solver.n_solves();
  compare("third update (6 springs, all kept, one dropped from the middle)", changes(ties, third),
          S3);
  check.equal(on + "back-substitutions of the third update",
              solver.n_solves() - solves_before_third - 4, 0u, "exact: every column kept");
  check.equal(on + "operators counted", solver.n_operators(), operators + 3, "exact");
  // no update: S itself again, to the last bit
  solver.update({});
  check.error(on + "empty update: one vector as before", relative(vector_solve(solver), plain_vector),
              0., "exact");
  check.error(on + "empty update: a block as before", relative(block_solve(solver), plain_block), 0.,
              "exact");
  return check.finish();
}
