#include <rotorfit/base/patterns.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/eigen/block_lanczos.h>
#include <rotorfit/linear_algebra/matrix_pattern.h>

#include <deal.II/base/mpi.h>

#include <deal.II/lac/arpack_solver.h>
#include <deal.II/lac/solver_control.h>

#include <algorithm>
#include <chrono>
#include <sstream>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace rotorfit
{
  using namespace dealii;

  namespace
  {
    /// Copy entries [offset, offset + n) of a replicated vector into the
    /// locally owned part of @p v.
    void
    scatter(const Vector<double> &x, const std::size_t offset, PETScWrappers::MPI::Vector &v)
    {
      PetscScalar *a;
      VecGetArray(v, &a);
      const auto range = v.local_range();
      for (auto i = range.first; i < range.second; ++i)
        a[i - range.first] = x[offset + i];
      VecRestoreArray(v, &a);
    }

    /// Gather a distributed vector into entries [offset, offset + n) of a
    /// replicated one.
    void
    gather(const PETScWrappers::MPI::Vector &v, Vector<double> &x, const std::size_t offset)
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
      MPI_Allgatherv(a, local, MPI_DOUBLE, x.data() + offset, counts.data(),
                     displs.data(), MPI_DOUBLE, comm);
      VecRestoreArrayRead(v, &a);
    }

    /// Work vectors in the matrices' layout.
    struct Work
    {
      explicit Work(const PETScWrappers::MPI::SparseMatrix &A)
        : owned(A.locally_owned_range_indices())
        , comm(A.get_mpi_communicator())
        , a(owned, comm)
        , b(owned, comm)
        , c(owned, comm)
      {}
      IndexSet                   owned;
      MPI_Comm                   comm;
      PETScWrappers::MPI::Vector a, b, c;
    };

    /// B = diag(I, M) on state vectors (x1, x2).
    class StateMass
    {
    public:
      StateMass(const PETScWrappers::MPI::SparseMatrix &M, const std::size_t n)
        : M(M)
        , n(n)
        , work(M)
      {}

      void
      vmult(Vector<double> &y, const Vector<double> &x) const
      {
        std::copy(x.begin(), x.begin() + n, y.begin());
        scatter(x, n, work.a);
        M.vmult(work.b, work.a);
        gather(work.b, y, n);
      }

    private:
      const PETScWrappers::MPI::SparseMatrix &M;
      std::size_t                              n;
      mutable Work                             work;
    };

    /// (A - sigma B)^{-1} r of the first companion form (doc/theory.md 8.2):
    /// y1 = -Q^{-1} [r2 + (C + sigma M) r1], y2 = r1 + sigma y1.
    class ShiftInvert
    {
    public:
      ShiftInvert(const PETScWrappers::MPI::SparseMatrix &M,
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
      vmult(Vector<double> &y, const Vector<double> &r) const
      {
        scatter(r, 0, work.a);        // r1
        M.vmult(work.b, work.a);      // M r1
        work.b *= sigma;
        C.vmult_add(work.b, work.a);  // (C + sigma M) r1
        scatter(r, n, work.c);        // r2
        work.b += work.c;
        const auto t0 = std::chrono::steady_clock::now();
        Q_inverse.solve(work.c, work.b);
        solve_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        work.c *= -1.;                // y1
        gather(work.c, y, 0);
        for (std::size_t i = 0; i < n; ++i)
          y[n + i] = r[i] + sigma * y[i];
        ++applications;
      }

    private:
      const PETScWrappers::MPI::SparseMatrix &M, &C;
      const DirectSolver                     &Q_inverse;
      double                                  sigma;
      std::size_t                             n;
      mutable Work                            work;
      unsigned int                           &applications;

    public:
      mutable double solve_seconds = 0;
    };

    double
    norm(const ComplexVector &v)
    {
      return std::sqrt(v.re.norm_sqr() + v.im.norm_sqr());
    }
  } // namespace

  unsigned int
  DampedEigensolver::krylov_size(const unsigned int nev, const double growth) const
  {
    return std::max<unsigned int>(nev + 3, std::ceil(growth * krylov_factor * nev));
  }

  void
  replicated_vmult(const PETScWrappers::MPI::SparseMatrix &A,
                   const Vector<double>                   &x,
                   Vector<double>                         &y,
                   const bool                              transpose)
  {
    Work work(A);
    scatter(x, 0, work.a);
    if (transpose)
      A.Tvmult(work.b, work.a);
    else
      A.vmult(work.b, work.a);
    y.reinit(x.size(), true);
    gather(work.b, y, 0);
  }

  void
  replicated_solve(const DirectSolver                     &solver,
                   const PETScWrappers::MPI::SparseMatrix &layout,
                   const Vector<double>                   &b,
                   Vector<double>                         &x)
  {
    Work work(layout);
    scatter(b, 0, work.a);
    solver.solve(work.b, work.a);
    x.reinit(b.size(), true);
    gather(work.b, x, 0);
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
  DampedEigensolver::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Eigenproblem");
    prm.declare_entry("Shift",
                      "10",
                      patterns::Positive(),
                      "Real shift sigma of the shift-invert operator [Hz], > 0 "
                      "(keeps Q(sigma) regular for free bodies). Modes come "
                      "ordered by distance from it; keep it below the lowest "
                      "frequency of interest.");
    prm.declare_entry("Tolerance",
                      "1e-10",
                      Patterns::Double(0.),
                      "ARPACK relative accuracy of the Ritz values [-] (0: "
                      "machine precision, ARPACK's own meaning).");
    prm.declare_entry("Krylov size factor",
                      "2",
                      Patterns::Double(1.),
                      "Arnoldi vectors = this times the number of eigenvalues "
                      "requested (at least that number + 2) [-].");
    prm.declare_entry("Maximum restarts",
                      "300",
                      Patterns::Integer(1),
                      "Cap on ARPACK's implicit restarts per speed.");
    prm.declare_entry("Lanczos block size",
                      "6",
                      Patterns::Integer(1),
                      "Columns back-substituted together in the undamped "
                      "anchors' symmetric Lanczos (Reduced anchors = undamped): "
                      "above 1 Anasazi's block Krylov-Schur (one pass over the "
                      "factors per block), with ARPACK on the same factors "
                      "where it finds too few modes; 1: ARPACK's "
                      "single-vector Lanczos [-].");
    prm.declare_entry("Lanczos tolerance",
                      "1e-6",
                      patterns::Positive(),
                      "Convergence tolerance of the undamped anchors' Lanczos run "
                      "(relative residual of each mode of S^-1 M; ARPACK's relative "
                      "accuracy with Lanczos block size = 1) [-]. The modes only "
                      "span the reduced basis (their backward errors stay near "
                      "1e-9): every reduced solve is checked on the full "
                      "matrices against Reduced tolerance.");
    prm.declare_entry("Backward error limit",
                      "1e-6",
                      patterns::Positive(),
                      "A mode whose backward error ||Q(lambda) phi|| / "
                      "((|lambda|^2 ||M|| + |lambda| ||C|| + ||K||) ||phi||) "
                      "exceeds this is unconverged: the run stops with an "
                      "error, keeping the speeds already done [-].");
    prm.leave_subsection();
  }

  void
  DampedEigensolver::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Eigenproblem");
    // > 0 by its pattern: with sigma = 0 a free body makes Q(sigma) singular
    sigma = 2 * M_PI * prm.get_double("Shift");
    tolerance          = prm.get_double("Tolerance");
    krylov_factor      = prm.get_double("Krylov size factor");
    max_restarts       = prm.get_integer("Maximum restarts");
    lanczos_block      = prm.get_integer("Lanczos block size");
    lanczos_tolerance  = prm.get_double("Lanczos tolerance");
    max_backward_error = prm.get_double("Backward error limit");
    prm.leave_subsection();
    solver.set_type(DirectSolver::Type::mumps_lu); // Q(sigma) is unsymmetric (G)
  }

  BackwardError::BackwardError(const PETScWrappers::MPI::SparseMatrix &M,
                               const PETScWrappers::MPI::SparseMatrix &C,
                               const PETScWrappers::MPI::SparseMatrix &K)
    : M(M)
    , C(C)
    , K(K)
    , norm_M(M.frobenius_norm())
    , norm_C(C.frobenius_norm())
    , norm_K(K.frobenius_norm())
  {}

  double
  BackwardError::operator()(const std::complex<double> l,
                            const ComplexVector       &phi,
                            ComplexVector             &Mp,
                            ComplexVector             *residual,
                            std::complex<double>      *derivative) const
  {
    ComplexVector Cp, Kp;
    replicated_vmult(M, phi, Mp);
    replicated_vmult(C, phi, Cp);
    replicated_vmult(K, phi, Kp);
    return (*this)(l, phi, Mp, Cp, Kp, residual, derivative);
  }

  double
  BackwardError::from_residual(const std::complex<double> l,
                               const ComplexVector       &phi,
                               const ComplexVector       &r) const
  {
    return relative(l, phi, std::sqrt(r.re.norm_sqr() + r.im.norm_sqr()));
  }

  double
  BackwardError::relative(const std::complex<double> l,
                          const ComplexVector       &phi,
                          const double               norm_r) const
  {
    const double scale = this->scale(l) * std::sqrt(phi.re.norm_sqr() + phi.im.norm_sqr());
    return scale > 0 ? norm_r / scale : 0.;
  }

  double
  BackwardError::mismatch(const ComplexVector &phi,
                          const ComplexVector &Mp,
                          const ComplexVector &Cp,
                          const ComplexVector &Kp,
                          const bool           transpose) const
  {
    double worst = 0;
    const std::pair<const PETScWrappers::MPI::SparseMatrix *, const ComplexVector *> given[3] = {
      {&M, &Mp}, {&C, &Cp}, {&K, &Kp}};
    for (const auto &[A, Ap] : given)
      {
        ComplexVector a;
        replicated_vmult(*A, phi, a, transpose);
        const double norm = std::sqrt(a.re.norm_sqr() + a.im.norm_sqr());
        a.re -= Ap->re;
        a.im -= Ap->im;
        const double d = std::sqrt(a.re.norm_sqr() + a.im.norm_sqr());
        if (!std::isfinite(d))
          return std::numeric_limits<double>::infinity();
        if (d > 0)
          worst = std::max(worst, d / norm);
      }
    return worst;
  }

  double
  BackwardError::operator()(const std::complex<double> l,
                            const ComplexVector       &phi,
                            const ComplexVector       &Mp,
                            const ComplexVector       &Cp,
                            const ComplexVector       &Kp,
                            ComplexVector             *residual,
                            std::complex<double>      *derivative) const
  {
    const std::size_t          n  = phi.re.size();
    const std::complex<double> l2 = l * l;
    Vector<double>             re(n), im(n);
    for (std::size_t i = 0; i < n; ++i)
      {
        const std::complex<double> r = l2 * std::complex<double>(Mp.re[i], Mp.im[i]) +
                                       l * std::complex<double>(Cp.re[i], Cp.im[i]) +
                                       std::complex<double>(Kp.re[i], Kp.im[i]);
        re[i] = r.real();
        im[i] = r.imag();
      }
    const double norm_r = std::sqrt(re.norm_sqr() + im.norm_sqr());
    if (derivative != nullptr)
      {
        const auto dot = [](const ComplexVector &a, const ComplexVector &b) { // a^H b
          return std::complex<double>(a.re * b.re + a.im * b.im, a.re * b.im - a.im * b.re);
        };
        *derivative = 2. * l * dot(phi, Mp) + dot(phi, Cp);
      }
    if (residual != nullptr)
      {
        residual->re = std::move(re);
        residual->im = std::move(im);
      }
    return relative(l, phi, norm_r);
  }

  namespace
  {
    /// The eigenpair of ARPACK's slot @p j (and of its partner j + 1 for a
    /// complex pair: @p j is advanced past it), with Im lambda >= 0 and
    /// |phi| = 1; false for an unconverged slot.
    /// What ARPACK returned: @p nev Ritz values and the state vectors
    /// (length 2 n) of their real and imaginary parts.
    struct RitzPairs
    {
      const std::vector<std::complex<double>> &lambda;
      const std::vector<Vector<double>>       &z;
      unsigned int                             nev;
      std::size_t                              n;
    };

    bool
    recover_pair(const RitzPairs     &ritz,
                 const BackwardError &backward_error,
                 const double         max_backward_error,
                 unsigned int        &j,
                 EigenPair           &p)
    {
      const auto &lambda = ritz.lambda;
      const auto &z      = ritz.z;
      const auto  nev    = ritz.nev;
      const auto  n      = ritz.n;
      // an unconverged slot: exactly 0 + 0i, a zero vector, or not finite
      if ((lambda[j] == std::complex<double>(0., 0.)) || !std::isfinite(lambda[j].real()) ||
          !std::isfinite(lambda[j].imag()) || !(z[j].l2_norm() > 0))
        return false;
      p.lambda = lambda[j];
      p.phi.re.reinit(n);
      p.phi.im.reinit(n);
      std::copy(z[j].begin(), z[j].begin() + n, p.phi.re.begin());
      const bool complex_pair = std::abs(lambda[j].imag()) > 1e-12 * std::abs(lambda[j]);
      if (complex_pair)
        {
          // ArpackSolver returns nev vectors: the partner of the last value
          // may be missing (one more value is always requested)
          if (j + 1 >= nev)
            {
              j = nev;
              return false;
            }
          std::copy(z[j + 1].begin(), z[j + 1].begin() + n, p.phi.im.begin());
          p.backward_error = backward_error(p.lambda, p.phi, p.m_phi);
          if (!(p.backward_error <= max_backward_error))
            {
              // the other member of the pair (ARPACK versions differ)
              ComplexVector swapped{p.phi.re, p.phi.im}, m_swapped;
              swapped.im *= -1.;
              const double other = backward_error(p.lambda, swapped, m_swapped);
              if (other < p.backward_error)
                {
                  p.phi            = swapped;
                  p.m_phi          = m_swapped;
                  p.backward_error = other;
                }
            }
          if (p.lambda.imag() < 0)
            {
              p.lambda = std::conj(p.lambda);
              p.phi.im *= -1.;
              p.m_phi.im *= -1.;
            }
          ++j; // the conjugate partner
        }
      else
        {
          p.lambda         = std::complex<double>(lambda[j].real(), 0.);
          p.backward_error = backward_error(p.lambda, p.phi, p.m_phi);
        }
      const double scale = norm(p.phi);
      if (scale > 0)
        for (auto *v : {&p.phi.re, &p.phi.im, &p.m_phi.re, &p.m_phi.im})
          *v /= scale;
      return true;
    }
  } // namespace

  void
  DampedEigensolver::factorize(const PETScWrappers::MPI::SparseMatrix &M,
                               const PETScWrappers::MPI::SparseMatrix &C,
                               PETScWrappers::MPI::SparseMatrix       &K)
  {
    // Q(sigma) = K + sigma C + sigma^2 M: K's pattern holds the others'
    add_subset(K, sigma, C);
    add_subset(K, sigma * sigma, M);
    solver.set_type(DirectSolver::Type::mumps_lu); // G makes Q unsymmetric
    const auto restore = [&]() {
      add_subset(K, -sigma * sigma, M);
      add_subset(K, -sigma, C);
    };
    try
      {
        solver.factorize(K);
      }
    catch (...)
      {
        restore();
        throw;
      }
    restore();
  }

  std::vector<DampedEigensolver::UndampedMode>
  DampedEigensolver::solve_undamped(const PETScWrappers::MPI::SparseMatrix &M,
                                    PETScWrappers::MPI::SparseMatrix       &K,
                                    const unsigned int                      n_modes,
                                    Statistics                             &stats,
                                    const bool                              factorize)
  {
    const std::size_t n = M.m();
    using clock         = std::chrono::steady_clock;
    const auto seconds  = [](const clock::time_point t0) {
      return std::chrono::duration<double>(clock::now() - t0).count();
    };
    auto t0 = clock::now();
    // S = K + sigma^2 M: symmetric (LDL^T, about half the LU's time and
    // memory) and regular with free bodies for the same reason as Q(sigma)
    // (formed in K's storage, as in factorize())
    if (factorize)
      {
        add_subset(K, sigma * sigma, M);
        solver.set_type(DirectSolver::Type::mumps_cholesky);
        try
          {
            solver.factorize(K);
          }
        catch (...)
          {
            add_subset(K, -sigma * sigma, M);
            throw;
          }
        add_subset(K, -sigma * sigma, M);
      }
    stats                       = Statistics();
    stats.factorization_seconds = seconds(t0);
    t0                          = clock::now();

    const unsigned int nev = std::min<std::size_t>(n_modes, n - 2);
    const unsigned int ncv = std::min<std::size_t>(n - 1, krylov_size(nev));
    stats.requested        = nev;
    stats.krylov_size      = ncv;
    stats.max_restarts     = max_restarts;

    // OP = S^-1 M, M-symmetric: its largest 1 / (mu + sigma^2) are the
    // lowest mu; deal.II maps them back with the shift -sigma^2
    struct Mass
    {
      const PETScWrappers::MPI::SparseMatrix &M;
      mutable Work                            work;
      void
      vmult(Vector<double> &y, const Vector<double> &x) const
      {
        scatter(x, 0, work.a);
        M.vmult(work.b, work.a);
        gather(work.b, y, 0);
      }
    } mass{M, Work(M)};
    struct Inverse
    {
      const DirectSolver &S_inverse;
      mutable Work        work;
      unsigned int       &applications;
      mutable double      solve_seconds = 0;
      void
      vmult(Vector<double> &y, const Vector<double> &x) const
      {
        scatter(x, 0, work.a);
        const auto t = clock::now();
        S_inverse.solve(work.b, work.a);
        solve_seconds += std::chrono::duration<double>(clock::now() - t).count();
        gather(work.b, y, 0);
        ++applications;
      }
    } inverse{solver, Work(M), stats.operator_applications};
    std::vector<Vector<double>>       z;
    std::vector<std::complex<double>> mu;
    const auto arpack = [&]() {
      SolverControl control(max_restarts, lanczos_tolerance, false, false);
      ArpackSolver  solver_arpack(
        control, ArpackSolver::AdditionalData(ncv, ArpackSolver::largest_magnitude, true));
      solver_arpack.set_shift(-sigma * sigma);
      z.assign(nev, Vector<double>(n));
      mu.assign(nev, 0.);
      solver_arpack.solve(mass, mass, inverse, mu, z, nev);
      stats.iterations = control.last_step();
    };
    if (lanczos_block > 1 && nev > lanczos_block && ncv + 2 * lanczos_block < n)
      {
        // one pass over the factors per block of columns (doc/theory.md 8.7):
        // the space as ARPACK's plus a block; Anasazi keeps whole blocks
        // over a restart, and keeping no more than nev stalls on the last
        // mode (the conical impeller, 20 modes in blocks of 5 or 10), so nev
        // is rounded up past a block boundary
        const unsigned int n_blocks = (ncv + lanczos_block - 1) / lanczos_block + 1;
        const unsigned int asked    = nev % lanczos_block == 0 ? nev + 1 : nev;
        std::vector<double>    theta;
        BlockLanczosStatistics block;
        block_lanczos(M, solver, asked, lanczos_block, n_blocks, max_restarts,
                      lanczos_tolerance, theta, z, block);
        z.resize(std::min<std::size_t>(z.size(), nev));
        mu.resize(z.size());
        for (std::size_t j = 0; j < z.size(); ++j)
          mu[j] = 1. / theta[j] - sigma * sigma;
        stats.block_size            = lanczos_block;
        stats.krylov_size           = lanczos_block * n_blocks;
        stats.iterations            = block.iterations;
        stats.block_solves          = block.block_solves;
        stats.operator_applications = block.operator_applications;
        inverse.solve_seconds       = block.solve_seconds;
        if (z.size() < nev)
          {
            // not all found (or Anasazi threw): ARPACK on the same factors
            std::ostringstream m;
            m << "block Krylov-Schur found " << z.size() << " of " << nev << " modes"
              << (block.failure.empty() ? "" : " (" + block.failure + ")");
            stats.fallback = m.str();
            stats.block_size   = 1;
            stats.krylov_size  = ncv;
            arpack();
          }
      }
    else
      arpack();
    stats.solve_seconds = inverse.solve_seconds;
    stats.arnoldi_seconds = seconds(t0);
    t0                    = clock::now();

    const double              norm_M = M.frobenius_norm(), norm_K = K.frobenius_norm();
    std::vector<UndampedMode> modes;
    std::vector<Vector<double>> Mz, Kz;
    {
      std::vector<const Vector<double> *> columns;
      for (const auto &v : z)
        columns.push_back(&v);
      replicated_mmult(M, columns, Mz);
      replicated_mmult(K, columns, Kz);
    }
    for (unsigned int j = 0; j < z.size(); ++j)
      {
        UndampedMode m;
        m.mu  = mu[j].real();
        m.phi = std::move(z[j]);
        Kz[j].add(-m.mu, Mz[j]);
        const double scale = (std::abs(m.mu) * norm_M + norm_K) * m.phi.l2_norm();
        // an unconverged slot (zeros, NaN) fails the test below
        m.residual = scale > 0 ? Kz[j].l2_norm() / scale : std::numeric_limits<double>::infinity();
        if (!std::isfinite(m.residual) || !std::isfinite(m.mu))
          m.residual = std::numeric_limits<double>::infinity();
        modes.push_back(std::move(m));
      }
    stats.check_seconds = seconds(t0);
    std::sort(modes.begin(), modes.end(), [](const UndampedMode &a, const UndampedMode &b) {
      return a.mu < b.mu;
    });
    return modes;
  }

  std::vector<EigenPair>
  DampedEigensolver::solve(const PETScWrappers::MPI::SparseMatrix &M,
                           const PETScWrappers::MPI::SparseMatrix &C,
                           PETScWrappers::MPI::SparseMatrix       &K,
                           const unsigned int                      nev,
                           Statistics                             &stats,
                           const unsigned int                      attempt)
  {
    const std::size_t n = M.m();
    using clock         = std::chrono::steady_clock;
    const auto seconds  = [](const clock::time_point t0) {
      return std::chrono::duration<double>(clock::now() - t0).count();
    };
    auto t0 = clock::now();
    if (attempt == 0)
      factorize(M, C, K);
    const double t_factor = seconds(t0);
    t0                    = clock::now();

    const double       growth = std::pow(2., attempt);
    const unsigned int ncv    = std::min<std::size_t>(2 * n - 1, krylov_size(nev, growth));
    stats                       = Statistics();
    stats.factorization_seconds = t_factor;
    stats.requested             = nev;
    stats.krylov_size           = ncv;
    stats.max_restarts          = static_cast<unsigned int>(max_restarts * growth);

    SolverControl control(stats.max_restarts, tolerance, false, false);
    ArpackSolver  arpack(control,
                        ArpackSolver::AdditionalData(ncv, ArpackSolver::largest_magnitude, false));
    arpack.set_shift(sigma);
    StateMass                         B(M, n);
    ShiftInvert                       inverse(M, C, solver, sigma, n, stats.operator_applications);
    std::vector<Vector<double>>       z(nev + 1, Vector<double>(2 * n));
    std::vector<std::complex<double>> lambda(nev);
    arpack.solve(B, B, inverse, lambda, z, nev);
    stats.iterations      = control.last_step();
    stats.arnoldi_seconds = seconds(t0);
    stats.solve_seconds   = inverse.solve_seconds;
    t0                    = clock::now();

    // dneupd stores a conjugate pair as Re, Im in consecutive vectors; which
    // member they belong to is checked by the backward error (doc/theory.md
    // 8.4). Only the Im >= 0 member is kept.
    const BackwardError    backward_error(M, C, K);
    const RitzPairs        ritz{lambda, z, nev, n};
    std::vector<EigenPair> pairs;
    for (unsigned int j = 0; j < nev; ++j)
      {
        EigenPair p;
        if (recover_pair(ritz, backward_error, max_backward_error, j, p))
          pairs.push_back(std::move(p));
        else if (j < nev)
          ++stats.unconverged_slots;
      }
    stats.check_seconds = seconds(t0);
    std::sort(pairs.begin(), pairs.end(), [](const EigenPair &a, const EigenPair &b) {
      return std::abs(a.lambda) < std::abs(b.lambda);
    });
    return pairs;
  }
} // namespace rotorfit
