/*
** Benchmark section 6: memory. Peak resident set (getrusage ru_maxrss of a child process) of
** `conifit fit` on the shipped and published tables, against the same binary doing nothing but
** printing its help.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bench.h"
#include "model/lattice.h"

typedef struct lat_job {
    int n;    /* cells per edge; 0: do nothing (the floor) */
    int step; /* 1: also run the force kernel once */
} lat_job;

/* Child body: builds the lattice (and runs one kernel pass), then returns. */
static void build_lattice(void *arg)
{
    const lat_job *j = arg;
    if (j->n <= 0)
        return;
    const cf_spring p = {8, 20, 2.5, 2, 100, 5};
    cf_law law;
    cf_lattice lat;
    cf_lattice_config cfg = cf_lattice_default();
    cfg.nx = cfg.ny = cfg.nz = j->n;
    if (cf_law_init(&law, &p, NULL) != CF_OK ||
        cf_lattice_create(&lat, &law, CF_LAW_CLOSED, &cfg, NULL) != CF_OK)
        _exit(1);
    if (j->step)
        bench_sink += cf_lattice_forces(&lat);
    cf_lattice_free(&lat);
}

long bench_child_maxrss_kb(void (*fn)(void *), void *arg)
{
    fflush(NULL);
    pid_t pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        fn(arg);
        _exit(0);
    }
    int status;
    struct rusage ru;
    if (wait4(pid, &status, 0, &ru) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
        return -1;
    return ru.ru_maxrss;
}

/* Runs argv (argv[0] is the program path) with stdout and stderr to /dev/null; its ru_maxrss in
** KiB, or -1 when it could not run or failed. */
static long exec_maxrss_kb(char *const argv[])
{
    struct rusage ru;
    return bench_exec(argv, &ru) == 0 ? ru.ru_maxrss : -1;
}

static long median_maxrss(char *const argv[], int repeats)
{
    double v[9];
    for (int r = 0; r < repeats; r++) {
        long kb = exec_maxrss_kb(argv);
        if (kb < 0)
            return -1;
        v[r] = (double)kb;
    }
    return (long)bench_summarise(v, repeats).median;
}

/* Memory of `conifit fit`, measured first, while the benchmark itself is still small: a forked
** child starts with its parent's resident pages, and Linux keeps that high-water mark across exec. */
void bench_memory_fit_early(bench_ctx *ctx)
{
    size_t len = 0;
    FILE *real = ctx->md;
    ctx->md = open_memstream(&ctx->mem_fit, &len);
    if (!ctx->md) {
        ctx->md = real;
        return;
    }
    struct rusage self;
    getrusage(RUSAGE_SELF, &self);
    const int repeats = ctx->quick ? 1 : 5;
    const char *env = getenv("CONIFIT");
    char exe[1024];
    snprintf(exe, sizeof exe, "%s", env && *env ? env : "build/conifit");
    fprintf(ctx->md,
            "## 6. Memory\n\n"
            "Peak resident set size (`getrusage` ru_maxrss of the child process, median of %d "
            "runs) of `conifit fit TABLE -o OUT.json --quiet` (both types, baselines, JSON "
            "written to a temporary folder), beside the same binary printing `--help`, which is "
            "the floor (program, libraries, C runtime).\n\n",
            repeats);
    char tmpl[] = "/tmp/conifit-bench-XXXXXX";
    char *tmp = mkdtemp(tmpl);
    if (!tmp) {
        fprintf(ctx->md, "(memory of the fit not measured: no temporary folder)\n\n");
        fclose(ctx->md);
        ctx->md = real;
        return;
    }
    char out[1100];
    snprintf(out, sizeof out, "%s/fit.json", tmp);
    char *help[] = {exe, "--help", NULL};
    long floor_kb = median_maxrss(help, repeats);
    fprintf(ctx->md, "| run | points | peak RSS, KiB | above the floor, KiB |\n|---|---|---|---|\n");
    fprintf(ctx->md, "| `conifit --help` (floor) | – | %ld | – |\n", floor_kb);
    static const struct {
        const char *path;
    } tables[] = {
        {"data/telescoping_noise1pct.csv"},
        {"data/strongly_conical.csv"},
        {"../shared/datasets/skin_porcine_stripbiaxial_x.csv"},
        {"../shared/datasets/thrombus_pureshear_force_displacement.csv"},
    };
    for (size_t i = 0; i < sizeof tables / sizeof tables[0]; i++) {
        if (access(tables[i].path, R_OK) != 0) {
            fprintf(ctx->md, "| fit `%s` | – | absent here, skipped | – |\n", tables[i].path);
            continue;
        }
        char *fit[] = {exe, "fit", (char *)tables[i].path, "-o", out, "--quiet", NULL};
        long kb = median_maxrss(fit, repeats);
        /* points: data rows of the table (lines that start with a digit, sign or point) */
        long pts = 0;
        FILE *f = fopen(tables[i].path, "r");
        char line[4096];
        while (f && fgets(line, sizeof line, f))
            if (strchr("0123456789-+.", line[0]) && line[0] != '\0')
                pts++;
        if (f)
            fclose(f);
        if (kb < 0)
            fprintf(ctx->md, "| fit `%s` | %ld | failed | – |\n", tables[i].path, pts);
        else
            fprintf(ctx->md, "| fit `%s` | %ld | %ld | %ld |\n", tables[i].path, pts, kb,
                    kb - floor_kb);
    }
    remove(out);
    rmdir(tmp);
    fprintf(ctx->md,
            "\nThese runs are launched before any other measurement, while the benchmark's own "
            "peak resident set is %ld KiB (a forked child inherits it as its starting high-water "
            "mark), below every value in the table.\n\n",
            self.ru_maxrss);
    fclose(ctx->md);
    ctx->md = real;
}

void bench_section_memory(bench_ctx *ctx)
{
    const int repeats = ctx->quick ? 1 : 5;
    if (ctx->mem_fit) {
        fputs(ctx->mem_fit, ctx->md);
        free(ctx->mem_fit);
        ctx->mem_fit = NULL;
    }

    /* the largest lattice of section 2, in a forked child, against a child that does nothing */
    if (!ctx->largest_springs) {
        fprintf(ctx->md, "(lattice memory not measured: section 2 built no lattice)\n\n");
        return;
    }
    lat_job none = {0, 0}, big = {ctx->largest_cells, 1};
    double a[9], b[9];
    int ok = 1;
    for (int r = 0; r < repeats && ok; r++) {
        long k0 = bench_child_maxrss_kb(build_lattice, &none);
        long k1 = bench_child_maxrss_kb(build_lattice, &big);
        ok = k0 >= 0 && k1 >= 0;
        a[r] = (double)k0;
        b[r] = (double)k1;
    }
    if (!ok) {
        fprintf(ctx->md, "(lattice memory not measured: the child failed)\n\n");
        return;
    }
    bench_stats s0 = bench_summarise(a, repeats), s1 = bench_summarise(b, repeats);
    const double per = (s1.median - s0.median) * 1024.0 / (double)ctx->largest_springs;
    fprintf(ctx->md,
            "The largest lattice of section 2 (%d³ cells, %zu springs, face and body diagonals), "
            "built and run through one kernel pass in a forked child of the benchmark, against a "
            "forked child that does nothing (the benchmark's own pages):\n\n"
            "| run | peak RSS, KiB | above the floor, KiB | bytes per spring |\n|---|---|---|---|\n"
            "| forked child, nothing (floor) | %.0f | – | – |\n"
            "| %d³ lattice + one kernel pass | %.0f | %.0f | %.0f |\n\n"
            "Bytes per spring include the nodes (about one node per %.1f springs) and the force "
            "arrays; the lattice stores 8 doubles and 2 32-bit node indices (72 bytes) per spring and 10 doubles per node.\n\n",
            ctx->largest_cells, ctx->largest_springs, s0.median, ctx->largest_cells, s1.median,
            s1.median - s0.median, per,
            (double)ctx->largest_springs / pow(ctx->largest_cells + 1, 3));
}
