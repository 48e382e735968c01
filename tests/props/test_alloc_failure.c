/*
** Allocation failures inside GSL and NLopt: tests/alloc/failalloc.c, preloaded into the program,
** makes the N-th allocation made from GSL or NLopt code fail. For the fit (every solver of the
** three stages, the errors, the baselines), the lattice build of a simulation and the fit's
** validation in the lattice, each failure must end the run with exit 70 and a message and no
** output file, or leave the result exactly as it is without the failure; never a signal. The
** viscoelastic fit's Levenberg-Marquardt loop is covered by every allocation made while it runs,
** the program's own included (the injector's CF_FAIL_ALLOC_WITHIN). (GSL's
** own sparse triplet matrix crashed on such failures: the tangent's pattern is now built without
** it.) Skipped under AddressSanitizer, which replaces the allocator itself.
*/
#include <sys/stat.h>

#include "testutil.h"

#include <jansson.h>

static char dir[] = "/tmp/conifit-alloc-XXXXXX";
static char shim[600];
static char within[128]; /* "CF_FAIL_ALLOC_WITHIN=START:SIZE " or empty: see failalloc.c */

static int setup(void **state)
{
    (void)state;
    if (!mkdtemp(dir))
        return -1;
    snprintf(shim, sizeof shim, "%s/failalloc.so", dir);
    char cmd[1400];
    const char *cc = getenv("CC");
    snprintf(cmd, sizeof cmd, "%s -shared -fPIC -O1 -o %s tests/alloc/failalloc.c -ldl",
             cc && *cc ? cc : "cc", shim);
    return system(cmd) == 0 ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[256];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

/* Runs `conifit ARGS` (ARGS names the output OUT, replaced by dir/out) with the N-th GSL/NLopt
** allocation failing (n = 0: none; the count goes to dir/count); returns the exit status, or
** 128 + the signal. */
static int run(long n, const char *args, char *errtext, size_t cap)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd,
             "rm -f %s/out; %sCF_FAIL_ALLOC_AT=%ld CF_FAIL_ALLOC_REPORT=%s/count LD_PRELOAD=%s "
             "%s %s >/dev/null 2>%s/err",
             dir, within, n, dir, shim, tu_conifit(), args, dir);
    int st = system(cmd);
    char ep[700];
    snprintf(ep, sizeof ep, "%s/err", dir);
    FILE *f = fopen(ep, "rb");
    size_t k = f ? fread(errtext, 1, cap - 1, f) : 0;
    errtext[k] = '\0';
    if (f)
        fclose(f);
    if (WIFSIGNALED(st))
        return 128 + WTERMSIG(st);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static long count(void)
{
    char p[700];
    snprintf(p, sizeof p, "%s/count", dir);
    FILE *f = fopen(p, "r");
    long n = -1;
    if (f) {
        if (fscanf(f, "%ld", &n) != 1)
            n = -1;
        fclose(f);
    }
    return n;
}

/* The output file without what differs between runs (wall times); NULL when absent. */
static json_t *result(void)
{
    char p[700];
    snprintf(p, sizeof p, "%s/out", dir);
    json_t *r = json_load_file(p, 0, NULL);
    size_t i;
    json_t *f;
    json_array_foreach(json_object_get(r, "fits"), i, f) {
        json_object_del(f, "wall_time_s");
        json_t *v = json_object_get(f, "validation");
        if (v)
            json_object_del(v, "wall_time_s");
        json_t *th = json_object_get(f, "through_msm");
        if (th)
            json_object_del(th, "wall_time_s");
    }
    return r;
}

static int out_exists(void)
{
    char p[700];
    struct stat s;
    snprintf(p, sizeof p, "%s/out", dir);
    return stat(p, &s) == 0;
}

/* Fails the allocations first..last (every one when step is 1) of a run of args and checks each
** outcome against the undisturbed run (json: compare the fit files). */
static void inject(const char *args, long first, long last, long step, int json)
{
    char err[4096];
    assert_int_equal(run(0, args, err, sizeof err), 0);
    long total = count();
    json_t *ref = json ? result() : NULL;
    if (json)
        assert_non_null(ref);
    if (last > total)
        last = total;
    print_message("%s: %ld allocations %s; failing %ld..%ld step %ld\n", args, total,
                  within[0] ? "while the function runs" : "in GSL and NLopt", first, last, step);
    int failed = 0;
    for (long n = first; n <= last; n += step) {
        int st = run(n, args, err, sizeof err);
        if (st == 70) {
            failed++;
            if (!strstr(err, "out of memory"))
                fail_msg("allocation %ld: exit 70 without an out-of-memory message: %s", n, err);
            if (out_exists())
                fail_msg("allocation %ld: exit 70 but the output was written", n);
        } else if (st == 0) {
            if (json) {
                json_t *r = result();
                int same = r && json_equal(r, ref);
                json_decref(r);
                if (!same)
                    fail_msg("allocation %ld failed, exit 0 with a different result", n);
            }
        } else {
            fail_msg("allocation %ld: exit %d (%s): %s", n, st, st > 128 ? "signal" : "status",
                     err);
        }
    }
    assert_true(failed > 0);
    json_decref(ref);
}

static void fit_survives_every_solver_allocation_failure(void **state)
{
    (void)state;
    if (strstr(tu_conifit(), "asan"))
        skip();
    char args[800];
    snprintf(args, sizeof args, "fit data/telescoping.csv -q -o %s/out", dir);
    inject(args, 1, 40, 1, 1);
    inject(args, 41, 100000, 23, 1);
}

static void lattice_build_survives_allocation_failures(void **state)
{
    (void)state;
    if (strstr(tu_conifit(), "asan"))
        skip();
    char args[800];
    snprintf(args, sizeof args, "simulate data/scenes/uniaxial.json -q -o %s/out", dir);
    inject(args, 1, 100000, 1, 0);
    /* the validation's lattice after the fit: the last allocations of the run */
    snprintf(args, sizeof args, "fit data/telescoping.csv --validate -q -o %s/out", dir);
    char err[4096];
    assert_int_equal(run(0, args, err, sizeof err), 0);
    long total = count();
    inject(args, total > 80 ? total - 80 : 1, total, 3, 1);
}

/* The viscoelastic fit's Levenberg-Marquardt loop (cf_lm_iterate as viscofit calls it) and
** the model curves it computes: an allocation that fails while the loop runs ends the fit with 70
** and a message, and no file. (A failed curve inside the loop was taken for a bad point and the
** fit went on to a different result with exit 0; a failed iteration dropped its start.) */
static void visco_fit_lm_loop_survives_allocation_failures(void **state)
{
    (void)state;
    if (strstr(tu_conifit(), "asan"))
        skip();
    char cmd[800], line[256], start[40] = "", size[40] = "";
    snprintf(cmd, sizeof cmd, "nm -S --defined-only %s", tu_conifit());
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    while (fgets(line, sizeof line, p)) {
        char a[40], b[40], t[8], name[128];
        if (sscanf(line, "%39s %39s %7s %127s", a, b, t, name) == 4 &&
            strcmp(name, "cf_lm_iterate") == 0) {
            strcpy(start, a);
            strcpy(size, b);
        }
    }
    pclose(p);
    if (!start[0])
        fail_msg("cf_lm_iterate not found by '%s'", cmd);
    snprintf(within, sizeof within, "CF_FAIL_ALLOC_WITHIN=%s:%s ", start, size);
    char args[800];
    snprintf(args, sizeof args,
             "fit data/series/synthetic_relaxation.csv --branches 1 --relaxation qlv -q -o %s/out",
             dir);
    inject(args, 1, 100000, 67, 1);
    within[0] = '\0';
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(fit_survives_every_solver_allocation_failure),
        cmocka_unit_test(lattice_build_survives_allocation_failures),
        cmocka_unit_test(visco_fit_lm_loop_survives_allocation_failures),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
