#include <rotorfit/base/patterns.h>
#include <rotorfit/base/input_error.h>
#include <rotorfit/eigen/block_lanczos.h>
#include <rotorfit/eigen/damped_eigensolver.h>
#include <rotorfit/eigen/shift_invert.h>
#include <rotorfit/linear_algebra/matrix_pattern.h>
#include <rotorfit/linear_algebra/replicated_blocks.h>

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
    using clock = std::chrono::steady_clock;

    double
    seconds_since(const clock::time_point t0)
    {
      return std::chrono::duration<double>(clock::now() - t0).count();
    }

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

  namespace
  {
    /// What ARPACK returned: @p nev Ritz values and the state vectors
    /// (length 2 n) of their real and imaginary parts.
    struct RitzPairs
    {
      const std::vector<std::complex<double>> &lambda;
      const std::vector<Vector<double>>       &z;
      unsigned int                             nev;
      std::size_t                              n;
    };

    /// The eigenpair of ARPACK's slot @p j (and of its partner j + 1 for a
    /// complex pair: @p j is advanced past it), with Im lambda >= 0 and
    /// |phi| = 1; false for an unconverged slot.
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
          {
            // the other member of the pair (ARPACK versions differ). Both can
            // pass the limit: the norm of K holds the ties' penalties, and
            // the wrong member, the eigenvector of conj(lambda), misses only
            // by 2 Im(lambda) (2 Re(lambda) M + C) phi, small under weak
            // gyroscopic coupling (found on the harmonic model, where it
            // swapped forward and backward whirl). Take it where it is
            // clearly better; a degenerate pair at rest keeps the first.
            ComplexVector swapped{p.phi.re, p.phi.im}, m_swapped;
            swapped.im *= -1.;
            const double other = backward_error(p.lambda, swapped, m_swapped);
            if (other < 1e-2 * p.backward_error ||
                (!(p.backward_error <= max_backward_error) && other < p.backward_error))
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

  void
  DampedEigensolver::factorize_shifted_stiffness(const PETScWrappers::MPI::SparseMatrix &M,
                                                 PETScWrappers::MPI::SparseMatrix       &K)
  {
    // S = K + sigma^2 M: symmetric (LDL^T, about half the LU's time and
    // memory) and regular with free bodies for the same reason as Q(sigma)
    // (formed in K's storage, as in factorize())
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

  bool
  DampedEigensolver::undamped_block_krylov_schur(const PETScWrappers::MPI::SparseMatrix &M,
                                                 const unsigned int                      nev,
                                                 const unsigned int                      ncv,
                                                 Statistics                             &stats,
                                                 std::vector<Vector<double>>            &z,
                                                 std::vector<std::complex<double>>      &mu) const
  {
    // one pass over the factors per block of columns (doc/theory.md 8.7):
    // the space as ARPACK's plus a block; Anasazi keeps whole blocks
    // over a restart, and keeping no more than nev stalls on the last
    // mode (the conical impeller, 20 modes in blocks of 5 or 10), so nev
    // is rounded up past a block boundary
    const unsigned int     n_blocks = (ncv + lanczos_block - 1) / lanczos_block + 1;
    const unsigned int     asked    = nev % lanczos_block == 0 ? nev + 1 : nev;
    std::vector<double>    theta;
    BlockLanczosStatistics block;
    block_lanczos(M, solver, asked, lanczos_block, n_blocks, max_restarts, lanczos_tolerance,
                  theta, z, block);
    z.resize(std::min<std::size_t>(z.size(), nev));
    mu.resize(z.size());
    for (std::size_t j = 0; j < z.size(); ++j)
      mu[j] = 1. / theta[j] - sigma * sigma;
    stats.block_size            = lanczos_block;
    stats.krylov_size           = lanczos_block * n_blocks;
    stats.iterations            = block.iterations;
    stats.block_solves          = block.block_solves;
    stats.operator_applications = block.operator_applications;
    stats.solve_seconds         = block.solve_seconds;
    if (z.size() >= nev)
      return true;
    std::ostringstream m;
    m << "block Krylov-Schur found " << z.size() << " of " << nev << " modes"
      << (block.failure.empty() ? "" : " (" + block.failure + ")");
    stats.fallback = m.str();
    return false;
  }

  void
  DampedEigensolver::undamped_arpack(const PETScWrappers::MPI::SparseMatrix &M,
                                     const unsigned int                      nev,
                                     const unsigned int                      ncv,
                                     Statistics                             &stats,
                                     std::vector<Vector<double>>            &z,
                                     std::vector<std::complex<double>>      &mu) const
  {
    // OP = S^-1 M, M-symmetric: its largest 1 / (mu + sigma^2) are the
    // lowest mu; deal.II maps them back with the shift -sigma^2
    const ReplicatedMass mass(M);
    ReplicatedInverse    inverse(solver, M, stats.operator_applications);
    inverse.solve_seconds = stats.solve_seconds; // (the block method's, if it ran)
    SolverControl control(max_restarts, lanczos_tolerance, false, false);
    ArpackSolver  solver_arpack(control,
                               ArpackSolver::AdditionalData(ncv, ArpackSolver::largest_magnitude, true));
    solver_arpack.set_shift(-sigma * sigma);
    z.assign(nev, Vector<double>(M.m()));
    mu.assign(nev, 0.);
    solver_arpack.solve(mass, mass, inverse, mu, z, nev);
    stats.iterations    = control.last_step();
    stats.solve_seconds = inverse.solve_seconds;
  }

  void
  DampedEigensolver::undamped_lanczos(const PETScWrappers::MPI::SparseMatrix &M,
                                      const unsigned int                      nev,
                                      const unsigned int                      ncv,
                                      Statistics                             &stats,
                                      std::vector<Vector<double>>            &z,
                                      std::vector<std::complex<double>>      &mu) const
  {
    if (lanczos_block > 1 && nev > lanczos_block && ncv + 2 * lanczos_block < M.m())
      {
        if (undamped_block_krylov_schur(M, nev, ncv, stats, z, mu))
          return;
        // not all found (or Anasazi threw): ARPACK on the same factors
        stats.block_size  = 1;
        stats.krylov_size = ncv;
      }
    undamped_arpack(M, nev, ncv, stats, z, mu);
  }

  namespace
  {
    /// The modes (mu_j, z_j) with their residuals on K and M.
    std::vector<DampedEigensolver::UndampedMode>
    checked_modes(const PETScWrappers::MPI::SparseMatrix  &M,
                  const PETScWrappers::MPI::SparseMatrix  &K,
                  std::vector<Vector<double>>             &z,
                  const std::vector<std::complex<double>> &mu)
    {
      using UndampedMode                      = DampedEigensolver::UndampedMode;
      const double                norm_M      = M.frobenius_norm(), norm_K = K.frobenius_norm();
      std::vector<UndampedMode>   modes;
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
          m.residual =
            scale > 0 ? Kz[j].l2_norm() / scale : std::numeric_limits<double>::infinity();
          if (!std::isfinite(m.residual) || !std::isfinite(m.mu))
            m.residual = std::numeric_limits<double>::infinity();
          modes.push_back(std::move(m));
        }
      return modes;
    }
  } // namespace

  std::vector<DampedEigensolver::UndampedMode>
  DampedEigensolver::solve_undamped(const PETScWrappers::MPI::SparseMatrix &M,
                                    PETScWrappers::MPI::SparseMatrix       &K,
                                    const unsigned int                      n_modes,
                                    Statistics                             &stats,
                                    const bool                              factorize)
  {
    const std::size_t n  = M.m();
    auto              t0 = clock::now();
    if (factorize)
      factorize_shifted_stiffness(M, K);
    stats                       = Statistics();
    stats.factorization_seconds = seconds_since(t0);
    t0                          = clock::now();

    const unsigned int nev = std::min<std::size_t>(n_modes, n - 2);
    const unsigned int ncv = std::min<std::size_t>(n - 1, krylov_size(nev));
    stats.requested        = nev;
    stats.krylov_size      = ncv;
    stats.max_restarts     = max_restarts;
    std::vector<Vector<double>>       z;
    std::vector<std::complex<double>> mu;
    undamped_lanczos(M, nev, ncv, stats, z, mu);
    stats.arnoldi_seconds = seconds_since(t0);
    t0                    = clock::now();

    auto modes          = checked_modes(M, K, z, mu);
    stats.check_seconds = seconds_since(t0);
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
    const std::size_t n  = M.m();
    auto              t0 = clock::now();
    if (attempt == 0)
      factorize(M, C, K);
    const double t_factor = seconds_since(t0);
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
    CompanionShiftInvert              inverse(M, C, solver, sigma, n, stats.operator_applications);
    std::vector<Vector<double>>       z(nev + 1, Vector<double>(2 * n));
    std::vector<std::complex<double>> lambda(nev);
    arpack.solve(B, B, inverse, lambda, z, nev);
    stats.iterations      = control.last_step();
    stats.arnoldi_seconds = seconds_since(t0);
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
    stats.check_seconds = seconds_since(t0);
    std::sort(pairs.begin(), pairs.end(), [](const EigenPair &a, const EigenPair &b) {
      return std::abs(a.lambda) < std::abs(b.lambda);
    });
    return pairs;
  }
} // namespace rotorfit
