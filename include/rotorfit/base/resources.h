#pragma once

#include <malloc.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace rotorfit
{
  /**
   * Memory estimates made before the work starts, so that a model too big
   * for the machine is refused with the estimate instead of hanging in gmsh
   * or dying in an allocation. The constants are measured (doc/limits.md):
   * quadratic tetrahedra of TS, 23,257 cells, 105,963 DOFs, 8.47M nonzeros;
   * MUMPS LU peak 2.4 GB, nested-dissection fill growing as n^(4/3).
   */
  namespace resources
  {
    constexpr double measured_dofs           = 105963;
    constexpr double measured_lu_bytes       = 2.4e9;
    constexpr double nonzeros_per_dof        = 80;  ///< P2 elasticity rows
    constexpr double dofs_per_tetrahedron    = 4.6; ///< P2, 3 components
    constexpr double regular_tet_volume      = 0.1179; ///< h^3 / (6 sqrt 2)

    /// MUMPS factor of an n x n P2 elasticity matrix [bytes] (LU; LDL^T half).
    inline double
    factorization_bytes(const double n, const bool symmetric)
    {
      return (symmetric ? 0.5 : 1.0) * measured_lu_bytes *
             std::pow(n / measured_dofs, 4. / 3.);
    }

    /// One PETSc AIJ matrix of n rows [bytes] (value + column index).
    inline double
    sparse_matrix_bytes(const double n)
    {
      return n * nonzeros_per_dof * 12.;
    }

    /// The machine's physical memory [bytes]: what a run may use unless
    /// Resources/Memory limit says less (a share of a machine used by others).
    inline double
    physical_memory_bytes()
    {
      return static_cast<double>(::sysconf(_SC_PHYS_PAGES)) *
             static_cast<double>(::sysconf(_SC_PAGE_SIZE));
    }

    /// Blocks from this size [bytes] are mapped alone (map_large_blocks()).
    constexpr std::size_t mapped_block_bytes = 12u << 20;

    /// Large blocks mapped and unmapped alone again. Debian 12's
    /// libsuperlu_dist (loaded with PETSc; HYPRE too) calls
    /// mallopt(M_MMAP_MAX, 0) in a constructor: every block, a 0.9 GB
    /// factor too, then lives in the brk heap, whose holes glibc cannot give
    /// back, and a freed factor left a hole the next one did not fit (a TS
    /// band run's resident peak stood 0.8 GB above its heap's). The
    /// threshold is fixed because any mallopt stops glibc's sliding one. At
    /// 12 MB the block solves' and mode blocks' arrays of a speed (12-25 MB
    /// on TS) leave no holes in the heap: TS's peak 1.51 -> 1.46 GB (32 MB,
    /// glibc's own ceiling, before). Smaller blocks, the vectors made at every
    /// speed, stay in the heap: a 128 kB threshold mapped each anew and made
    /// TS 50 % slower (benchmarks/README.md).
    inline void
    map_large_blocks()
    {
      mallopt(M_MMAP_MAX, 65536); // glibc's default
      mallopt(M_MMAP_THRESHOLD, static_cast<int>(mapped_block_bytes));
    }

    /// Free pages inside the heap given back to the system (glibc's
    /// malloc_trim): the blocks below mapped_block_bytes that the speeds
    /// free leave holes the heap keeps resident. Called before an anchor's
    /// factorisation, not after every speed: there the pages given back are
    /// faulted in again at the next speed (TS: 9 % more wall time for 30 MB
    /// less, benchmarks/README.md).
    inline void
    give_back_free_memory()
    {
      malloc_trim(0);
    }

    /// This process's resident memory [bytes], now or at its peak (Linux
    /// /proc/self/status VmRSS, VmHWM; 0 where there is none).
    inline double
    resident_bytes(const bool peak)
    {
      std::FILE *f = std::fopen("/proc/self/status", "r");
      if (f == nullptr)
        return 0;
      const char *key = peak ? "VmHWM:" : "VmRSS:";
      char        line[256];
      double      kib = 0;
      while (std::fgets(line, sizeof(line), f) != nullptr)
        if (std::strncmp(line, key, std::strlen(key)) == 0)
          kib = std::atof(line + std::strlen(key));
      std::fclose(f);
      return kib * 1024.;
    }

    inline std::string
    gigabytes(const double bytes)
    {
      char s[32];
      std::snprintf(s, sizeof(s), "%.3g GB", bytes / 1e9);
      return s;
    }
  } // namespace resources
} // namespace rotorfit
