/* First touch of fresh anonymous blocks with and without transparent huge
 * pages (madvise), as rotorfit's factorisations and bases are touched:
 *   cc -O2 benchmarks/first_touch.c -o /tmp/first_touch
 *   /tmp/first_touch MB ROUNDS
 * prints the write rate of the fresh block and the unmap time per block,
 * 4 kB pages first, then huge pages (benchmarks/README.md, "Huge pages
 * revisited"). The 4 kB pass measures 4 kB pages only where the kernel's
 * mode (/sys/kernel/mm/transparent_hugepage/enabled) is madvise or never. */
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>

static double
now(void)
{
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec + t.tv_nsec * 1e-9;
}

int
main(int argc, char **argv)
{
  if (argc != 3)
    {
      fprintf(stderr, "usage: %s MB ROUNDS\n", argv[0]);
      return 1;
    }
  const size_t bytes  = (size_t)atoi(argv[1]) << 20;
  const int    rounds = atoi(argv[2]);
  if (bytes == 0 || rounds <= 0)
    {
      fprintf(stderr, "MB and ROUNDS must be positive\n");
      return 1;
    }
  for (int huge = 0; huge < 2; ++huge)
    {
      double touch = 0, unmap = 0;
      for (int i = 0; i < rounds; ++i)
        {
          char *p = mmap(NULL, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
          if (p == MAP_FAILED || (huge && madvise(p, bytes, MADV_HUGEPAGE) != 0))
            {
              perror("mmap/madvise");
              return 1;
            }
          const double t0 = now();
          memset(p, 1, bytes);
          const double t1 = now();
          munmap(p, bytes);
          touch += t1 - t0;
          unmap += now() - t1;
        }
      printf("%zu MB, %s: first touch %.2f GB/s, unmap %.4f s per block\n", bytes >> 20,
             huge ? "huge pages" : "4 kB pages", rounds * bytes / 1e9 / touch, unmap / rounds);
    }
  return 0;
}
