/*
** Tests of the export (src/out/export.c, conifit export): adaptive tables against the law on a dense
** grid of their own, the FEBio, LS-DYNA and SOFA layouts and values, the JSON round trip through
** `conifit force --spring`, error handling, and the proof: CalculiX (ccx) run on the exported
** springs, its reaction forces matched against the law at every step.
*/
#include <sys/stat.h>

#include "testutil.h"

#include "conifit/export.h"
#include "conifit/fitfile.h"
#include "conifit/law.h"

/* ccx prints forces with 7 significant digits. */
#define CCX_PRINT_REL 1e-6

static char dir[64];

static const cf_spring TEL = {10, 30, 4, 1, 80000, 40}; /* telescoping, s = 39 mm */
static const cf_spring NON = {10, 20, 6, 1, 80000, 40}; /* non-telescoping, s = 34 mm */

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/conifit-export-XXXXXX");
    if (!mkdtemp(dir))
        return -1;
    char p[128];
    snprintf(p, sizeof p, "%s/fit.json", dir);
    FILE *f = fopen(p, "w");
    if (!f)
        return -1;
    fprintf(f, "{\"conifit_version\":\"0.1.0\",\"data\":{\"file\":\"data/t.csv\",\"y_unit\":\"kPa\"},"
               "\"fits\":[{\"type\":\"telescoping\",\"params\":{\"D1_mm\":10,\"D2_mm\":30,\"n\":4,"
               "\"d_mm\":1,\"G_MPa\":80000,\"H_mm\":40},\"rmse\":0.5},{\"type\":\"non-telescoping\","
               "\"params\":{\"D1_mm\":10,\"D2_mm\":20,\"n\":6,\"d_mm\":1,\"G_MPa\":80000,\"H_mm\":40},"
               "\"rmse\":0.7}],\"better_type\":\"telescoping\"}\n");
    fclose(f);
    snprintf(p, sizeof p, "%s/tel_only.json", dir);
    f = fopen(p, "w");
    if (!f)
        return -1;
    fprintf(f, "{\"fits\":[{\"type\":\"telescoping\",\"params\":{\"D1_mm\":10,\"D2_mm\":30,\"n\":4,"
               "\"d_mm\":1,\"G_MPa\":80000,\"H_mm\":40}}]}\n");
    fclose(f);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    return system(cmd) == 0 ? 0 : -1;
}

static void law_of(cf_law *law, const cf_spring *p)
{
    cf_error err = {0};
    if (cf_law_init(law, p, &err) != CF_OK)
        fail_msg("spring refused: %s", err.msg);
}

/* Tension force (N) at elongation e (mm), in the simulators' convention. */
static double tension(const cf_law *law, double e)
{
    return -cf_law_force(law, CF_LAW_EXACT, -e, NULL, NULL);
}

static double allowed(const cf_law *law, double tol, double F)
{
    return tol * fmax(fabs(F), CF_EXPORT_FLOOR * law->F_C_N);
}

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = malloc((size_t)n + 1);
    size_t got = fread(buf, 1, (size_t)n, f);
    buf[got] = '\0';
    fclose(f);
    return buf;
}

/* Runs `conifit export ARGS -o DIR/name` and returns the file's text (caller frees). */
static char *export_to(const char *name, const char *args)
{
    char err[4096];
    int rc = tu_run(NULL, 0, err, sizeof err, "export %s/fit.json %s -o %s/%s", dir, args, dir,
                    name);
    if (rc != 0)
        fail_msg("conifit export %s exited %d: %s", args, rc, err);
    char p[160];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    char *text = slurp(p);
    assert_non_null(text);
    return text;
}

/* ---- tables ----------------------------------------------------------------------------------- */

static void check_table(const cf_spring *p, double tol)
{
    cf_law law;
    cf_export_table t;
    cf_error err = {0};
    law_of(&law, p);
    assert_int_equal(cf_export_table_build(&law, tol, &t, &err), CF_OK);
    /* rows ascend, are odd-symmetric, and include 0, +-u_T and the ends */
    int has0 = 0, hasT = 0;
    for (size_t i = 0; i < t.rows; i++) {
        if (i > 0)
            assert_true(t.u_mm[i] > t.u_mm[i - 1]);
        assert_close(t.u_mm[i], -t.u_mm[t.rows - 1 - i], 0.0);
        assert_close(t.F_N[i], -t.F_N[t.rows - 1 - i], 0.0);
        has0 |= t.u_mm[i] == 0.0;
        hasT |= t.u_mm[i] == law.u_T_mm;
    }
    assert_true(has0 && hasT);
    /* the end is where the law carries F_C (1 - tol), just short of solid */
    assert_close(t.F_N[t.rows - 1], law.F_C_N * (1 - tol), 1e-9 * law.F_C_N);
    assert_true(t.u_end_mm < law.travel_mm);
    /* an independent dense grid (a different count from the module's own check) */
    const int N = 99991;
    double worst = 0;
    for (int i = 0; i <= N; i++) {
        double u = -t.u_end_mm + 2.0 * t.u_end_mm * i / N;
        double w = (double)i / N; /* and crowded towards the end of the table */
        double v = t.u_end_mm * (1.0 - w * w * w * w);
        double us[2] = {u, v};
        for (int j = 0; j < 2; j++) {
            double F = cf_law_force(&law, CF_LAW_EXACT, us[j], NULL, NULL);
            double e = fabs(cf_export_table_eval(&t, us[j]) - F);
            if (e > allowed(&law, tol, F))
                fail_msg("tol %g: table off by %g N at u = %.17g (F = %g)", tol, e, us[j], F);
            worst = fmax(worst, e / fmax(fabs(F), CF_EXPORT_FLOOR * law.F_C_N));
        }
    }
    /* the reported error is a true bound of what we see, and is not vacuous */
    assert_true(t.max_err_rel <= tol);
    assert_true(t.max_err_rel > 0.1 * tol);
    assert_true(worst <= t.max_err_rel * 1.05);
    /* past the table, holding the last force is within tol F_C of the law up to solid (u_end is
    ** a double a few 1e-12 mm short of solid at tol 1e-6: its rounding moves F by ~0.1%) */
    assert_true(law.F_C_N - t.F_N[t.rows - 1] <= tol * law.F_C_N * (1 + 1e-2));
    cf_export_table_free(&t);
}

static void tables_stay_within_tolerance_on_a_dense_grid_for_both_types(void **state)
{
    (void)state;
    const double tols[3] = {1e-2, 1e-4, 1e-6};
    for (int i = 0; i < 3; i++) {
        check_table(&TEL, tols[i]);
        check_table(&NON, tols[i]);
    }
}

static void row_count_grows_like_inverse_square_root_of_tolerance(void **state)
{
    (void)state;
    cf_law law;
    cf_export_table a, b;
    cf_error err = {0};
    law_of(&law, &TEL);
    assert_int_equal(cf_export_table_build(&law, 1e-3, &a, &err), CF_OK);
    assert_int_equal(cf_export_table_build(&law, 1e-5, &b, &err), CF_OK);
    double ratio = (double)b.rows / (double)a.rows; /* ideal: sqrt(100) = 10 */
    assert_true(ratio > 7 && ratio < 13);
    cf_export_table_free(&a);
    cf_export_table_free(&b);
    assert_int_equal(cf_export_table_build(&law, 0.5, &a, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, "0.5"));
}

static void cylindrical_spring_needs_three_rows_and_a_linear_polynomial(void **state)
{
    (void)state;
    const cf_spring cyl = {20, 20, 5, 1, 80000, 30};
    cf_law law;
    cf_export_table t;
    cf_export_poly poly;
    cf_error err = {0};
    law_of(&law, &cyl);
    assert_int_equal(cf_export_table_build(&law, 1e-4, &t, &err), CF_OK);
    assert_int_equal(t.rows, 3);
    assert_true(t.max_err_rel < 1e-13);
    assert_int_equal(cf_export_poly_fit(&law, &t, 1, &poly, &err), CF_OK);
    /* force = k0 u = k0 H L: the single coefficient is k0 H */
    assert_close(poly.a_N[0], law.k0_N_per_mm * cyl.H_mm, 1e-12 * law.k0_N_per_mm * cyl.H_mm);
    cf_export_table_free(&t);
}

/* ---- layouts ---------------------------------------------------------------------------------- */

static void febio_output_follows_the_febio4_layout_and_the_law(void **state)
{
    (void)state;
    cf_law law;
    law_of(&law, &NON);
    char *x = export_to("s.feb", "--format febio --type non-telescoping --tol 1e-3");
    const char *order[] = {"<?xml",
                           "units: mm, N, s, tonne",
                           "<febio_spec version=\"4.0\">",
                           "<Mesh>",
                           "<DiscreteSet name=\"conifit_springs\">",
                           "<delem>",
                           "</Mesh>",
                           "<Discrete>",
                           "type=\"nonlinear spring\">",
                           "<measure>elongation</measure>",
                           "<force type=\"point\">",
                           "<interpolate>LINEAR</interpolate>",
                           "<extend>CONSTANT</extend>",
                           "<points>",
                           "<pt>",
                           "</points>",
                           "</discrete_material>",
                           "<discrete dmat=\"1\" discrete_set=\"conifit_springs\"/>",
                           "</Discrete>",
                           "</febio_spec>"};
    const char *at = x;
    for (size_t i = 0; i < sizeof order / sizeof order[0]; i++) {
        const char *hit = strstr(at, order[i]);
        if (!hit)
            fail_msg("FEBio output lacks '%s' after position %td", order[i], at - x);
        at = hit;
    }
    /* XML comments must not contain "--" */
    for (const char *c = strstr(x, "<!--"); c; c = strstr(c + 4, "<!--")) {
        const char *end = strstr(c + 4, "-->");
        assert_non_null(end);
        for (const char *q = c + 4; q < end; q++)
            assert_false(q[0] == '-' && q[1] == '-');
    }
    size_t n = 0;
    double prev = -INFINITY, e, F;
    for (const char *p = strstr(x, "<pt>"); p; p = strstr(p + 4, "<pt>")) {
        assert_int_equal(sscanf(p, "<pt>%lf,%lf</pt>", &e, &F), 2);
        assert_true(e > prev);
        assert_close(F, tension(&law, e), 1e-13 * law.F_C_N);
        prev = e;
        n++;
    }
    assert_true(n > 20);
    free(x);
}

static void lsdyna_output_has_keyword_order_and_fixed_width_fields(void **state)
{
    (void)state;
    cf_law law;
    law_of(&law, &TEL);
    char *x = export_to("s.k", "--format lsdyna --tol 1e-3");
    assert_non_null(strstr(x, "$ units: mm, N, s, tonne"));
    const char *kw[] = {"*KEYWORD\n", "*MAT_SPRING_NONLINEAR_ELASTIC\n", "*DEFINE_CURVE\n",
                        "*END\n"};
    const char *at = x;
    for (int i = 0; i < 4; i++) {
        const char *hit = strstr(at, kw[i]);
        if (!hit)
            fail_msg("LS-DYNA output lacks %s in order", kw[i]);
        at = hit;
    }
    /* data cards: skip comments ($) and keywords (*) */
    int card = 0;
    size_t points = 0;
    double prev = -INFINITY;
    char *save = NULL;
    for (char *line = strtok_r(x, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
        if (line[0] == '$' || line[0] == '*')
            continue;
        card++;
        char f[8][21];
        if (card == 1) { /* MID LCD LCR, 10 characters each */
            assert_int_equal(strlen(line), 30);
            for (int k = 0; k < 3; k++)
                snprintf(f[k], 11, "%.10s", line + 10 * k);
            assert_int_equal(atoi(f[0]), 1);
            assert_int_equal(atoi(f[1]), 1);
        } else if (card == 2) { /* LCID SIDR SFA SFO OFFA OFFO DATTYP */
            assert_int_equal(strlen(line), 70);
            snprintf(f[0], 11, "%.10s", line);
            assert_int_equal(atoi(f[0]), 1);
            snprintf(f[2], 11, "%.10s", line + 20);
            snprintf(f[3], 11, "%.10s", line + 30);
            assert_close(atof(f[2]), 1.0, 0.0);
            assert_close(atof(f[3]), 1.0, 0.0);
        } else { /* A1 O1, 20 characters each */
            assert_int_equal(strlen(line), 40);
            snprintf(f[0], 21, "%.20s", line);
            snprintf(f[1], 21, "%.20s", line + 20);
            double e = atof(f[0]), F = atof(f[1]);
            assert_true(e > prev);
            prev = e;
            /* 13 digits of elongation: near solid the law at the printed abscissa moves by
            ** the (huge) stiffness times the rounding, still far within the tolerance */
            assert_close(F, tension(&law, e), allowed(&law, 1e-3, F) * 1e-2);
            points++;
        }
    }
    assert_true(points > 20);
    free(x);
}

static void sofa_polynomial_error_is_reported_truthfully(void **state)
{
    (void)state;
    cf_law law;
    law_of(&law, &TEL);
    double reported[2];
    const int degrees[2] = {3, 11};
    for (int r = 0; r < 2; r++) {
        char args[64];
        snprintf(args, sizeof args, "--format sofa --degree %d", degrees[r]);
        char *x = export_to("s.scn", args);
        assert_non_null(strstr(x, "units: mm, N, s, tonne"));
        const char *pf = strstr(x, "<PolynomialSpringsForceField ");
        assert_non_null(pf);
        int deg = 0;
        assert_int_equal(sscanf(strstr(pf, "polynomialDegree=\""), "polynomialDegree=\"%d", &deg),
                         1);
        assert_int_equal(deg, degrees[r]);
        const char *c = strstr(pf, "polynomialStiffness=\"") + strlen("polynomialStiffness=\"");
        cf_export_poly poly = {.degree = deg};
        for (int k = 0; k < deg; k++) {
            char *end;
            poly.a_N[k] = strtod(c, &end);
            assert_true(end > c);
            c = end;
        }
        assert_int_equal(*c, '"');
        assert_non_null(strstr(pf, "zeroLength=\"40\""));
        const char *m = strstr(x, "maximum error against the law ");
        assert_non_null(m);
        reported[r] = atof(m + strlen("maximum error against the law "));
        /* our own evaluation of the file's polynomial never exceeds the reported error by more
        ** than the grid can miss, and reaches close to it */
        double worst = 0;
        const double L_end = 0.9999 * law.travel_mm / law.p.H_mm;
        for (int i = 0; i <= 20000; i++) {
            double L = -L_end + 2 * L_end * i / 20000.0;
            worst = fmax(worst, fabs(cf_export_poly_eval(&poly, L) - tension(&law, L * 40)));
        }
        assert_true(worst <= reported[r] * 1.001);
        assert_true(worst >= reported[r] * 0.5);
        free(x);
    }
    assert_true(reported[1] < reported[0]); /* a higher degree fits better */
}

static void csv_and_inp_blocks_have_their_layout(void **state)
{
    (void)state;
    cf_law law;
    law_of(&law, &TEL);
    char *x = export_to("s.csv", "--format csv --tol 1e-3");
    assert_true(strncmp(x, "u_mm,force_N,stiffness_N_per_mm\n", 32) == 0);
    free(x);
    x = export_to("s.inp", "--format abaqus --tol 1e-3");
    assert_non_null(strstr(x, "** units: mm, N, s, tonne"));
    const char *b = strstr(x, "*SPRING, ELSET=CONIFIT_SPRING, NONLINEAR\n\n");
    assert_non_null(b);
    b = strchr(b, '\n') + 2;
    double prev = -INFINITY, F, e;
    int n = 0, used;
    while (sscanf(b, "%lf, %lf\n%n", &F, &e, &used) == 2) {
        assert_true(e > prev); /* elongation ascending, force first */
        assert_close(F, tension(&law, e), 1e-13 * law.F_C_N);
        prev = e;
        b += used;
        n++;
    }
    assert_true(n > 20);
    assert_int_equal(*b, '\0');
    free(x);
}

/* ---- command line ----------------------------------------------------------------------------- */

static void json_round_trips_through_force_spring(void **state)
{
    (void)state;
    const char *types[2] = {"telescoping", "non-telescoping"};
    const cf_spring *ps[2] = {&TEL, &NON};
    for (int k = 0; k < 2; k++) {
        char args[64], name[32];
        snprintf(args, sizeof args, "--format json --type %s", types[k]);
        snprintf(name, sizeof name, "%s.json", types[k]);
        free(export_to(name, args));
        const double us[5] = {-33.9, -12.5, 0.5, 20.25, 33.99};
        for (int i = 0; i < 5; i++) {
            char a[64], b[64];
            assert_int_equal(tu_run(a, sizeof a, NULL, 0, "force --spring %s/%s --u %.17g", dir,
                                    name, us[i]),
                             0);
            const cf_spring *p = ps[k];
            assert_int_equal(tu_run(b, sizeof b, NULL, 0,
                                    "force --D1 %.17g --D2 %.17g --n %.17g --d %.17g --G %.17g "
                                    "--H %.17g --u %.17g",
                                    p->D1_mm, p->D2_mm, p->n, p->d_mm, p->G_MPa, p->H_mm, us[i]),
                             0);
            assert_string_equal(a, b);
        }
        /* and from the fit file itself, with the type suffix */
        char a[64], b[64];
        assert_int_equal(tu_run(a, sizeof a, NULL, 0, "force --spring %s/fit.json:%s --u 7", dir,
                                types[k]),
                         0);
        assert_int_equal(tu_run(b, sizeof b, NULL, 0, "force --spring %s/%s --u 7", dir, name), 0);
        assert_string_equal(a, b);
    }
    char out[4096];
    assert_int_equal(tu_run(out, sizeof out, NULL, 0, "info --spring %s/non-telescoping.json", dir),
                     0);
    assert_non_null(strstr(out, "non-telescoping"));
    assert_int_equal(tu_run(NULL, 0, NULL, 0, "force --spring %s/fit.json --D1 3 --u 1", dir), 2);
}

static void bad_fit_files_give_their_exit_status_and_no_output(void **state)
{
    (void)state;
    char out[256], err[1024], p[160];
    struct stat st;
    snprintf(p, sizeof p, "%s/never.csv", dir);
    /* missing */
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "export %s/absent.json --format csv",
                            dir),
                     66);
    assert_string_equal(out, "");
    assert_non_null(strstr(err, "absent.json"));
    /* lacking the type */
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err,
                            "export %s/tel_only.json --type non-telescoping --format csv -o %s",
                            dir, p),
                     65);
    assert_non_null(strstr(err, "non-telescoping"));
    assert_int_equal(stat(p, &st), -1);
    /* malformed */
    char bad[160];
    snprintf(bad, sizeof bad, "%s/bad.json", dir);
    FILE *f = fopen(bad, "w");
    fputs("{\"fits\": [ {\"type\": ", f);
    fclose(f);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "export %s --format csv", bad), 65);
    assert_string_equal(out, "");
    /* usage */
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "export %s/fit.json --format vtk", dir), 2);
    assert_non_null(strstr(err, "vtk"));
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "export %s/fit.json", dir), 2);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "export %s/fit.json --format csv --tol 2",
                            dir),
                     2);
    /* refusing to overwrite the input */
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "export %s/fit.json --format csv -o %s/fit.json",
                            dir, dir),
                     73);
    /* the row count and error on stderr */
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "export %s/fit.json --format csv "
                                                              "--tol 0.01 -o %s/ok.csv",
                            dir, dir),
                     0);
    assert_non_null(strstr(err, "rows, max error"));
    /* calculix refuses a table longer than it reads, unless the tolerance is left to it */
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "export %s/fit.json --format calculix "
                                                      "--tol 1e-6", dir),
                     65);
    assert_non_null(strstr(err, "200"));
}

/* ---- the proof: CalculiX reads the export back ---------------------------------------------- */

/* Parses the .dat: for each step, node 2's x-displacement and x-reaction. Returns the count. */
static int parse_dat(const char *text, double *disp, double *rf, int cap)
{
    int nd = 0, nf = 0;
    for (const char *p = text; (p = strstr(p, " for set ")) != NULL; p++) {
        const char *line_start = p;
        while (line_start > text && line_start[-1] != '\n')
            line_start--;
        const char *body = strstr(p, "\n\n");
        if (!body)
            break;
        int node;
        double v;
        if (sscanf(body, " %d %lf", &node, &v) != 2 || node != 2)
            continue;
        if (strncmp(line_start, " displacements", 14) == 0 && nd < cap)
            disp[nd++] = v;
        else if (strncmp(line_start, " forces", 7) == 0 && nf < cap)
            rf[nf++] = v;
    }
    assert_int_equal(nd, nf);
    return nd;
}

static void run_ccx(const char *job)
{
    char cmd[256];
    snprintf(cmd, sizeof cmd, "cd %s && ccx -i %s > %s.log 2>&1", dir, job, job);
    int rc = system(cmd);
    if (!(WIFEXITED(rc) && WEXITSTATUS(rc) == 0))
        fail_msg("ccx failed on %s/%s.inp (see its .log)", dir, job);
}

static void check_ccx_against_law(const cf_law *law, const char *job, double tol, int expect)
{
    char p[160];
    snprintf(p, sizeof p, "%s/%s.dat", dir, job);
    char *dat = slurp(p);
    assert_non_null(dat);
    double disp[64], rf[64];
    int n = parse_dat(dat, disp, rf, 64);
    free(dat);
    assert_int_equal(n, expect);
    for (int i = 0; i < n; i++) {
        double want = tension(law, disp[i]);
        double bound = allowed(law, tol, want) + CCX_PRINT_REL * fabs(want);
        if (!(fabs(rf[i] - want) <= bound))
            fail_msg("%s step %d: ccx reaction %.7g N at elongation %.7g mm, law %.7g N (bound "
                     "%.3g)",
                     job, i + 1, rf[i], disp[i], want, bound);
    }
}

static void calculix_reads_the_export_and_matches_the_law_at_every_step(void **state)
{
    (void)state;
    if (system("command -v ccx >/dev/null 2>&1") != 0)
        fail_msg("ccx (Debian package calculix-ccx) is not installed: run 'make deps'");
    const char *types[2] = {"telescoping", "non-telescoping"};
    const cf_spring *ps[2] = {&TEL, &NON};
    const double tol = 1e-3;
    /* stretch and compression: inside region 1, across the transition, deep in region 2 and
    ** a hair before solid, in both directions */
    const double frac[8] = {0.2, -0.2, 0.55, -0.55, 0.9, -0.9, 0.999999, -0.999999};
    for (int k = 0; k < 2; k++) {
        cf_law law;
        law_of(&law, ps[k]);
        char args[96], name[48];
        snprintf(args, sizeof args, "--format calculix --type %s --tol %g", types[k], tol);
        snprintf(name, sizeof name, "block_%d.inp", k);
        char *block = export_to(name, args);
        /* the *SPRING block pasted into a model of our own */
        double u_end = cf_law_deflection(&law, law.F_C_N * (1 - tol));
        char job[32], path[160];
        snprintf(job, sizeof job, "model_%d", k);
        snprintf(path, sizeof path, "%s/%s.inp", dir, job);
        FILE *f = fopen(path, "w");
        assert_non_null(f);
        fprintf(f, "*NODE, NSET=NALL\n1, 0, 0, 0\n2, %.17g, 0, 0\n", ps[k]->H_mm);
        fprintf(f, "*NSET, NSET=N2\n2\n*ELEMENT, TYPE=SPRINGA, ELSET=CONIFIT_SPRING\n1, 1, 2\n");
        fputs(block, f);
        fprintf(f, "*BOUNDARY\n1, 1, 3\n2, 2, 3\n");
        for (int i = 0; i < 8; i++)
            fprintf(f, "*STEP\n*STATIC\n*BOUNDARY\n2, 1, 1, %.17g\n*NODE PRINT, NSET=N2\nU, RF\n"
                       "*END STEP\n",
                    frac[i] * u_end);
        fclose(f);
        free(block);
        run_ccx(job);
        check_ccx_against_law(&law, job, tol, 8);
        /* and the complete example model, as written */
        snprintf(args, sizeof args, "--format calculix --type %s --example", types[k]);
        snprintf(job, sizeof job, "example_%d", k);
        snprintf(name, sizeof name, "%s.inp", job);
        char err[1024];
        assert_int_equal(tu_run(NULL, 0, err, sizeof err, "export %s/fit.json %s -o %s/%s", dir,
                                args, dir, name),
                         0);
        double used_tol = atof(strstr(err, "tol ") + 4);
        assert_true(used_tol >= 1e-4 && used_tol <= 1e-2);
        run_ccx(job);
        check_ccx_against_law(&law, job, used_tol, 4);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(tables_stay_within_tolerance_on_a_dense_grid_for_both_types),
        cmocka_unit_test(row_count_grows_like_inverse_square_root_of_tolerance),
        cmocka_unit_test(cylindrical_spring_needs_three_rows_and_a_linear_polynomial),
        cmocka_unit_test(febio_output_follows_the_febio4_layout_and_the_law),
        cmocka_unit_test(lsdyna_output_has_keyword_order_and_fixed_width_fields),
        cmocka_unit_test(sofa_polynomial_error_is_reported_truthfully),
        cmocka_unit_test(csv_and_inp_blocks_have_their_layout),
        cmocka_unit_test(json_round_trips_through_force_spring),
        cmocka_unit_test(bad_fit_files_give_their_exit_status_and_no_output),
        cmocka_unit_test(calculix_reads_the_export_and_matches_the_law_at_every_step),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
