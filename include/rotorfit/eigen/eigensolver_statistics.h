#pragma once

#include <string>

namespace rotorfit
{
  /// What one call of DampedEigensolver::solve() or solve_undamped() did:
  /// sizes, iterations and times, for the log.
  struct EigensolverStatistics
  {
    unsigned int requested    = 0; ///< ARPACK nev (conjugates counted twice)
    unsigned int krylov_size  = 0;
    unsigned int iterations   = 0; ///< Arnoldi restarts used
    unsigned int max_restarts = 0; ///< cap of this attempt
    /// ARPACK slots left unconverged (deal.II 9.4 returns them as 0 + 0i
    /// with its checks compiled out): never eigenvalues, never rigid modes
    unsigned int unconverged_slots     = 0;
    unsigned int operator_applications = 0;
    unsigned int block_size            = 1; ///< columns per back-substitution (undamped)
    unsigned int block_solves          = 0; ///< passes over the factors (block Lanczos)
    std::string  fallback;                  ///< why the block Lanczos gave way to ARPACK
    double       factorization_seconds = 0, arnoldi_seconds = 0, solve_seconds = 0,
                 check_seconds = 0;
  };
} // namespace rotorfit
