/*
** The memory budget against what a run really takes: static scenes of a few sizes, each run as a
** child whose peak resident memory (getrusage ru_maxrss through wait4) must stay below the
** estimate the budget refuses with (the program, the lattice, the tangent and the sparse
** factorisation's fill), and the estimate within a factor of two of it, so that it neither lets
** through a lattice that takes gigabytes nor refuses one that fits. Kept to seconds: 6^3 to 13^3.
** A scene's spring groups are in the estimate: a 9^3 scene whose law is evaluated by a table of
** 400,000 intervals estimates more with two groups (a table per group's law, the grouped kernel's
** arrays) than without, by at least the two tables, and each run's peak stays below its estimate
** and above half of it.
*/
#include <sys/resource.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <unistd.h>

#include "testutil.h"

static char out[1 << 14], errb[1 << 14];
TU_SCRATCH_GROUP("budgetpeak")

/* A static ramp of an n^3 lattice with two samples into dir/peakN.json. */
static void cube_scene(int n, char *path, size_t cap)
{
    snprintf(path, cap, "%s/peak%d.json", dir, n);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fprintf(f, "{\"spring\": {\"params\": {\"D1_mm\": 6, \"D2_mm\": 15, \"n\": 2.5, \"d_mm\": 2, "
               "\"G_MPa\": 26, \"H_mm\": 10}}, \"lattice\": {\"nx\": %d, \"ny\": %d, \"nz\": %d, "
               "\"calibration\": \"isotropic\", \"bottom\": \"axial\"}, \"protocol\": {\"kind\": "
               "\"ramp\", \"to_strain\": 0.05, \"duration_s\": 1}, \"samples_per_segment\": 2}\n",
            n, n, n);
    assert_int_equal(fclose(f), 0);
}

#define TABLE_INTERVALS 400000
#define GROUP_SPRING "{\"params\": {\"D1_mm\": 6, \"D2_mm\": 15, \"n\": 2.5, \"d_mm\": 2, " \
                     "\"G_MPa\": 52, \"H_mm\": 10}}"

/* A static ramp of a 9^3 lattice with its law by table (TABLE_INTERVALS intervals) into
** dir/tableG.json; with groups, the face and the body springs on a spring twice as stiff. */
static void table_scene(int groups, char *path, size_t cap)
{
    snprintf(path, cap, "%s/table%d.json", dir, groups);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fprintf(f, "{\"spring\": {\"params\": {\"D1_mm\": 6, \"D2_mm\": 15, \"n\": 2.5, \"d_mm\": 2, "
               "\"G_MPa\": 26, \"H_mm\": 10}}, %s\"law_method\": \"table\", "
               "\"table_intervals\": %d, \"lattice\": {\"nx\": 9, \"ny\": 9, \"nz\": 9, "
               "\"calibration\": \"isotropic\", \"bottom\": \"axial\"}, \"protocol\": {\"kind\": "
               "\"ramp\", \"to_strain\": 0.05, \"duration_s\": 1}, \"samples_per_segment\": 2}\n",
            groups ? "\"groups\": [{\"springs\": \"face\", \"spring\": " GROUP_SPRING "}, "
                     "{\"springs\": \"body\", \"spring\": " GROUP_SPRING "}], "
                   : "",
            TABLE_INTERVALS);
    assert_int_equal(fclose(f), 0);
}

/* The estimate in MiB, read from the refusal under a limit nothing fits. */
static double estimate_mib(const char *scene)
{
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "simulate %s -o %s/e.csv --max-memory 1K", scene, dir),
                     65);
    const char *p = strstr(errb, "needs about ");
    assert_non_null(p);
    return strtod(p + strlen("needs about "), NULL);
}

/* The run's peak resident memory in MiB (its exit status must be 0). */
static double peak_mib(const char *scene)
{
    char csv[512];
    snprintf(csv, sizeof csv, "%s/p.csv", dir);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        int null = open("/dev/null", O_WRONLY);
        if (null >= 0) {
            dup2(null, 1);
            dup2(null, 2);
        }
        execl(tu_conifit(), tu_conifit(), "simulate", scene, "-o", csv, "-q", (char *)NULL);
        _exit(127);
    }
    int st = 0;
    struct rusage ru;
    assert_int_equal(wait4(pid, &st, 0, &ru), pid);
    assert_true(WIFEXITED(st));
    assert_int_equal(WEXITSTATUS(st), 0);
    return ru.ru_maxrss / 1024.0; /* kilobytes on Linux */
}

static void estimate_bounds_the_real_peak(void **state)
{
    (void)state;
    if (strstr(tu_conifit(), "asan") || getenv("CONIFIT_WRAPPER"))
        skip(); /* the sanitizer's shadow memory is no part of the estimate */
    const int sizes[] = {6, 9, 13};
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
        char scene[512];
        cube_scene(sizes[i], scene, sizeof scene);
        const double est = estimate_mib(scene), real = peak_mib(scene);
        print_message("%d^3: estimate %.0f MiB, peak %.1f MiB\n", sizes[i], est, real);
        if (!(real <= est))
            fail_msg("%d^3: the run peaked at %.1f MiB, above the estimate %.0f MiB", sizes[i],
                     real, est);
        if (!(est <= 2 * real))
            fail_msg("%d^3: the estimate %.0f MiB is more than twice the peak %.1f MiB",
                     sizes[i], est, real);
    }
}

static void groups_are_in_the_estimate(void **state)
{
    (void)state;
    if (strstr(tu_conifit(), "asan") || getenv("CONIFIT_WRAPPER"))
        skip(); /* the sanitizer's shadow memory is no part of the estimate */
    double est[2], real[2];
    for (int g = 0; g < 2; g++) {
        char scene[512];
        table_scene(g, scene, sizeof scene);
        est[g] = estimate_mib(scene);
        real[g] = peak_mib(scene);
        print_message("9^3, law by table, %s: estimate %.0f MiB, peak %.1f MiB\n",
                      g ? "two spring groups" : "no groups", est[g], real[g]);
        if (!(real[g] <= est[g] && est[g] <= 2 * real[g]))
            fail_msg("%s groups: peak %.1f MiB against the estimate %.0f MiB (must lie between "
                     "half of it and it)", g ? "two" : "no", real[g], est[g]);
    }
    /* the two groups' tables: two values an end and four coefficients an interval */
    const double tables = 2 * 48.0 * (TABLE_INTERVALS + 1) / (1024.0 * 1024.0);
    assert_true(est[1] - est[0] >= floor(tables));
    assert_true(real[1] - real[0] > 0.5 * tables); /* and the run holds them */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(estimate_bounds_the_real_peak),
        cmocka_unit_test(groups_are_in_the_estimate),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
