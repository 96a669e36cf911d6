#include <rotorfit/eigen/shift_invert.h>

#include <algorithm>
#include <chrono>

namespace rotorfit
{
  using namespace dealii;

  StateMass::StateMass(const PETScWrappers::MPI::SparseMatrix &M, const std::size_t n)
    : M(M)
    , n(n)
    , work(M)
  {}

  void
  StateMass::vmult(Vector<double> &y, const Vector<double> &x) const
  {
    std::copy(x.begin(), x.begin() + n, y.begin());
    replicated_scatter(x, n, work.a);
    M.vmult(work.b, work.a);
    replicated_gather(work.b, y, n);
  }

  CompanionShiftInvert::CompanionShiftInvert(const PETScWrappers::MPI::SparseMatrix &M,
                                             const PETScWrappers::MPI::SparseMatrix &C,
                                             const DirectSolver                     &Q_inverse,
                                             const double                            sigma,
                                             const std::size_t                       n,
                                             unsigned int                           &applications)
    : M(M)
    , C(C)
    , Q_inverse(Q_inverse)
    , sigma(sigma)
    , n(n)
    , work(M)
    , applications(applications)
  {}

  void
  CompanionShiftInvert::vmult(Vector<double> &y, const Vector<double> &r) const
  {
    replicated_scatter(r, 0, work.a); // r1
    M.vmult(work.b, work.a);          // M r1
    work.b *= sigma;
    C.vmult_add(work.b, work.a);      // (C + sigma M) r1
    replicated_scatter(r, n, work.c); // r2
    work.b += work.c;
    const auto t0 = std::chrono::steady_clock::now();
    Q_inverse.solve(work.c, work.b);
    solve_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    work.c *= -1.; // y1
    replicated_gather(work.c, y, 0);
    for (std::size_t i = 0; i < n; ++i)
      y[n + i] = r[i] + sigma * y[i];
    ++applications;
  }

  ReplicatedMass::ReplicatedMass(const PETScWrappers::MPI::SparseMatrix &M)
    : M(M)
    , work(M)
  {}

  void
  ReplicatedMass::vmult(Vector<double> &y, const Vector<double> &x) const
  {
    replicated_scatter(x, 0, work.a);
    M.vmult(work.b, work.a);
    replicated_gather(work.b, y, 0);
  }

  ReplicatedInverse::ReplicatedInverse(const DirectSolver                     &S_inverse,
                                       const PETScWrappers::MPI::SparseMatrix &layout,
                                       unsigned int                           &applications)
    : S_inverse(S_inverse)
    , work(layout)
    , applications(applications)
  {}

  void
  ReplicatedInverse::vmult(Vector<double> &y, const Vector<double> &x) const
  {
    replicated_scatter(x, 0, work.a);
    const auto t = std::chrono::steady_clock::now();
    S_inverse.solve(work.b, work.a);
    solve_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
    replicated_gather(work.b, y, 0);
    ++applications;
  }
} // namespace rotorfit
