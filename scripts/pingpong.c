// How long a cache line takes to go from one core to another and back, for the threads section
// of docs/performance.md: two threads, pinned to cores 0 and 1, hand one atomic counter back and
// forth (each waits for the other's number, then writes its own); a round trip is two transfers
// of the line. Prints the best of five runs of a million round trips.
// Run it on an idle machine: cc -O2 -pthread -o /tmp/pingpong scripts/pingpong.c && /tmp/pingpong
#define _GNU_SOURCE
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdio.h>
#include <time.h>

#define ROUNDS 1000000L

static _Alignas(64) atomic_long counter;

static void pin(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  if (pthread_setaffinity_np(pthread_self(), sizeof set, &set) != 0) {
    fprintf(stderr, "cannot pin a thread to core %d\n", cpu);
  }
}

static void *other(void *unused) {
  (void)unused;
  pin(1);
  for (long i = 0; i < ROUNDS; i++) {
    while (atomic_load_explicit(&counter, memory_order_acquire) != 2 * i + 1) {
    }
    atomic_store_explicit(&counter, 2 * i + 2, memory_order_release);
  }
  return NULL;
}

int main(void) {
  double best = 1e30;
  pin(0);
  for (int run = 0; run < 5; run++) {
    atomic_store(&counter, 0);
    pthread_t thread;
    pthread_create(&thread, NULL, other, NULL);
    struct timespec start, end;
    clock_gettime(CLOCK_MONOTONIC, &start);
    for (long i = 0; i < ROUNDS; i++) {
      atomic_store_explicit(&counter, 2 * i + 1, memory_order_release);
      while (atomic_load_explicit(&counter, memory_order_acquire) != 2 * i + 2) {
      }
    }
    clock_gettime(CLOCK_MONOTONIC, &end);
    pthread_join(thread, NULL);
    double ns = (end.tv_sec - start.tv_sec) * 1e9 + (end.tv_nsec - start.tv_nsec);
    if (ns < best) best = ns;
  }
  printf("%.0f ns a round trip between cores 0 and 1 (best of 5 runs of %ld)\n", best / ROUNDS,
         ROUNDS);
  return 0;
}
