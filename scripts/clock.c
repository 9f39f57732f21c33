// The clock of one core, for the roofline of docs/performance.md: a chain of dependent 64-bit
// integer multiplies, which take 3 cycles each on x86-64 cores of the last decade (Intel since
// Nehalem, AMD since Zen), timed by the wall clock; the best of five runs of 8e9 multiplies.
// Run it on an idle machine: cc -O2 -o /tmp/clock scripts/clock.c && /tmp/clock
#include <stdio.h>
#include <time.h>

int main(void) {
  const long iterations = 2000000000L;
  double best = 1e30;
  for (int run = 0; run < 5; run++) {
    struct timespec start, end;
    long x = 3;
    clock_gettime(CLOCK_MONOTONIC, &start);
    for (long i = 0; i < iterations; i++) {
#if defined(__x86_64__)
      __asm__ volatile("imul %0, %0\n\timul %0, %0\n\timul %0, %0\n\timul %0, %0" : "+r"(x));
#else
#error "x86-64 only: the latency of imul is what this counts on"
#endif
    }
    clock_gettime(CLOCK_MONOTONIC, &end);
    double ns = (end.tv_sec - start.tv_sec) * 1e9 + (end.tv_nsec - start.tv_nsec);
    if (ns < best) best = ns;
  }
  printf("%.2f GHz (4 x 3 cycles of dependent imul per iteration, best of 5)\n",
         12.0 * iterations / best);
  return 0;
}
