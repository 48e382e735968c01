/*
** conifit-bench: measures what accuracy costs in time at every stage of conifit and writes a
** Markdown report with tables and gnuplot plots.
** Usage: conifit-bench [--quick] [--progress|--no-progress] DIR
** (progress lines on stderr by default when stderr is a terminal).
** Every number in the report is measured by this program on the machine that runs it.
*/
#include "bench.h"

#include <locale.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/utsname.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <gsl/gsl_errno.h>

volatile double bench_sink;

double bench_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

bench_stats bench_summarise(double *x, int count)
{
    bench_stats s = {0, 0, 0, count};
    if (count <= 0)
        return s;
    qsort(x, (size_t)count, sizeof *x, cmp_double);
    s.min = x[0];
    s.max = x[count - 1];
    s.median = (count % 2) ? x[count / 2] : 0.5 * (x[count / 2 - 1] + x[count / 2]);
    return s;
}

FILE *bench_open_data(const bench_ctx *ctx, const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", ctx->dir, name);
    return fopen(path, "w");
}

/* gnuplot run in the report's folder with the script on its standard input: no shell, so the
** folder's name (a command-line argument) is never read as a command. */
int bench_gnuplot(const bench_ctx *ctx, const char *script)
{
    int fd[2];
    if (pipe(fd) != 0)
        return -1;
    pid_t pid = fork();
    if (pid < 0) {
        close(fd[0]);
        close(fd[1]);
        return -1;
    }
    if (pid == 0) {
        close(fd[1]);
        if (chdir(ctx->dir) != 0 || dup2(fd[0], 0) < 0)
            _exit(126);
        execlp("gnuplot", "gnuplot", (char *)NULL);
        _exit(127);
    }
    close(fd[0]);
    FILE *p = fdopen(fd[1], "w");
    if (p) {
        fputs(script, p);
        fclose(p);
    } else {
        close(fd[1]);
    }
    int st;
    if (waitpid(pid, &st, 0) != pid)
        return -1;
    return p && WIFEXITED(st) && WEXITSTATUS(st) == 0 ? 0 : -1;
}

void bench_target_add(bench_ctx *ctx, const char *name, int met, const char *fmt, ...)
{
    if (ctx->ntargets >= BENCH_MAX_TARGETS)
        return;
    bench_target *t = &ctx->targets[ctx->ntargets++];
    snprintf(t->name, sizeof t->name, "%s", name);
    t->met = met;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(t->measured, sizeof t->measured, fmt, ap);
    va_end(ap);
}

/* The closing table: every target of the benchmark with its measured value. */
static void write_targets(bench_ctx *ctx)
{
    fprintf(ctx->md, "## Targets\n\n| target | measured | verdict |\n|---|---|---|\n");
    for (int i = 0; i < ctx->ntargets; i++) {
        const bench_target *t = &ctx->targets[i];
        fprintf(ctx->md, "| %s | %s | %s |\n", t->name, t->measured,
                t->met > 0 ? "**met**" : t->met == 0 ? "**not met**" : "not measured");
    }
    fprintf(ctx->md, "\n");
}

int main(int argc, char **argv)
{
    setlocale(LC_ALL, "C");
    gsl_set_error_handler_off();
    bench_ctx ctx = {0};
    const char *dir = NULL;
    static const char usage[] = "usage: conifit-bench [--quick] [--progress|--no-progress] [--only WORD] DIR\n";
    int progress = isatty(STDERR_FILENO);
    const char *only = NULL; /* --only WORD: the sections whose name contains WORD */
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--quick") == 0)
            ctx.quick = 1;
        else if (strcmp(argv[i], "--progress") == 0)
            progress = 1;
        else if (strcmp(argv[i], "--no-progress") == 0)
            progress = 0;
        else if (strcmp(argv[i], "--only") == 0 && i + 1 < argc)
            only = argv[++i];
        else if (argv[i][0] == '-') {
            fputs(usage, stderr);
            return 2;
        } else
            dir = argv[i];
    }
    if (!dir) {
        fputs(usage, stderr);
        return 2;
    }
    ctx.dir = dir;
    char path[1024], tmp[1100];
    snprintf(path, sizeof path, "%s/REPORT.md", dir);
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    ctx.md = fopen(tmp, "w");
    if (!ctx.md) {
        fprintf(stderr, "conifit-bench: cannot write %s\n", tmp);
        return 73;
    }
    struct utsname un;
    uname(&un);
    fprintf(ctx.md, "# conifit benchmark report\n\n"
                    "What accuracy costs in time, measured by `make bench` (tests/bench/). Every "
                    "time is the median of repeated runs with the spread (min–max) beside it; "
                    "one core, `-O2`. Machine: %s %s.\n\n",
            un.sysname, un.machine);
    /* other work on the machine shows in the load average; the report states it when present */
    double load = -1;
    FILE *la = fopen("/proc/loadavg", "r");
    if (la) {
        if (fscanf(la, "%lf", &load) != 1)
            load = -1;
        fclose(la);
    }
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    if (load >= 0.5)
        fprintf(ctx.md, "Noise: the 1-minute load average was %.2f on %ld cores when the run "
                        "started (other work was running), which widens the spreads.\n\n",
                load, cores);
    double t0 = bench_now();
    static const struct {
        const char *what;
        void (*run)(bench_ctx *);
    } sections[] = {{"start-up", bench_section_startup},
                    {"memory of a fit", bench_memory_fit_early},
                    {"statics at scale (measured first: it forks)", bench_statics_early},
                    {"the force law", bench_section_law},
                    {"the spring with a cylindrical tail", bench_section_tail},
                    {"the lattice step", bench_section_lattice},
                    {"the double-acting element and the volume term", bench_section_pair},
                    {"the integrators", bench_section_integrators},
                    {"fitting", bench_section_fit},
                    {"lattice resolution", bench_section_resolution},
                    {"memory", bench_section_memory},
                    {"lattice calibration and the homogenised cell", bench_section_calibration},
                    {"viscoelastic fit", bench_section_visco},
                    {"statics at scale", bench_section_statics},
                    {"long tables", bench_section_longfit},
                    {"fits at the cost of the law", bench_section_fastfit},
                    {"tissue bodies: the probe loop", bench_section_body},
                    {"tissue bodies at organ scale (50,000 nodes)", bench_section_body_large},
                    {"output files: a --vtu series", bench_section_output},
                    {"tissue bodies: Hertz on the finest contact mesh", bench_section_contact}};
    const int nsec = (int)(sizeof sections / sizeof sections[0]);
    for (int k = 0; k < nsec; k++) {
        if (only && !strstr(sections[k].what, only))
            continue;
        if (progress)
            fprintf(stderr, "conifit-bench: [%d/%d] %s (%.0f s so far)\n", k + 1, nsec,
                    sections[k].what, bench_now() - t0);
        sections[k].run(&ctx);
    }
    write_targets(&ctx);
    fprintf(ctx.md, "\n---\nWhole benchmark run: %.0f s.\n", bench_now() - t0);
    if (fclose(ctx.md) != 0 || rename(tmp, path) != 0) {
        fprintf(stderr, "conifit-bench: cannot write %s\n", path);
        return 73;
    }
    fprintf(stderr, "conifit-bench: wrote %s\n", path);
    return 0;
}
