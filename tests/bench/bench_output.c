/*
** Benchmark section: output files. A body's --vtu series writes two files a step into one
** folder through the atomic writer (src/base/atomic.c), every one held as a finished temporary
** until all are committed. Each open used to sweep the whole folder for dead runs' temporaries,
** so n files cost O(n^2) (a 6,000-step dynamic run: 35-43 s with --vtu against 1.3 s without);
** a folder is now swept once. Measured: the time per file of series of n files (small
** files, so the folder's reading, not the writing, would dominate), which must stay flat in n.
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/atomic.h"
#include "bench.h"

/* Writes n files dir/body_NNNN.vtu as cli_body.c does (open, write, finish each; then commit
** all); seconds, or -1 on a failure. */
static double series(const char *dir, int n)
{
    cf_atomic *a = calloc((size_t)n, sizeof *a);
    if (!a)
        return -1;
    char path[600];
    cf_error err = {0};
    int ok = 1;
    const double t0 = bench_now();
    for (int k = 0; k < n && ok; k++) {
        snprintf(path, sizeof path, "%s/body_%04d.vtu", dir, k);
        ok = cf_atomic_open(&a[k], path, NULL, &err) == CF_OK;
        if (ok) {
            fputs("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\"/>\n", a[k].fp);
            ok = cf_atomic_finish(&a[k], &err) == CF_OK;
        }
    }
    for (int k = 0; k < n && ok; k++)
        ok = cf_atomic_commit(&a[k], &err) == CF_OK;
    const double t = bench_now() - t0;
    for (int k = 0; k < n; k++) {
        cf_atomic_abort(&a[k]);
        snprintf(path, sizeof path, "%s/body_%04d.vtu", dir, k);
        unlink(path);
    }
    free(a);
    return ok ? t : -1;
}

void bench_section_output(bench_ctx *ctx)
{
    fprintf(ctx->md, "## Output files: a --vtu series into one folder\n\n"
                     "n files written as `conifit simulate --vtu` writes them (each a finished "
                     "temporary until all are committed), small, into a fresh folder: the time "
                     "per file stays flat in n when the folder is swept for dead runs' "
                     "temporaries once, not on every open (tests/bench/bench_output.c).\n\n");
    fprintf(ctx->md, "| files | time, s | per file, us | folder sweeps |\n|---|---|---|---|\n");
    const int sizes[] = {1000, 4000, 12000};
    const int nsizes = ctx->quick ? 2 : 3;
    double per_first = 0, per_last = 0;
    for (int s = 0; s < nsizes; s++) {
        char dir[] = "/tmp/conifit-bench-vtu-XXXXXX";
        if (!mkdtemp(dir)) {
            fprintf(ctx->md, "| %d | no temporary folder | – | – |\n", sizes[s]);
            continue;
        }
        const unsigned long sw = cf_atomic_sweeps();
        const double t = series(dir, sizes[s]);
        const unsigned long swept = cf_atomic_sweeps() - sw;
        rmdir(dir);
        if (t < 0) {
            fprintf(ctx->md, "| %d | failed | – | – |\n", sizes[s]);
            continue;
        }
        const double per = t / sizes[s] * 1e6;
        fprintf(ctx->md, "| %d | %.3f | %.1f | %lu |\n", sizes[s], t, per, swept);
        if (s == 0)
            per_first = per;
        per_last = per;
    }
    fprintf(ctx->md, "\n");
    if (per_first > 0 && per_last > 0)
        bench_target_add(ctx, "a --vtu series: time per file flat in n (within 3x from 1,000 files)",
                         per_last <= 3 * per_first, "%.1f us a file at %d files, %.1f at 1,000",
                         per_last, sizes[nsizes - 1], per_first);
}
