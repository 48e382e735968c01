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
typedef struct bench_ctx {
    FILE *md;              /* the Markdown report */
    const char *dir;       /* folder of the report, plots and plot data */
    int quick;             /* 1: fewer repeats and sizes (a smoke run) */
} bench_ctx;

/* Runs gnuplot on script (with `set output` already naming a PNG in dir); returns 0 on success. */
int bench_gnuplot(const bench_ctx *ctx, const char *script);

/* Opens dir/name for writing plot data; NULL on failure. */
FILE *bench_open_data(const bench_ctx *ctx, const char *name);

/* Sink that keeps the compiler from discarding benchmark work. */
extern volatile double bench_sink;

void bench_section_law(bench_ctx *ctx);

#endif
