/*
 * driver.c -- a plain-C driver for the libFuzzer target of fuzz_api.c, for machines without
 * clang's libFuzzer: feeds LLVMFuzzerTestOneInput random byte strings from a seeded PRNG
 * (splitmix64) for a bounded CPU time, or replays the files given on the command line.
 *
 *   fuzz_driver [-t SECONDS] [-s SEED] [-n MAX_RUNS] [-l MAX_LEN]   fuzz (defaults 10 s, seed 1, 400 bytes)
 *   fuzz_driver -s SEED -r RUN -o FILE                               write the input of run RUN to FILE
 *   fuzz_driver FILE...                                              replay inputs (also libFuzzer's crash files)
 *
 * Prints "fuzz: N executions in T s (R exec/s), ..." and exits 0.  A contract violation
 * aborts inside the target; the SIGABRT handler then prints the seed and run that reproduce
 * it (run with ASAN_OPTIONS=abort_on_error=1 UBSAN_OPTIONS=abort_on_error=1 so that
 * sanitizer reports go the same way).
 */
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static volatile unsigned long long current_seed, current_run;

static void on_abort(int sig)
{
    (void)sig;
    fprintf(stderr, "fuzz: failing input: seed %llu run %llu (write it with -s %llu -r %llu -o FILE)\n",
            current_seed, current_run, current_seed, current_run);
    signal(SIGABRT, SIG_DFL);
}

static uint64_t next_u64(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

/* The input of run `run` for `seed`: a length in [0, max_len], then that many random bytes. */
static size_t make_input(unsigned long long seed, unsigned long long run, size_t max_len, uint8_t *buf)
{
    uint64_t s = seed * 0x100000001B3ULL + run;
    const size_t len = (size_t)(next_u64(&s) % (max_len + 1));
    size_t k;
    for (k = 0; k < len; ++k) buf[k] = (uint8_t)next_u64(&s);
    return len;
}

static double cpu_seconds(void) { return (double)clock() / CLOCKS_PER_SEC; }

static int replay(const char *path)
{
    static uint8_t buf[1 << 16];
    size_t n;
    FILE *f = fopen(path, "rb");
    if (!f) {
        perror(path);
        return 1;
    }
    n = fread(buf, 1, sizeof buf, f);
    fclose(f);
    LLVMFuzzerTestOneInput(buf, n);
    printf("fuzz: replayed %s (%lu bytes): no contract violation\n", path, (unsigned long)n);
    return 0;
}

int main(int argc, char **argv)
{
    double seconds = 10, started, elapsed = 0;
    unsigned long long seed = 1, max_runs = 0, runs = 0, write_run = 0;
    size_t max_len = 400;
    const char *out = NULL;
    uint8_t *buf;
    int i, files = 0, status = 0, have_write_run = 0;
    for (i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "-t") && i + 1 < argc) seconds = atof(argv[++i]);
        else if (!strcmp(argv[i], "-s") && i + 1 < argc) seed = strtoull(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "-n") && i + 1 < argc) max_runs = strtoull(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "-l") && i + 1 < argc) max_len = (size_t)strtoul(argv[++i], NULL, 10);
        else if (!strcmp(argv[i], "-r") && i + 1 < argc) write_run = strtoull(argv[++i], NULL, 10), have_write_run = 1;
        else if (!strcmp(argv[i], "-o") && i + 1 < argc) out = argv[++i];
        else {
            status |= replay(argv[i]);
            ++files;
        }
    }
    if (files) return status;
    buf = malloc(max_len + 1);
    if (!buf) return 1;
    if (have_write_run && out) {
        const size_t len = make_input(seed, write_run, max_len, buf);
        FILE *f = fopen(out, "wb");
        if (!f || fwrite(buf, 1, len, f) != len) return 1;
        fclose(f);
        free(buf);
        return 0;
    }
    signal(SIGABRT, on_abort);
    current_seed = seed;
    started = cpu_seconds();
    do {
        const size_t len = make_input(seed, runs, max_len, buf);
        current_run = runs;
        LLVMFuzzerTestOneInput(buf, len);
        ++runs;
        if (runs % 64 == 0) elapsed = cpu_seconds() - started;
    } while ((max_runs == 0 || runs < max_runs) && (runs % 64 != 0 || elapsed < seconds));
    elapsed = cpu_seconds() - started;
    printf("fuzz: %llu executions in %.1f s (%.0f exec/s), seed %llu, inputs up to %lu bytes: "
           "no contract violation\n",
           runs, elapsed, (double)runs / (elapsed > 0 ? elapsed : 1), seed, (unsigned long)max_len);
    free(buf);
    return 0;
}
