// resources::map_large_blocks() (include/rotorfit/base/resources.h): after
// mallopt(M_MMAP_MAX, 0), as Debian 12's libsuperlu_dist calls it when PETSc
// loads it, a 64 MB block is mapped alone again and unmapped by free(); a
// 1 MB block stays in the heap.
// Reference: glibc's own count of mapped blocks (mallinfo2().hblks), exact.

#include <rotorfit/base/resources.h>

#include "unit_check.h"

#include <malloc.h>

#include <cstdlib>
#include <cstring>

using namespace rotorfit_unit;

namespace
{
  /// mapped blocks while a block of @p bytes is held
  std::size_t
  mapped_with_block(const std::size_t bytes)
  {
    // (through volatile pointers: the compiler may drop a malloc/free pair)
    void *(*volatile allocate)(std::size_t) = std::malloc;
    void (*volatile release)(void *)        = std::free;
    char *p = static_cast<char *>(allocate(bytes));
    std::memset(p, 1, bytes);
    const std::size_t n = mallinfo2().hblks;
    release(p);
    return n;
  }
} // namespace

int
main()
{
  Checks       check;
  const std::size_t before = mallinfo2().hblks;
  std::printf("before the call a 64 MB block is %s (in the heap: a library loaded with this executable turned mapping off)\n",
              mapped_with_block(64u << 20) == before ? "in the heap" : "mapped");
  // what that library does, whether or not this executable loads it
  mallopt(M_MMAP_MAX, 0);
  malloc_trim(0); // (the heap's free top would serve the next block)
  rotorfit::resources::map_large_blocks();
  const std::size_t base = mallinfo2().hblks;
  check.equal("mapped blocks while 64 MB is held", mapped_with_block(64u << 20), base + 1,
              "glibc mallinfo2");
  check.equal("mapped blocks after it is freed", std::size_t(mallinfo2().hblks), base,
              "glibc mallinfo2");
  check.equal("mapped blocks while 1 MB is held", mapped_with_block(1u << 20), base,
              "glibc mallinfo2");
  return check.finish();
}
