/* memory_floor.c -- the memory traffic of the batch accel on n states and nothing else:
 * read the 35 entries of every state and its 2 torques, write 5 numbers per state, with no
 * arithmetic beyond the sums that keep the reads alive.  What a checked batch accel on states
 * that do not fit in the caches cannot beat on this core (docs/sweeps.md, "The memory floor").
 *
 * usage: memory_floor N ROUNDS -- prints {"states": N, "ns_per_state": best round}.
 * Built by runtime/bench/harness.py with -O3 -ffast-math -march=native (the sums vectorised and
 * reassociated: the fastest this loop can be).  A benchmark tool, not library code: it allocates.
 */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define NX 35
#define NU 2
#define NV 5
#define BLOCK 64 /* rows per pass, as the batch accel's blocks */

static double now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return 1e9 * (double)t.tv_sec + (double)t.tv_nsec;
}

int main(int argc, char **argv)
{
    long n, i, k, b;
    int rounds, r;
    double *x, *u, *a, best = 1e300, check = 0;
    if (argc != 3 || (n = atol(argv[1])) < 1 || (rounds = atoi(argv[2])) < 1) {
        fprintf(stderr, "usage: %s N ROUNDS\n", argv[0]);
        return 2;
    }
    x = malloc(sizeof(double) * NX * (size_t)n);
    u = malloc(sizeof(double) * NU * (size_t)n);
    a = malloc(sizeof(double) * NV * (size_t)n);
    if (!x || !u || !a) { fprintf(stderr, "out of memory\n"); return 2; }
    for (i = 0; i < NX * n; ++i) x[i] = 1e-9 * (double)(i % 1000);
    for (i = 0; i < NU * n; ++i) u[i] = 0.1;
    memset(a, 0, sizeof(double) * NV * (size_t)n); /* first touch outside the timed rounds */
    for (r = 0; r < rounds; ++r) {
        const double t0 = now_ns();
        for (b = 0; b < n; b += BLOCK) {
            const long m = n - b < BLOCK ? n - b : BLOCK;
            double s = 0, su = 0;
            for (k = 0; k < NX * m; ++k) s += x[NX * b + k];
            for (k = 0; k < NU * m; ++k) su += u[NU * b + k];
            for (k = 0; k < NV * m; ++k) a[NV * b + k] = s + su;
        }
        {
            const double t = (now_ns() - t0) / (double)n;
            if (t < best) best = t;
        }
    }
    for (i = 0; i < NV * n; i += 4099) check += a[i];
    printf("{\"states\": %ld, \"ns_per_state\": %.3f, \"check\": %g}\n", n, best, check);
    free(x);
    free(u);
    free(a);
    return 0;
}
