/*
** The benchmark report: shared timing helpers and the sections, each of which measures one stage
** of conifit and appends its tables (and plot data) to the report.
*/
#ifndef CF_BENCH_H
#define CF_BENCH_H

#include <stddef.h>
#include <stdio.h>

/* Seconds on a monotonic clock. */
double bench_now(void);

/* Summary of repeated timings: median and the spread (min, max) over the repeats. */
typedef struct bench_stats {
    double median, min, max;
    int repeats;
} bench_stats;

/* Sorts x (count values) and summarises it. */
bench_stats bench_summarise(double *x, int count);

/* Where the report and its plots go, and how to draw a plot. */
/* One target of the issue with its measured value, for the summary at the end of the report. */
typedef struct bench_target {
    char name[160];
    char measured[200];
    int met; /* 1 met, 0 not met, -1 not measured */
} bench_target;

#define BENCH_MAX_TARGETS 32

typedef struct bench_ctx {
    FILE *md;              /* the Markdown report */
    const char *dir;       /* folder of the report, plots and plot data */
    int quick;             /* 1: fewer repeats and sizes (a smoke run) */
    bench_target targets[BENCH_MAX_TARGETS];
    int ntargets;
    size_t largest_springs; /* springs of the largest lattice of section 2 */
    int largest_cells;      /* its cells per edge */
    double slope_closed;    /* growth exponent of the closed-form lattice step */
    char *mem_fit;          /* section 6's fit-memory text, measured first (bench_memory_fit_early) */
} bench_ctx;

/* Records a target for the summary table; measured is printf-formatted. */
void bench_target_add(bench_ctx *ctx, const char *name, int met, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* Runs gnuplot on script (with `set output` already naming a PNG in dir); returns 0 on success. */
int bench_gnuplot(const bench_ctx *ctx, const char *script);

/* Opens dir/name for writing plot data; NULL on failure. */
FILE *bench_open_data(const bench_ctx *ctx, const char *name);

/* Runs fn(arg) in a forked child; the child's peak resident set (ru_maxrss, KiB), -1 on failure. */
long bench_child_maxrss_kb(void (*fn)(void *), void *arg);

/* CPU time of this process, s: on a shared machine the wall time of a one-core run grows with
** the load, its CPU time does not. */
double bench_cpu_now(void);

/* Runs argv (argv[0] is the program path) with stdout and stderr to /dev/null and waits for it;
** *ru receives its resources. 0 when it exited with status 0, else -1. */
struct rusage;
int bench_exec(char *const argv[], struct rusage *ru);

/* Writes a CSV table "strain,stress_kPa" of n rows, strain evenly from 0 to xmax, stress
** scale (curve(strain) + Gaussian noise of sd noise_sd, seed 1). 0 on success. */
int bench_write_table(const char *path, size_t n, double xmax, double noise_sd, double scale,
                      double (*curve)(double x, const void *arg), const void *arg);

/* Sink that keeps the compiler from discarding benchmark work. */
extern volatile double bench_sink;

void bench_section_law(bench_ctx *ctx);
void bench_section_tail(bench_ctx *ctx);
void bench_section_lattice(bench_ctx *ctx);
void bench_section_pair(bench_ctx *ctx);
void bench_section_integrators(bench_ctx *ctx);
void bench_section_fit(bench_ctx *ctx);
void bench_section_resolution(bench_ctx *ctx);
void bench_memory_fit_early(bench_ctx *ctx);
void bench_section_memory(bench_ctx *ctx);
void bench_section_calibration(bench_ctx *ctx);
void bench_section_visco(bench_ctx *ctx);
void bench_section_statics(bench_ctx *ctx);
void bench_statics_early(bench_ctx *ctx);
void bench_section_longfit(bench_ctx *ctx);
void bench_section_fastfit(bench_ctx *ctx);
void bench_section_body(bench_ctx *ctx);
void bench_section_body_ccx(bench_ctx *ctx); /* called by bench_section_body */
void bench_section_body_large(bench_ctx *ctx); /* about 50,000 nodes against a minute of CPU */
void bench_section_output(bench_ctx *ctx);
void bench_section_contact(bench_ctx *ctx);
void bench_section_startup(bench_ctx *ctx);

#endif
