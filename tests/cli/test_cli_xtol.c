/*
** The reaction tolerance a lattice export states when its cells carry a volume term
** (export_lattice.c, propagated_tol): a 2^3 lattice of the synthetic telescoping fit with
** kappa 30 MPa, compressed to strain 0.4 in 11 steps (without kappa the lattice follows 9), tables at --tol 0.03. The springs' own
** error, summed over the springs a plane cuts (the tolerance of the same lattice without the
** volume term), is not all the volume term lets through: a table's error moves the equilibrium,
** and the cells turn that move into reaction, so the stated tolerance is larger (measured 2.3x).
** When ccx is installed, ccx's reaction at every step is conifit's within the stated tolerance.
*/
#include "testutil.h"

TU_SCRATCH_GROUP("xtol")

static char out[1 << 16], errb[1 << 14];

/* Exports the lattice with volume modulus kappa (MPa) into NAME.inp; returns the header's
** tolerance (N) and conifit's reactions (N) in ref (their count in *n). */
static double export_lattice(const char *fit, const char *kappa, const char *name, double *ref,
                             int *n)
{
    char scene[300], inp[300], text[600];
    snprintf(scene, sizeof scene, "%s/%s.json", dir, name);
    snprintf(inp, sizeof inp, "%s/%s.inp", dir, name);
    snprintf(text, sizeof text,
             "{\"spring\": {\"fit\": \"%s\"}, \"lattice\": {\"nx\": 2, \"ny\": 2, \"nz\": 2, "
             "\"volume_modulus_MPa\": %s}, \"protocol\": {\"kind\": \"ramp\", \"to_strain\": 0.4, "
             "\"duration_s\": 1}, \"samples_per_segment\": 11}",
             fit, kappa);
    assert_int_equal(tu_write_bytes(scene, text, strlen(text)), 0);
    if (tu_run(out, sizeof out, errb, sizeof errb,
               "export %s --lattice %s --format calculix --tol 0.03 -o %s", fit, scene, inp) != 0)
        fail_msg("export: %s", errb);
    char *x = tu_slurp(inp);
    assert_non_null(x);
    const char *p = strstr(x, "reaction tolerance implied by the tables: ");
    assert_non_null(p);
    const double tol = strtod(p + strlen("reaction tolerance implied by the tables: "), NULL);
    *n = 0;
    for (p = strstr(x, "conifit reaction "); p && *n < 16; p = strstr(p + 1, "conifit reaction "))
        ref[(*n)++] = strtod(p + strlen("conifit reaction "), NULL);
    free(x);
    assert_true(*n >= 2);
    return tol;
}

static void the_volume_term_widens_the_stated_tolerance(void **state)
{
    (void)state;
    char fit[300];
    snprintf(fit, sizeof fit, "%s/f.json", dir);
    if (tu_run(out, sizeof out, errb, sizeof errb, "fit data/telescoping.csv -o %s", fit) != 0)
        fail_msg("fit: %s", errb);
    double ref0[16], ref[16];
    int n0, n;
    const double cut = export_lattice(fit, "0", "plain", ref0, &n0);
    const double tol = export_lattice(fit, "30", "volume", ref, &n);
    print_message("stated reaction tolerance: %.6g N without the volume term, %.6g N with it\n",
                  cut, tol);
    assert_true(cut > 0 && isfinite(tol));
    assert_true(tol > 1.5 * cut); /* the lateral springs' error reaches the reaction */
    if (system("command -v ccx >/dev/null 2>&1") != 0)
        return; /* the export is checked; running it needs ccx (Makefile DEBS) */
    char cmd[700];
    snprintf(cmd, sizeof cmd, "cd '%s' && ccx -i volume > volume.log 2>&1", dir);
    assert_int_equal(system(cmd), 0);
    char dat[300];
    snprintf(dat, sizeof dat, "%s/volume.dat", dir);
    char *d = tu_slurp(dat);
    assert_non_null(d);
    int k = 0;
    double worst = 0.0;
    for (const char *p = strstr(d, "and time"); p; p = strstr(p + 1, "and time")) {
        char *end;
        const double time = strtod(p + strlen("and time"), &end);
        if (time != floor(time)) /* an increment inside a step */
            continue;
        double fx, fy, fz;
        assert_int_equal(sscanf(end, "%lf %lf %lf", &fx, &fy, &fz), 3);
        assert_true(k < n);
        const double diff = fabs(-fz - ref[k]);
        if (!(diff <= tol + 1e-6 * fabs(ref[k]))) /* ccx prints 7 digits */
            fail_msg("step %d: ccx %.7g N, conifit %.7g N (tolerance %.3g N)", k + 1, -fz, ref[k],
                     tol);
        worst = fmax(worst, diff);
        k++;
    }
    free(d);
    assert_int_equal(k, n);
    print_message("ccx against conifit: worst step %.3g N, %.3g of the stated tolerance, %.3g of "
                  "the springs' cut alone\n",
                  worst, worst / tol, worst / cut);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(the_volume_term_widens_the_stated_tolerance),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
