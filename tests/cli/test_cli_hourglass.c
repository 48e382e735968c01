/*
** The lattice's hourglass control in a CalculiX export (export_inp.c, lattice_hourglass.h): a
** 2^3 lattice of the brain cortex's compression fit, clamped at its base (a non-uniform state,
** where the control acts), with hourglass 2 and 0. The file with it holds the *EQUATION and the
** SPRING1 that carry it, the file without holds neither; conifit's reactions differ by the
** control's share; and, when ccx is installed, ccx's reaction at every step is conifit's within
** the header's tolerance, with and without (measured: within 1e-6 at the first step, where the
** control adds 1.2 %).
*/
#include "testutil.h"

#include <sys/stat.h>

TU_SCRATCH_GROUP("hourglass")

static char out[1 << 16], errb[1 << 14];

/* Exports the clamped lattice at hourglass fraction hg into sub-folder hN and returns conifit's
** reactions (N) of the 4 steps; runs ccx there when it is installed (*ran 1) and returns its
** reactions in ccx_N. */
static void export_and_run(const char *fit, int hg, double ref[4], double ccx_N[4], double *tol,
                           int *ran)
{
    char sub[300], scene[340], inp[340], text[600];
    snprintf(sub, sizeof sub, "%s/h%d", dir, hg);
    assert_int_equal(mkdir(sub, 0700), 0);
    snprintf(scene, sizeof scene, "%s/scene.json", sub);
    snprintf(inp, sizeof inp, "%s/lat.inp", sub);
    snprintf(text, sizeof text,
             "{\"spring\": {\"fit\": \"%s\"}, \"lattice\": {\"nx\": 2, \"ny\": 2, \"nz\": 2, "
             "\"bottom\": \"clamped\", \"hourglass\": %d}, \"protocol\": {\"kind\": \"ramp\", "
             "\"to_strain\": 0.1, \"duration_s\": 1}, \"samples_per_segment\": 4}",
             fit, hg);
    assert_int_equal(tu_write_bytes(scene, text, strlen(text)), 0);
    if (tu_run(out, sizeof out, errb, sizeof errb, "export %s --lattice %s --format calculix -o %s",
               fit, scene, inp) != 0)
        fail_msg("export: %s", errb);
    char *x = tu_slurp(inp);
    assert_non_null(x);
    assert_int_equal(strstr(x, "TYPE=SPRING1") != NULL, hg > 0);
    assert_int_equal(strstr(x, "*EQUATION") != NULL, hg > 0);
    const char *p = strstr(x, "reaction tolerance implied by the tables: ");
    assert_non_null(p);
    *tol = strtod(p + strlen("reaction tolerance implied by the tables: "), NULL);
    int n = 0;
    for (p = strstr(x, "conifit reaction "); p && n < 4; p = strstr(p + 1, "conifit reaction "))
        ref[n++] = strtod(p + strlen("conifit reaction "), NULL);
    free(x);
    assert_int_equal(n, 4);
    *ran = system("command -v ccx >/dev/null 2>&1") == 0;
    if (!*ran)
        return; /* the export is checked; running it needs ccx (Makefile DEBS) */
    char cmd[700];
    snprintf(cmd, sizeof cmd, "cd '%s' && ccx -i lat > lat.log 2>&1", sub);
    assert_int_equal(system(cmd), 0);
    char dat[340];
    snprintf(dat, sizeof dat, "%s/lat.dat", sub);
    char *d = tu_slurp(dat);
    assert_non_null(d);
    int k = 0;
    for (p = strstr(d, "total force"); p && k < 4; p = strstr(p + 1, "total force")) {
        const char *line = strchr(p, '\n');
        assert_non_null(line);
        double fx, fy, fz;
        assert_int_equal(sscanf(line, "%lf %lf %lf", &fx, &fy, &fz), 3);
        ccx_N[k++] = -fz;
    }
    free(d);
    assert_int_equal(k, 4);
}

static void calculix_carries_the_hourglass_control(void **state)
{
    (void)state;
    const char *ds = tu_datasets();
    if (!ds)
        skip();
    char fit[300];
    snprintf(fit, sizeof fit, "%s/f.json", dir);
    if (tu_run(out, sizeof out, errb, sizeof errb, "fit %s/brain_cortex_compression.csv -o %s", ds,
               fit) != 0)
        fail_msg("fit: %s", errb);
    double r0[4], r2[4], c0[4], c2[4], tol0, tol2;
    int ran0, ran2;
    export_and_run(fit, 0, r0, c0, &tol0, &ran0);
    export_and_run(fit, 2, r2, c2, &tol2, &ran2);
    for (int k = 0; k < 4; k++) {
        print_message("step %d: conifit %.9g N without hourglass control, %.9g N with\n", k + 1,
                      r0[k], r2[k]);
        assert_true(r2[k] > r0[k] * 1.005); /* the clamped block feels the control */
        if (!ran0 || !ran2)
            continue;
        print_message("        ccx %.9g N without, %.9g N with\n", c0[k], c2[k]);
        assert_true(fabs(c0[k] - r0[k]) <= tol0);
        assert_true(fabs(c2[k] - r2[k]) <= tol2);
    }
    if (ran0 && ran2) /* at the first step (in the table's finest rows) far closer than the effect */
        assert_true(fabs(c2[0] - r2[0]) < 0.01 * (r2[0] - r0[0]));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(calculix_carries_the_hourglass_control),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
