#include <rotorfit/app/application.h>
#include <rotorfit/base/resources.h>

#include <deal.II/base/mpi.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include <unistd.h>

namespace
{
  /// Large blocks in transparent huge pages, on request only
  /// (ROTORFIT_HUGE_PAGES=1): whether they pay depends on the host's state
  /// (TS: 8 % faster one day, 27 % slower another; benchmarks/README.md,
  /// "Huge pages revisited"). glibc asks for them (madvise) only under the
  /// tunable glibc.malloc.hugetlb=1, read at start-up, so the process then
  /// starts itself once more with it. Any value but 0 or 1 is warned about
  /// and taken as 0.
  void
  restart_with_huge_pages(char **argv)
  {
    const char *tunables = std::getenv("GLIBC_TUNABLES");
    const char *choice   = std::getenv("ROTORFIT_HUGE_PAGES");
    if (choice && std::strcmp(choice, "0") != 0 && std::strcmp(choice, "1") != 0)
      {
        std::fprintf(stderr,
                     "Warning: ROTORFIT_HUGE_PAGES = '%s' is neither 0 nor 1; running without "
                     "huge pages.\n",
                     choice);
        return;
      }
    // (once: a loader that drops the tunable, as for set-uid programs,
    // must not make this a loop)
    if (!choice || std::strcmp(choice, "0") == 0 || std::getenv("ROTORFIT_RESTARTED") ||
        (tunables && std::strstr(tunables, "glibc.malloc.hugetlb")))
      return;
    setenv("ROTORFIT_RESTARTED", "1", 1);
    const std::string value =
      (tunables && *tunables ? std::string(tunables) + ":" : std::string()) +
      "glibc.malloc.hugetlb=1";
    if (setenv("GLIBC_TUNABLES", value.c_str(), 1) == 0)
      execv("/proc/self/exe", argv); // returns only on failure: run as we are
  }
} // namespace

int
main(int argc, char **argv)
{
  rotorfit::resources::map_large_blocks();
  restart_with_huge_pages(argv);
  // one thread per rank: the machine has two cores, MPI uses them
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  return rotorfit::run_application(argc, argv);
}
