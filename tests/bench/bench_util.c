/*
** Helpers the benchmark's sections share: CPU time, a child process's resources, and a noisy
** stress-strain table written as CSV.
*/
#include <stdio.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "bench.h"

double bench_cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int bench_exec(char *const argv[], struct rusage *ru)
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
    if (wait4(pid, &status, 0, ru) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
        return -1;
    return 0;
}

int bench_write_table(const char *path, size_t n, double xmax, double noise_sd, double scale,
                      double (*curve)(double x, const void *arg), const void *arg)
{
    FILE *f = fopen(path, "w");
    gsl_rng *r = gsl_rng_alloc(gsl_rng_mt19937);
    if (!f || !r) {
        if (f)
            fclose(f);
        gsl_rng_free(r);
        return -1;
    }
    gsl_rng_set(r, 1);
    fprintf(f, "strain,stress_kPa\n");
    for (size_t i = 0; i < n; i++) {
        double x = xmax * (double)i / (double)(n - 1);
        double y = curve(x, arg);
        y += gsl_ran_gaussian(r, noise_sd);
        fprintf(f, "%.17g,%.17g\n", x, scale * y);
    }
    gsl_rng_free(r);
    return fclose(f) == 0 ? 0 : -1;
}
