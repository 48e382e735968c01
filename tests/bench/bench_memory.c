/*
** Benchmark section 6: memory. Peak resident set (getrusage ru_maxrss of a child process) of
** `conifit fit` on the shipped and published tables, against the same binary doing nothing but
** printing its help.
*/
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bench.h"

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
    fflush(NULL);
    pid_t pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        if (!freopen("/dev/null", "w", stdout) || !freopen("/dev/null", "w", stderr))
            _exit(127);
        execv(argv[0], argv);
        _exit(127);
    }
    int status;
    struct rusage ru;
    if (wait4(pid, &status, 0, &ru) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
        return -1;
    return ru.ru_maxrss;
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

void bench_section_memory(bench_ctx *ctx)
{
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
    fprintf(ctx->md, "\n");
}
