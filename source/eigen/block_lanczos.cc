#include <rotorfit/eigen/block_lanczos.h>
#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/linear_algebra/replicated_blocks.h>

#include <AnasaziBasicEigenproblem.hpp>
#include <AnasaziBlockKrylovSchurSolMgr.hpp>
#include <AnasaziEpetraAdapter.hpp>
#include <Epetra_Map.h>
#include <Epetra_MultiVector.h>
#include <Epetra_Operator.h>
#include <Epetra_SerialComm.h>

#include <algorithm>
#include <chrono>
#include <numeric>
#include <random>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    /// Y = S^-1 M X (or M X) on replicated Epetra columns: each block
    /// goes to the distributed product and MUMPS in one pass.
    class ReplicatedOperator : public Epetra_Operator
    {
    public:
      ReplicatedOperator(const PETScWrappers::MPI::SparseMatrix &M,
                         const DirectSolver                     *S_inverse,
                         const Epetra_Map                       &map,
                         BlockLanczosStatistics                 *statistics)
        : M(M)
        , S_inverse(S_inverse)
        , map(map)
        , statistics(statistics)
      {}

      int
      Apply(const Epetra_MultiVector &X, Epetra_MultiVector &Y) const override
      {
        const std::size_t  n = M.m();
        const unsigned int k = X.NumVectors();
        std::vector<double> x(n * k), mx(n * k);
        for (unsigned int j = 0; j < k; ++j)
          std::copy(X[j], X[j] + n, x.begin() + j * n);
        replicated_mmult(M, x.data(), k, mx.data());
        if (S_inverse != nullptr)
          {
            const auto t0 = std::chrono::steady_clock::now();
            replicated_solve(*S_inverse, M, mx.data(), k, x.data());
            statistics->solve_seconds +=
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            statistics->operator_applications += k;
            ++statistics->block_solves;
            mx.swap(x);
          }
        for (unsigned int j = 0; j < k; ++j)
          std::copy(mx.begin() + j * n, mx.begin() + (j + 1) * n, Y[j]);
        return 0;
      }

      int
      SetUseTranspose(bool) override
      {
        return -1;
      }
      int
      ApplyInverse(const Epetra_MultiVector &, Epetra_MultiVector &) const override
      {
        return -1;
      }
      double
      NormInf() const override
      {
        return -1;
      }
      const char *
      Label() const override
      {
        return S_inverse ? "S^-1 M" : "M";
      }
      bool
      UseTranspose() const override
      {
        return false;
      }
      bool
      HasNormInf() const override
      {
        return false;
      }
      const Epetra_Comm &
      Comm() const override
      {
        return map.Comm();
      }
      const Epetra_Map &
      OperatorDomainMap() const override
      {
        return map;
      }
      const Epetra_Map &
      OperatorRangeMap() const override
      {
        return map;
      }

    private:
      const PETScWrappers::MPI::SparseMatrix &M;
      const DirectSolver                     *S_inverse;
      const Epetra_Map                       &map;
      BlockLanczosStatistics                 *statistics;
    };

    /// The start block: @p block columns of uniform random entries in
    /// [-1, 1], the same on every rank (a fixed seed).
    Teuchos::RCP<Epetra_MultiVector>
    random_start(const Epetra_Map &map, const std::size_t n, const unsigned int block)
    {
      auto                                   start = Teuchos::rcp(new Epetra_MultiVector(map, block));
      std::mt19937                           random(12345);
      std::uniform_real_distribution<double> uniform(-1, 1);
      for (unsigned int j = 0; j < block; ++j)
        for (std::size_t i = 0; i < n; ++i)
          (*start)[j][i] = uniform(random);
      return start;
    }

    /// Anasazi's converged pairs into @p theta (descending) and @p z.
    void
    take_solution(const Anasazi::Eigensolution<double, Epetra_MultiVector> &solution,
                  const std::size_t                                          n,
                  std::vector<double>                                       &theta,
                  std::vector<Vector<double>>                               &z)
    {
      // (numVecs, Evals, index and Evecs agree in Anasazi; taken at their least)
      std::size_t count = std::max(solution.numVecs, 0);
      count = std::min({count, solution.Evals.size(), solution.index.size(),
                        solution.Evecs.is_null() ? std::size_t(0) :
                                                   static_cast<std::size_t>(solution.Evecs->NumVectors())});
      std::vector<std::size_t> order(count);
      std::iota(order.begin(), order.end(), 0);
      std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return solution.Evals[a].realpart > solution.Evals[b].realpart;
      });
      for (const auto k : order)
        {
          // a Hermitian problem has real eigenvalues (index 0: a real vector
          // in column k); anything else is a fault, left out
          if (solution.index[k] != 0)
            continue;
          theta.push_back(solution.Evals[k].realpart);
          z.emplace_back(n);
          std::copy((*solution.Evecs)[k], (*solution.Evecs)[k] + n, z.back().begin());
        }
    }
  } // namespace

  void
  block_lanczos(const PETScWrappers::MPI::SparseMatrix &M,
                const DirectSolver                     &S_inverse,
                const unsigned int                      nev,
                const unsigned int                      block,
                const unsigned int                      n_blocks,
                const unsigned int                      max_restarts,
                const double                            tolerance,
                std::vector<double>                    &theta,
                std::vector<Vector<double>>            &z,
                BlockLanczosStatistics                 &statistics)
  {
    using MV = Epetra_MultiVector;
    using OP = Epetra_Operator;
    theta.clear();
    z.clear();
    statistics = BlockLanczosStatistics();
    const std::size_t       n = M.m();
    // every rank runs the same iteration on whole vectors (a serial map):
    // the same start block and the same gathered products keep them equal
    const Epetra_SerialComm comm;
    const Epetra_Map        map(static_cast<int>(n), 0, comm);
    const auto              start = random_start(map, n, block);
    auto op   = Teuchos::rcp(new ReplicatedOperator(M, &S_inverse, map, &statistics));
    auto mass = Teuchos::rcp(new ReplicatedOperator(M, nullptr, map, &statistics));
    auto problem = Teuchos::rcp(new Anasazi::BasicEigenproblem<double, MV, OP>(op, mass, start));
    problem->setHermitian(true);
    problem->setNEV(nev);
    if (!problem->setProblem())
      {
        statistics.failure = "Anasazi refused the problem";
        return;
      }
    Teuchos::ParameterList list;
    list.set("Which", std::string("LM"));
    list.set("Block Size", static_cast<int>(block));
    list.set("Num Blocks", static_cast<int>(n_blocks));
    list.set("Maximum Restarts", static_cast<int>(max_restarts));
    list.set("Convergence Tolerance", tolerance);
    // Ritz values after every block: stop as soon as the wanted ones have
    // converged instead of filling the space first
    list.set("Step Size", 1);
    // ("Extra NEV Blocks" would keep more over a restart, but crashes in
    // Trilinos 13.2's SetBlock: the caller rounds nev up instead)
    list.set("Verbosity", static_cast<int>(Anasazi::Errors));
    try
      {
        Anasazi::BlockKrylovSchurSolMgr<double, MV, OP> manager(problem, list);
        statistics.converged = manager.solve() == Anasazi::Converged;
        statistics.iterations = manager.getNumIters();
      }
    catch (const std::exception &e)
      {
        statistics.failure = e.what();
        return;
      }
    take_solution(problem->getSolution(), n, theta, z);
  }
} // namespace rotorfit
