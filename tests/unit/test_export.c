/*
** Tests of the export (src/export/export*.c, conifit export):
**  - tables: within tol F_C of the law on a dense grid of their own, rows where the error is (at
**    most 200 at 1e-4 for every rho >= 0.05; the shipped fits through the command line), ranges;
**  - each format parsed back and every number checked against the law: the CalculiX/Abaqus and
**    FEBio blocks, the LS-DYNA curve with LCINT >= rows, the SOFA scene (compressible read back,
**    the force SOFA computes from the file's springs), the lattice models of every format;
**  - the proof by running: CalculiX (ccx) on the exported single spring and on the exported
**    lattice, its reactions matched against the law and against `conifit simulate`;
**  - bad input: exit status, message with the number that works, nothing written;
**  - a tail so stiff that the table's error stops falling (n_tail 1e-15: the table grew without
**    bound) is refused, naming n_tail and its value, while tails of 1e-6 coils still tabulate.
*/
#include <sys/stat.h>

#include "testutil.h"

#include <glob.h>

#include "model/body.h"
#include "export/export.h"
#include "io/fitfile.h"
#include "model/law_internal.h"

/* ccx prints forces with 7 significant digits. */
#define CCX_PRINT_REL 1e-6

static char dir[64];

static const cf_spring TEL = {10, 30, 4, 1, 80000, 40}; /* telescoping, s = 39 mm */
static const cf_spring NON = {10, 20, 6, 1, 80000, 40}; /* non-telescoping, s = 34 mm */
/* TEL's cone in 30 mm of the free length and a cylindrical tail of one coil in the other 10: the
** cone closes at u_C = 36.25 mm (F_C = 72.5 N), the tail at 38 mm (F_solid = 90 N) */
static const cf_spring TAIL = {10, 30, 4, 1, 80000, 40, 1, 10};

/* Writes text into the file name of the test's folder: 0, or -1 when it cannot. */
static int write_in_dir(const char *name, const char *text)
{
    char p[128];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    FILE *f = fopen(p, "w");
    if (!f)
        return -1;
    fputs(text, f);
    return fclose(f) == 0 ? 0 : -1;
}

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/conifit-export-XXXXXX");
    if (!mkdtemp(dir))
        return -1;
    if (write_in_dir("fit.json",
                     "{\"conifit_version\":\"0.1.0\",\"data\":{\"file\":\"data/t.csv\",\"y_unit\":"
                     "\"kPa\"},\"fits\":[{\"type\":\"telescoping\",\"params\":{\"D1_mm\":10,"
                     "\"D2_mm\":30,\"n\":4,\"d_mm\":1,\"G_MPa\":80000,\"H_mm\":40},\"rmse\":0.5},"
                     "{\"type\":\"non-telescoping\",\"params\":{\"D1_mm\":10,\"D2_mm\":20,\"n\":6,"
                     "\"d_mm\":1,\"G_MPa\":80000,\"H_mm\":40},\"rmse\":0.7}],\"better_type\":"
                     "\"telescoping\"}\n") != 0)
        return -1;
    if (write_in_dir("tel_only.json",
                     "{\"fits\":[{\"type\":\"telescoping\",\"params\":{\"D1_mm\":10,\"D2_mm\":30,"
                     "\"n\":4,\"d_mm\":1,\"G_MPa\":80000,\"H_mm\":40}}]}\n") != 0)
        return -1;
    /* TAIL */
    return write_in_dir("tail.json",
                        "{\"fits\":[{\"type\":\"telescoping\",\"params\":{\"D1_mm\":10,\"D2_mm\":30,"
                        "\"n\":4,\"d_mm\":1,\"G_MPa\":80000,\"H_mm\":40,\"n_tail\":1,"
                        "\"H_tail_mm\":10}}]}\n");
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

/* Runs `conifit export FIT ARGS -o DIR/name` and returns the file's text (caller frees). */
static char *export_file(const char *fit, const char *name, const char *args)
{
    char err[4096];
    int rc = tu_run(NULL, 0, err, sizeof err, "export %s %s -o %s/%s", fit, args, dir, name);
    if (rc != 0)
        fail_msg("conifit export %s %s exited %d: %s", fit, args, rc, err);
    char p[160];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    char *text = tu_slurp(p);
    assert_non_null(text);
    return text;
}

static char *export_to(const char *name, const char *args)
{
    char fit[96];
    snprintf(fit, sizeof fit, "%s/fit.json", dir);
    return export_file(fit, name, args);
}

/* The same from the test's fit file of the tailed spring. */
static char *export_tail(const char *name, const char *args)
{
    char fit[96];
    snprintf(fit, sizeof fit, "%s/tail.json", dir);
    return export_file(fit, name, args);
}

static int have_ccx(void)
{
    return system("command -v ccx >/dev/null 2>&1") == 0;
}

/* ---- tables ----------------------------------------------------------------------------------- */

static void check_table(const cf_spring *p, double tol)
{
    cf_law law;
    cf_export_table t;
    cf_error err = {0};
    law_of(&law, p);
    assert_int_equal(cf_export_table_build(&law, tol, &t, &err), CF_OK);
    /* rows ascend, are odd-symmetric, and include 0, +-u_T and the ends, which lie on the law
    ** (and, with a tail, +-u_C where the cone closes) */
    int has0 = 0, hasT = 0, hasC = !law.tail;
    for (size_t i = 0; i < t.rows; i++) {
        if (i > 0)
            assert_true(t.u_mm[i] > t.u_mm[i - 1]);
        assert_close(t.u_mm[i], -t.u_mm[t.rows - 1 - i], 0.0);
        assert_close(t.F_N[i], -t.F_N[t.rows - 1 - i], 0.0);
        has0 |= t.u_mm[i] == 0.0 && t.F_N[i] == 0.0;
        if (t.u_mm[i] == law.u_T_mm) {
            hasT = 1;
            assert_close(t.F_N[i], law.F_T_N, 1e-12 * law.F_T_N);
        }
        if (law.tail && t.u_mm[i] == law.u_C_mm) {
            hasC = 1;
            assert_close(t.F_N[i], law.F_C_N, 1e-12 * law.F_C_N);
        }
    }
    assert_true(has0 && hasT && hasC);
    /* the end is where the law carries F_solid - tol F_C (F_C (1 - tol) without a tail), just
    ** short of solid */
    assert_close(t.F_N[t.rows - 1], law.F_solid_N - tol * law.F_C_N, 1e-9 * law.F_C_N);
    assert_true(t.u_hi_mm < law.travel_mm);
    /* an independent dense grid (a different count from the module's own check) */
    const int N = 99991;
    double worst = 0;
    for (int i = 0; i <= N; i++) {
        double u = -t.u_hi_mm + 2.0 * t.u_hi_mm * i / N;
        double w = (double)i / N; /* and crowded towards the end of the table */
        double v = t.u_hi_mm * (1.0 - w * w * w * w);
        double c = law.u_C_mm * (1.0 - w * w * w * w); /* crowded towards the cone's solid */
        double us[3] = {u, v, c};
        for (int j = 0; j < (law.tail ? 3 : 2); j++) {
            double F = cf_law_force(&law, CF_LAW_EXACT, us[j], NULL, NULL);
            double e = fabs(cf_export_table_eval(&t, us[j]) - F);
            if (e > tol * law.F_C_N)
                fail_msg("tol %g: table off by %g N at u = %.17g (F = %g)", tol, e, us[j], F);
            worst = fmax(worst, e / law.F_C_N);
        }
    }
    /* the reported error is a true bound of what we see, and is not vacuous */
    assert_true(t.max_err_rel <= tol);
    assert_true(t.max_err_rel > 0.3 * tol);
    assert_true(worst <= t.max_err_rel * 1.05);
    /* past the table, holding the last force is within tol F_C of the law up to solid (u_end is
    ** a double a few 1e-12 mm short of solid at tol 1e-6: its rounding moves F by ~0.1 %) */
    assert_true(law.F_solid_N - t.F_N[t.rows - 1] <= tol * law.F_C_N * (1 + 1e-2));
    cf_export_table_free(&t);
}

/* A tailed spring: the table keeps u_C on the law, runs on through the straight region 3 to
** within tol F_C of the solid force, and meets the tolerance on a grid crowded at u_C. */
static void tables_of_a_tailed_spring_stay_within_tolerance_through_region_3(void **state)
{
    (void)state;
    const double tols[3] = {1e-2, 1e-4, 1e-6};
    for (int i = 0; i < 3; i++)
        check_table(&TAIL, tols[i]);
    cf_law law;
    cf_export_table t;
    cf_error err = {0};
    law_of(&law, &TAIL);
    assert_int_equal(cf_export_table_build(&law, 1e-4, &t, &err), CF_OK);
    assert_true(t.u_hi_mm > law.u_C_mm); /* the table reaches region 3 */
    /* region 3 is one straight interval: no row between u_C and the end */
    assert_close(t.u_mm[t.rows - 2], law.u_C_mm, 0.0);
    /* and the plain spring with the same cone needs about as many rows (region 2 alike) */
    cf_law plain;
    cf_export_table tp;
    law_of(&plain, &TEL);
    assert_int_equal(cf_export_table_build(&plain, 1e-4, &tp, &err), CF_OK);
    assert_true(t.rows < 2 * tp.rows);
    cf_export_table_free(&t);
    cf_export_table_free(&tp);
}

static void a_tail_too_stiff_to_tabulate_is_refused_naming_n_tail(void **state)
{
    (void)state;
    /* (a guard, not a speed target: the unbounded table ran for minutes and took gigabytes) */
    alarm(300);
    const double tols[2] = {1e-4, 1e-9};
    for (int i = 0; i < 2; i++) {
        cf_spring p = TAIL;
        p.n_tail = 1e-15;
        cf_law law;
        law_of(&law, &p);
        cf_export_table t;
        cf_error err = {0};
        assert_int_equal(cf_export_table_build(&law, tols[i], &t, &err), CF_E_DATA);
        assert_non_null(strstr(err.msg, "n_tail = 1e-15"));
        assert_int_equal(t.rows, 0);
        assert_null(t.u_mm);
        cf_law_free(&law);
        /* a tail of a millionth of a coil is stiff but still tabulates, at both tolerances */
        p.n_tail = 1e-6;
        law_of(&law, &p);
        assert_int_equal(cf_export_table_build(&law, tols[i], &t, &err), CF_OK);
        assert_true(t.max_err_rel <= tols[i]);
        cf_export_table_free(&t);
        cf_law_free(&law);
    }
    alarm(0);
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

/* The row count depends on rho and the tolerance only (the density of the nodes does), and it
** falls as rho grows: 1e-4 of F_C within CalculiX's 200 pairs from rho = 0.05 up, both types,
** any size and stiffness. */
static void every_spring_from_rho_0_05_fits_200_rows_at_1e_4(void **state)
{
    (void)state;
    const double rhos[] = {0.05, 0.06, 0.08, 0.1, 0.15, 0.25, 0.4, 0.6, 0.8, 0.95, 0.999};
    size_t prev = SIZE_MAX;
    for (size_t i = 0; i < sizeof rhos / sizeof rhos[0]; i++) {
        /* telescoping: D2 large, few coils; non-telescoping: many thick coils */
        const cf_spring ps[2] = {{2.0, 2.0 / rhos[i], 2, 0.2, 3.0, 12},
                                 {30.0 * rhos[i], 30.0, 12, 0.9, 7.9e4, 60}};
        for (int k = 0; k < 2; k++) {
            cf_law law;
            cf_export_table t;
            cf_error err = {0};
            law_of(&law, &ps[k]);
            assert_int_equal(cf_export_table_build(&law, 1e-4, &t, &err), CF_OK);
            if (t.rows > CF_EXPORT_CALCULIX_MAX_ROWS || t.max_err_rel > 1e-4)
                fail_msg("rho %g (%s): %zu rows, error %g of F_C", rhos[i],
                         cf_spring_type_name(law.type), t.rows, t.max_err_rel);
            if (k == 0) {
                assert_true(t.rows <= prev);
                prev = t.rows;
            }
            cf_export_table_free(&t);
        }
    }
}

static void a_range_covers_only_what_is_asked_and_stays_within_tolerance(void **state)
{
    (void)state;
    cf_law law;
    cf_export_table t, full;
    cf_error err = {0};
    law_of(&law, &TEL);
    const double lo = -5.0, hi = 0.9 * law.travel_mm;
    assert_int_equal(cf_export_table_build_range(&law, 1e-4, lo, hi, &t, &err), CF_OK);
    assert_close(t.u_mm[0], lo, 0.0);
    assert_close(t.u_mm[t.rows - 1], hi, 0.0);
    assert_close(t.F_N[t.rows - 1], cf_law_force(&law, CF_LAW_EXACT, hi, NULL, NULL), 0.0);
    for (int i = 0; i <= 20000; i++) {
        const double u = lo + (hi - lo) * i / 20000.0;
        const double e = fabs(cf_export_table_eval(&t, u) -
                              cf_law_force(&law, CF_LAW_EXACT, u, NULL, NULL));
        if (e > 1e-4 * law.F_C_N)
            fail_msg("range table off by %g N at u = %g", e, u);
    }
    /* away from solid far fewer rows are needed */
    assert_int_equal(cf_export_table_build(&law, 1e-4, &full, &err), CF_OK);
    assert_true(t.rows < full.rows / 2);
    cf_export_table_free(&t);
    /* past the travel: refused with the largest reach */
    assert_int_equal(cf_export_table_build_range(&law, 1e-4, 0.0, law.travel_mm, &t, &err),
                     CF_E_DATA);
    char reach[32];
    snprintf(reach, sizeof reach, "%.10g", full.u_hi_mm);
    assert_non_null(strstr(err.msg, reach));
    assert_int_equal(cf_export_table_build_range(&law, 1e-4, 1.0, 2.0, &t, &err), CF_E_DATA);
    cf_export_table_free(&full);
}

static void cylindrical_spring_needs_three_rows(void **state)
{
    (void)state;
    const cf_spring cyl = {20, 20, 5, 1, 80000, 30};
    cf_law law;
    cf_export_table t;
    cf_error err = {0};
    law_of(&law, &cyl);
    assert_int_equal(cf_export_table_build(&law, 1e-4, &t, &err), CF_OK);
    assert_int_equal(t.rows, 3);
    assert_true(t.max_err_rel < 1e-13);
    cf_export_table_free(&t);
}

/* ---- shipped fits through the command line ---------------------------------------------------- */

/* Reads the (force, elongation) pairs of the first *SPRING block; returns the count. */
static size_t inp_pairs(const char *x, const char *after, double *F, double *e, size_t cap)
{
    const char *b = strstr(x, after);
    assert_non_null(b);
    b = strchr(b, '\n') + 2; /* the block's blank line */
    size_t n = 0;
    int used;
    double f, el;
    while (sscanf(b, "%lf, %lf\n%n", &f, &el, &used) == 2) {
        /* both numbers carry a decimal point: ccx tells spring data from degrees of freedom by
        ** whether the first line under *SPRING holds reals */
        int dots = 0;
        for (int k = 0; k < used; k++)
            dots += b[k] == '.';
        assert_int_equal(dots, 2);
        if (n < cap) {
            F[n] = f;
            e[n] = el;
        }
        n++;
        b += used;
    }
    return n;
}

static void shipped_fits_export_for_calculix_at_1e_4_within_200_pairs(void **state)
{
    (void)state;
    glob_t g;
    if (glob("fits/*.json", 0, NULL, &g) != 0)
        fail_msg("no shipped fits in fits/");
    const char *types[2] = {"telescoping", "non-telescoping"};
    size_t checked = 0;
    for (size_t f = 0; f < g.gl_pathc; f++)
        for (int k = 0; k < 2; k++) {
            cf_fitted_spring fs;
            cf_error err = {0};
            if (cf_fitfile_load(g.gl_pathv[f], types[k], &fs, &err) != CF_OK)
                continue; /* a fit file may hold one type only */
            cf_law law;
            law_of(&law, &fs.params);
            char args[96];
            snprintf(args, sizeof args, "--format calculix --type %s --tol 1e-4", types[k]);
            char *x = export_file(g.gl_pathv[f], "shipped.inp", args);
            double F[256], e[256];
            size_t n = inp_pairs(x, "*SPRING, ELSET=CONIFIT_SPRING, NONLINEAR", F, e, 256);
            if (n > CF_EXPORT_CALCULIX_MAX_ROWS)
                fail_msg("%s %s: %zu pairs", g.gl_pathv[f], types[k], n);
            for (size_t i = 0; i < n; i++) {
                if (i > 0)
                    assert_true(e[i] > e[i - 1]);
                if (!(fabs(F[i] - tension(&law, e[i])) <= 1e-4 * law.F_C_N))
                    fail_msg("%s %s: pair %zu (%g N at %g mm) off the law", g.gl_pathv[f],
                             types[k], i, F[i], e[i]);
            }
            /* between the pairs, as ccx interpolates */
            for (size_t i = 0; i + 1 < n; i++)
                for (int q = 1; q < 8; q++) {
                    const double a = q / 8.0, el = e[i] + a * (e[i + 1] - e[i]);
                    const double lin = F[i] + a * (F[i + 1] - F[i]);
                    if (!(fabs(lin - tension(&law, el)) <= 1e-4 * law.F_C_N))
                        fail_msg("%s %s: off by %g F_C at %g mm", g.gl_pathv[f], types[k],
                                 fabs(lin - tension(&law, el)) / law.F_C_N, el);
                }
            free(x);
            checked++;
        }
    globfree(&g);
    assert_true(checked >= 8);
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
        assert_true(fabs(F - tension(&law, e)) <= 1e-3 * law.F_C_N);
        prev = e;
        n++;
    }
    assert_true(n > 20);
    free(x);
}

/* Splits a fixed-width card into fields of `w` characters. */
static void fields(const char *line, int w, int count, double *out)
{
    char f[24];
    for (int k = 0; k < count; k++) {
        snprintf(f, (size_t)w + 1, "%.*s", w, line + w * k);
        out[k] = atof(f);
    }
}

static void lsdyna_curve_carries_lcint_of_at_least_its_rows(void **state)
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
    int card = 0;
    size_t points = 0;
    double lcint = 0, prev = -INFINITY, f[8];
    char *save = NULL;
    for (char *line = strtok_r(x, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
        if (line[0] == '$' || line[0] == '*')
            continue;
        card++;
        if (card == 1) { /* MID LCD LCR */
            assert_int_equal(strlen(line), 30);
            fields(line, 10, 3, f);
            assert_close(f[0], 1, 0);
            assert_close(f[1], 1, 0);
        } else if (card == 2) { /* LCID SIDR SFA SFO OFFA OFFO DATTYP LCINT */
            assert_int_equal(strlen(line), 80);
            fields(line, 10, 8, f);
            assert_close(f[0], 1, 0);
            assert_close(f[2], 1.0, 0.0);
            assert_close(f[3], 1.0, 0.0);
            lcint = f[7];
        } else { /* A1 O1 */
            assert_int_equal(strlen(line), 40);
            fields(line, 20, 2, f);
            assert_true(f[0] > prev);
            prev = f[0];
            assert_true(fabs(f[1] - tension(&law, f[0])) <= 1.01e-3 * law.F_C_N);
            points++;
        }
    }
    assert_true(points > 20);
    if (!(lcint >= (double)points))
        fail_msg("LCINT %g is below the curve's %zu points: LS-DYNA would resample it", lcint,
                 points);
    free(x);
}

/* The force SOFA's PolynomialSpringsForceField applies along a spring of current length l for
** one component (rest length l0, degree-1 coefficient a): force = a |l - l0|/l0, times +1 when
** stretched and, compressed, -1 if compressible else 0 (PolynomialSpringsForceField.inl). */
static double sofa_force(double l, double l0, double a, int compressible)
{
    const double L = fabs(l - l0) / l0;
    const double sign = l - l0 >= 0 ? 1.0 : (compressible ? -1.0 : 0.0);
    return a * L * sign;
}

typedef struct sofa_field {
    int compressible;
    double l0, a;
    unsigned first, second; /* the first spring's nodes */
} sofa_field;

/* Reads every PolynomialSpringsForceField of x; returns the count. */
static size_t sofa_fields(const char *x, sofa_field *out, size_t cap)
{
    size_t n = 0;
    for (const char *p = strstr(x, "<PolynomialSpringsForceField "); p;
         p = strstr(p + 1, "<PolynomialSpringsForceField ")) {
        const char *end = strstr(p, "/>");
        assert_non_null(end);
        sofa_field f = {0};
        const char *c = strstr(p, "compressible=\"");
        assert_true(c && c < end);
        f.compressible = atoi(c + strlen("compressible=\""));
        assert_true(f.compressible == 0 || f.compressible == 1);
        c = strstr(p, "zeroLength=\"");
        assert_true(c && c < end);
        f.l0 = atof(c + strlen("zeroLength=\""));
        c = strstr(p, "polynomialStiffness=\"");
        assert_true(c && c < end);
        f.a = atof(c + strlen("polynomialStiffness=\""));
        c = strstr(p, "polynomialDegree=\"");
        assert_true(c && c < end);
        assert_int_equal(atoi(c + strlen("polynomialDegree=\"")), 1);
        c = strstr(p, "computeZeroLength=\"0\"");
        assert_true(c && c < end);
        f.first = (unsigned)atoi(strstr(p, "firstObjectPoints=\"") + 19);
        f.second = (unsigned)atoi(strstr(p, "secondObjectPoints=\"") + 20);
        if (n < cap)
            out[n] = f;
        n++;
    }
    return n;
}

static void sofa_scene_is_compressible_and_follows_the_law_within_tol(void **state)
{
    (void)state;
    cf_law law;
    law_of(&law, &TEL);
    char *x = export_to("s.scn", "--format sofa --tol 1e-4");
    assert_non_null(strstr(x, "units: mm, N, s, tonne"));
    assert_non_null(strstr(x, "<MechanicalObject name=\"dofs\" template=\"Vec3d\""));
    assert_null(strstr(x, "@OBJECT")); /* a scene, not a snippet */
    static sofa_field f[1024];
    const size_t n = sofa_fields(x, f, 1024);
    assert_true(n > 10 && n <= 1024);
    /* the affine part is two compressible springs; every other one is one-sided */
    size_t comp = 0;
    for (size_t i = 0; i < n; i++)
        comp += f[i].compressible == 1;
    assert_int_equal(comp, 2);
    assert_close(f[0].l0, TEL.H_mm, 0.0);
    assert_int_equal(f[0].compressible, 1);
    /* the summed force SOFA computes, against the law, from full stretch to near solid */
    const double u_end = cf_export_table_end(&law, 1e-4);
    double worst = 0.0;
    for (int i = 0; i <= 40000; i++) {
        const double w = (double)i / 40000.0;
        const double u = -u_end + 2.0 * u_end * w;
        const double l = TEL.H_mm - u;
        double T = 0.0;
        for (size_t k = 0; k < n; k++)
            T += sofa_force(l, f[k].l0, f[k].a, f[k].compressible);
        worst = fmax(worst, fabs(T - tension(&law, -u)) / law.F_C_N);
    }
    if (worst > 1e-4)
        fail_msg("SOFA springs off the law by %g of F_C", worst);
    assert_true(worst > 1e-6); /* the comparison sees the table, not a copy of the law */
    free(x);
}

static void inp_block_has_its_layout_and_the_law(void **state)
{
    (void)state;
    cf_law law;
    law_of(&law, &TEL);
    char *x = export_to("s.csv", "--format csv --tol 1e-3");
    assert_true(strncmp(x, "u_mm,force_N,stiffness_N_per_mm\n", 32) == 0);
    free(x);
    x = export_to("s.inp", "--format abaqus --tol 1e-3");
    assert_non_null(strstr(x, "** units: mm, N, s, tonne"));
    assert_non_null(strstr(x, "holds the force of the last pair beyond the table"));
    double F[256], e[256];
    size_t n = inp_pairs(x, "*SPRING, ELSET=CONIFIT_SPRING, NONLINEAR", F, e, 256);
    assert_true(n > 20 && n <= 256);
    for (size_t i = 0; i < n; i++) {
        if (i)
            assert_true(e[i] > e[i - 1]);
        assert_true(fabs(F[i] - tension(&law, e[i])) <= 1e-3 * law.F_C_N);
    }
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
    }
}

static void bad_input_gives_its_exit_status_the_number_that_works_and_no_output(void **state)
{
    (void)state;
    char out[256], err[1024], p[160];
    struct stat st;
    snprintf(p, sizeof p, "%s/never.out", dir);
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
    /* usage */
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "export %s/fit.json --format vtk", dir), 2);
    assert_non_null(strstr(err, "vtk"));
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "export %s/fit.json", dir), 2);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "export %s/fit.json --format csv --tol 2",
                            dir),
                     2);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "export %s/fit.json --format csv --range 3",
                            dir),
                     2);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "export %s/fit.json --format csv --example",
                            dir),
                     2);
    /* refusing to overwrite the input */
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "export %s/fit.json --format csv -o %s/fit.json",
                            dir, dir),
                     73);
    /* a range past the travel: 65, the reach in the message, nothing written */
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err,
                            "export %s/fit.json --format calculix --range 0:39 -o %s", dir, p),
                     65);
    assert_non_null(strstr(err, "reaches |u| <= 38.99"));
    assert_int_equal(stat(p, &st), -1);
    /* calculix refuses a table longer than it reads, naming the tolerance that fits */
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "export %s/fit.json --format calculix "
                                                      "--tol 1e-6 -o %s", dir, p),
                     65);
    assert_non_null(strstr(err, "200"));
    const char *fits = strstr(err, "tolerance ");
    fits = fits ? strstr(fits + 10, "tolerance ") : NULL;
    assert_non_null(fits);
    const double need = atof(fits + 10);
    assert_true(need > 1e-6 && need < 1e-3);
    assert_int_equal(stat(p, &st), -1);
    char args[64];
    snprintf(args, sizeof args, "--format calculix --tol %.17g", need);
    free(export_to("fits.inp", args)); /* and that tolerance does fit */
    /* the row count and error on stderr */
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "export %s/fit.json --format csv "
                                                              "--tol 0.01 -o %s/ok.csv",
                            dir, dir),
                     0);
    assert_non_null(strstr(err, "rows, max error"));
}

/* ---- the proof: CalculiX reads the export back ---------------------------------------------- */

/* The summed reactions ("total force ... for set NTOP and time T") at whole times 1, 2, ... of
** a ccx .dat: rz[k - 1] for time k. Returns the count of whole times found. */
static int parse_totals(const char *text, double *rz, int cap)
{
    int n = 0;
    for (const char *p = text; (p = strstr(p, "total force (fx,fy,fz) for set NTOP and time")) != NULL;
         p++) {
        double t, fx, fy, fz;
        if (sscanf(p, "total force (fx,fy,fz) for set NTOP and time %lf %lf %lf %lf", &t, &fx, &fy,
                   &fz) != 4)
            continue;
        const double k = floor(t + 0.5);
        if (fabs(t - k) > 1e-9 || k < 1 || k > cap)
            continue;
        rz[(int)k - 1] = fz;
        if ((int)k > n)
            n = (int)k;
    }
    return n;
}

static void run_ccx(const char *job)
{
    char cmd[256];
    snprintf(cmd, sizeof cmd, "cd %s && ccx -i %s > %s.log 2>&1", dir, job, job);
    int rc = system(cmd);
    if (!(WIFEXITED(rc) && WEXITSTATUS(rc) == 0))
        fail_msg("ccx failed on %s/%s.inp (see its .log)", dir, job);
}

/* The step values written in a model's header: top displacement and conifit's reaction. */
static int header_steps(const char *x, double *dz, double *ref, int cap)
{
    int n = 0;
    for (const char *p = strstr(x, "  step "); p && n < cap; p = strstr(p + 1, "  step ")) {
        int k;
        double e;
        if (sscanf(p, "  step %d: top z displacement %lf mm (strain %*f), conifit reaction %lf N",
                   &k, &dz[n], &e) != 3)
            continue;
        ref[n++] = e;
    }
    return n;
}

static double header_reaction_tol(const char *x)
{
    const char *p = strstr(x, "reaction tolerance implied by the tables: ");
    assert_non_null(p);
    return atof(p + strlen("reaction tolerance implied by the tables: "));
}

static void calculix_runs_the_one_spring_example_and_matches_the_law(void **state)
{
    (void)state;
    if (!have_ccx())
        skip(); /* CI installs calculix-ccx (Makefile DEBS) */
    const char *types[3] = {"telescoping", "non-telescoping", "telescoping"};
    const cf_spring *ps[3] = {&TEL, &NON, &TAIL};
    for (int k = 0; k < 3; k++) { /* the third, the tailed spring, is pushed into region 3 */
        cf_law law;
        law_of(&law, ps[k]);
        char args[96], job[32], name[48];
        snprintf(args, sizeof args, "--format calculix --type %s --example", types[k]);
        snprintf(job, sizeof job, "example_%d", k);
        snprintf(name, sizeof name, "%s.inp", job);
        char *x = k < 2 ? export_to(name, args) : export_tail(name, args);
        if (law.tail) { /* 0.99 of the table's end lies past u_C */
            double dz0[16], ref0[16];
            assert_int_equal(header_steps(x, dz0, ref0, 16), 6);
            assert_true(-dz0[2] > law.u_C_mm);
        }
        run_ccx(job);
        double dz[16], ref[16], rz[16];
        const int n = header_steps(x, dz, ref, 16);
        assert_int_equal(n, 6);
        char p[160];
        snprintf(p, sizeof p, "%s/%s.dat", dir, job);
        char *dat = tu_slurp(p);
        assert_non_null(dat);
        assert_int_equal(parse_totals(dat, rz, 16), n);
        const double tol = header_reaction_tol(x);
        if (!(tol > 0 && tol <= 1e-4 * law.F_C_N * (1 + 1e-5)))
            fail_msg("reaction tolerance %g against F_C %g", tol, law.F_C_N);
        for (int i = 0; i < n; i++) {
            /* the support holds the spring: its reaction is the spring's tension at elongation
            ** dz, and conifit's compressive reaction is minus that */
            const double want = tension(&law, dz[i]);
            assert_close(ref[i], -want, 1e-12 * law.F_C_N);
            const double bound = tol + CCX_PRINT_REL * fabs(want);
            if (!(fabs(rz[i] - want) <= bound))
                fail_msg("%s step %d: ccx %.7g N, law %.7g N (bound %.3g)", job, i + 1, rz[i],
                         want, bound);
        }
        free(dat);
        free(x);
    }
}

/* What src/notes/export.md says of CalculiX: past the last pair it holds the force constant. */
static void calculix_holds_the_last_force_beyond_the_table(void **state)
{
    (void)state;
    if (!have_ccx())
        skip(); /* CI installs calculix-ccx (Makefile DEBS) */
    cf_law law;
    law_of(&law, &TEL);
    char *block = export_to("hold.inp", "--format calculix --tol 1e-2");
    double F[256], e[256];
    const size_t n = inp_pairs(block, "*SPRING, ELSET=CONIFIT_SPRING, NONLINEAR", F, e, 256);
    assert_true(n > 3 && n <= 256);
    char path[160];
    snprintf(path, sizeof path, "%s/hold_model.inp", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "*NODE, NSET=NALL\n1, 0, 0, 0\n2, 0, 0, %.17g\n*NSET, NSET=NTOP\n2\n"
               "*ELEMENT, TYPE=SPRINGA, ELSET=CONIFIT_SPRING\n1, 1, 2\n",
            TEL.H_mm);
    fputs(block, f);
    fprintf(f, "*BOUNDARY\n1, 1, 3\n2, 1, 2\n");
    /* compressed past the table's end (e[0]) towards solid, and stretched past its other end */
    const double dz[2] = {0.5 * (e[0] - law.travel_mm), 0.5 * (e[n - 1] + law.travel_mm)};
    for (int k = 0; k < 2; k++)
        fprintf(f, "*STEP\n*STATIC\n*BOUNDARY\nNTOP, 3, 3, %.17g\n*NODE PRINT, NSET=NTOP, "
                   "TOTALS=ONLY\nRF\n*END STEP\n",
                dz[k]);
    fclose(f);
    run_ccx("hold_model");
    snprintf(path, sizeof path, "%s/hold_model.dat", dir);
    char *dat = tu_slurp(path);
    assert_non_null(dat);
    double rz[4];
    assert_int_equal(parse_totals(dat, rz, 4), 2);
    /* the reaction is the end pair's force, not the law (which is at or near F_C there) and not
    ** an extrapolated slope */
    assert_close(rz[0], F[0], CCX_PRINT_REL * fabs(F[0]));
    assert_close(rz[1], F[n - 1], CCX_PRINT_REL * fabs(F[n - 1]));
    free(dat);
    free(block);
}

/* ---- lattices --------------------------------------------------------------------------------- */

/* A small static uniaxial scene built from the test's fit file `fit` (fit.json or tail.json). */
static void write_scene_of(const char *fit, const char *name, double to_strain, int samples)
{
    char p[160];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    FILE *f = fopen(p, "w");
    assert_non_null(f);
    fprintf(f, "{\"spring\": {\"fit\": \"%s/%s\", \"type\": \"telescoping\"},\n"
               " \"lattice\": {\"nx\": 2, \"ny\": 2, \"nz\": 2, \"diagonals\": \"face+body\", "
               "\"bottom\": \"axial\"},\n"
               " \"protocol\": {\"kind\": \"ramp\", \"to_strain\": %.17g, \"duration_s\": 1},\n"
               " \"samples_per_segment\": %d}\n",
               dir, fit, to_strain, samples);
    fclose(f);
}

static void write_scene(const char *name, double to_strain, int samples)
{
    write_scene_of("fit.json", name, to_strain, samples);
}

/* The lattice of spring P (the test's fit file `fit`) loaded in 12 steps to strain `to`, exported
** for CalculiX as job `job`, run in ccx, and compared at every step with conifit simulate of the
** same scene. */
static double ccx_lattice_matches_simulate(const char *fit, const cf_spring *P, double to,
                                           const char *job)
{
    char scene[48], args[200], name[48], ffile[96];
    snprintf(scene, sizeof scene, "%s.json", job);
    snprintf(name, sizeof name, "%s.inp", job);
    snprintf(ffile, sizeof ffile, "%s/%s", dir, fit);
    write_scene_of(fit, scene, to, 12);
    snprintf(args, sizeof args, "--lattice %s/%s --format calculix --type telescoping", dir,
             scene);
    char *x = export_file(ffile, name, args);
    run_ccx(job);
    /* conifit simulate on the same scene */
    char err[1024];
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "simulate %s/%s -o %s/%s.csv", dir, scene,
                            dir, job),
                     0);
    char p[160];
    snprintf(p, sizeof p, "%s/%s.csv", dir, job);
    char *csv = tu_slurp(p);
    assert_non_null(csv);
    double strain[64], stress_kPa[64];
    int ns = 0;
    for (const char *line = strchr(csv, '\n'); line && line[1] && ns < 64;
         line = strchr(line + 1, '\n')) {
        double t, e, s;
        if (sscanf(line + 1, "%lf,%lf,%lf", &t, &e, &s) == 3 && t > 0) {
            strain[ns] = e;
            stress_kPa[ns++] = s;
        }
    }
    assert_int_equal(ns, 12);
    snprintf(p, sizeof p, "%s/%s.dat", dir, job);
    char *dat = tu_slurp(p);
    assert_non_null(dat);
    double rz[64], dz[64], ref[64];
    assert_int_equal(parse_totals(dat, rz, 64), ns);
    assert_int_equal(header_steps(x, dz, ref, 64), ns);
    const double tol = header_reaction_tol(x);
    const double area = 4.0 * P->H_mm * P->H_mm, height = 2.0 * P->H_mm;
    double worst = 0.0;
    for (int k = 0; k < ns; k++) {
        const double sim_N = stress_kPa[k] * 1e-3 * area; /* compressive top reaction */
        assert_close(dz[k], -strain[k] * height, 1e-9 * height);
        assert_close(ref[k], sim_N, 1e-6 * fabs(sim_N) + 1e-12);
        const double ccx_N = -rz[k];
        const double bound = tol + CCX_PRINT_REL * fabs(sim_N);
        if (!(fabs(ccx_N - sim_N) <= bound))
            fail_msg("step %d (strain %g): ccx %.7g N, conifit simulate %.7g N (bound %.3g)",
                     k + 1, strain[k], ccx_N, sim_N, bound);
        worst = fmax(worst, fabs(ccx_N - sim_N) / tol);
    }
    print_message("%s: ccx against conifit simulate, worst step at %.3g of the tolerance\n", job,
                  worst);
    free(dat);
    free(csv);
    free(x);
    return tol;
}

/* ---- a double-acting element and a volume term ------------------------------------------------ */

/* TEL in compression, its own extension spring EXT (the same H) in extension. */
static const cf_spring EXT = {8, 24, 6, 1.2, 80000, 40};
#define PAIR_PARAMS                                                                               \
    "\"params\": {\"D1_mm\": 10, \"D2_mm\": 30, \"n\": 4, \"d_mm\": 1, \"G_MPa\": 80000, "     \
    "\"H_mm\": 40}, \"params_extension\": {\"D1_mm\": 8, \"D2_mm\": 24, \"n\": 6, "            \
    "\"d_mm\": 1.2, \"G_MPa\": 80000, \"H_mm\": 40}"

/* pair.json: TEL and EXT with a volume term kappa = 0.5 MPa; pair0.json: the same pair alone. */
static void write_pair_fits(void)
{
    assert_int_equal(write_in_dir("pair.json",
                                  "{\"fits\": [{\"type\": \"telescoping\", " PAIR_PARAMS
                                  ", \"lattice\": {\"volume_modulus_MPa\": 0.5}}]}\n"),
                     0);
    assert_int_equal(write_in_dir("pair0.json",
                                  "{\"fits\": [{\"type\": \"telescoping\", " PAIR_PARAMS "}]}\n"),
                     0);
}

/* The last stress (kPa) of `conifit simulate` on a scene of fit file `fit` loaded to `to`. */
static double simulated_end_kPa(const char *fit, double to, const char *job)
{
    char scene[48], err[1024], p[160];
    snprintf(scene, sizeof scene, "%s.json", job);
    write_scene_of(fit, scene, to, 12);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "simulate %s/%s -o %s/%s.csv", dir, scene,
                            dir, job),
                     0);
    snprintf(p, sizeof p, "%s/%s.csv", dir, job);
    char *csv = tu_slurp(p);
    assert_non_null(csv);
    double s = NAN, t, e, v;
    for (const char *line = strchr(csv, '\n'); line && line[1]; line = strchr(line + 1, '\n'))
        if (sscanf(line + 1, "%lf,%lf,%lf", &t, &e, &v) == 3)
            s = v;
    free(csv);
    return s;
}

/* The lattice of a double-acting element with a volume term, exported for CalculiX (SPRINGA tables
** holding both springs, one C3D8 hexahedron per cell of a neo-Hookean material with C10 = 0 and
** D1 = 2/kappa), runs in ccx within the stated tolerance of conifit simulate at every step of a
** compression and of an extension; the volume term moves the reaction by far more than that
** tolerance (so the hexahedra carry it), and the compression spring alone would not be the
** lattice in extension. */
static void calculix_runs_the_pair_and_volume_lattice_and_matches_simulate(void **state)
{
    (void)state;
    if (!have_ccx())
        skip(); /* CI installs calculix-ccx (Makefile DEBS) */
    write_pair_fits();
    const double area = 4.0 * TEL.H_mm * TEL.H_mm;
    const double to[2] = {0.3, -0.3};
    const char *job[2] = {"lat_pair_c", "lat_pair_t"}, *job0[2] = {"pair0_c", "pair0_t"};
    for (int i = 0; i < 2; i++) {
        const double tol_N = ccx_lattice_matches_simulate("pair.json", &TEL, to[i], job[i]);
        const double with = simulated_end_kPa("pair.json", to[i], job[i]);
        const double without = simulated_end_kPa("pair0.json", to[i], job0[i]);
        const double moved_N = fabs(with - without) * 1e-3 * area;
        if (!(moved_N > 10.0 * tol_N))
            fail_msg("%s: the volume term moves the reaction by %.4g N, not above 10 times the "
                     "tolerance %.4g N",
                     job[i], moved_N, tol_N);
    }
}

/* Every table of a pair holds both springs: the CSV's rows at u >= 0 on the compression spring's
** law and at u < 0 on the extension spring's, within tol of that spring's F_C; the JSON carries
** params_extension and the volume term back through the fit-file reader; CalculiX, Abaqus and
** FEBio write the volume term as hexahedra of a purely volumetric material; the model formats that
** cannot carry it refuse the lattice (65, naming the format and why, nothing written),
** as does the one-spring example of a fit with one; without the volume term every model format
** writes the pair's lattice. */
static void every_export_of_a_pair_holds_both_springs(void **state)
{
    (void)state;
    write_pair_fits();
    char fit[96], fit0[96];
    snprintf(fit, sizeof fit, "%s/pair.json", dir);
    snprintf(fit0, sizeof fit0, "%s/pair0.json", dir);
    cf_law lc, le, pair;
    law_of(&lc, &TEL);
    law_of(&le, &EXT);
    law_of(&pair, &TEL);
    assert_int_equal(cf_law_pair(&pair, &le, NULL), CF_OK);
    char *csv = export_file(fit, "pair.csv", "--format csv --tol 1e-4");
    assert_non_null(strstr(csv, "# extension spring"));
    assert_non_null(strstr(csv, "volume term"));
    size_t below = 0, above = 0;
    double lo = 0;
    for (const char *line = strstr(csv, "u_mm,force_N"); line && (line = strchr(line, '\n')) &&
                                                         line[1];
         line++) {
        double u, F, k;
        if (sscanf(line + 1, "%lf,%lf,%lf", &u, &F, &k) != 3)
            continue;
        const cf_law *side = u < 0 ? &le : &lc;
        const double law_F = u < 0 ? -cf_law_force(&le, CF_LAW_EXACT, -u, NULL, NULL)
                                   : cf_law_force(&lc, CF_LAW_EXACT, u, NULL, NULL);
        assert_close(F, law_F, 1e-4 * side->F_C_N);
        assert_close(F, cf_law_force(&pair, CF_LAW_EXACT, u, NULL, NULL), 1e-4 * side->F_C_N);
        below += u < 0;
        above += u > 0;
        lo = fmin(lo, u);
    }
    assert_true(below > 10 && above > 10);
    /* the stretch side runs to the extension spring's travel, not the compression spring's */
    assert_true(-lo <= le.travel_mm && -lo > 0.99 * le.travel_mm && le.travel_mm < lc.travel_mm);
    free(csv);
    /* JSON: read back as the whole element */
    free(export_file(fit, "pair_spring.json", "--format json"));
    char p[160];
    snprintf(p, sizeof p, "%s/pair_spring.json", dir);
    cf_fitted_spring fs;
    cf_error err = {0};
    assert_int_equal(cf_fitfile_load_element(p, NULL, &fs, &err), CF_OK);
    assert_true(fs.has_extension);
    for (int k = 0; k < CF_P_COUNT; k++)
        assert_true(cf_spring_get(&fs.extension, k) == cf_spring_get(&EXT, k));
    assert_true(fs.volume_modulus_MPa == 0.5);
    /* lattices: the volume term only where it can be carried */
    write_scene_of("pair.json", "pair_lat.json", 0.2, 4);
    write_scene_of("pair0.json", "pair0_lat.json", 0.2, 4);
    for (int f = 0; f < CF_EXPORT_FORMAT_COUNT; f++) {
        const cf_export_format_info *fi = cf_export_format_get((cf_export_format)f);
        if (!fi->model)
            continue;
        char args[512], name[48], errb[2048];
        snprintf(name, sizeof name, "pair_lat.%s", fi->name);
        snprintf(args, sizeof args, "export %s --lattice %s/pair_lat.json --format %s -o %s/%s",
                 fit, dir, fi->name, dir, name);
        const int rc = tu_run(NULL, 0, errb, sizeof errb, "%s", args);
        snprintf(p, sizeof p, "%s/%s", dir, name);
        struct stat st;
        if (f == CF_EXPORT_CALCULIX || f == CF_EXPORT_ABAQUS) {
            if (rc != 0)
                fail_msg("%s: exit %d: %s", args, rc, errb);
            char *x = tu_slurp(p);
            assert_non_null(strstr(x, "*ELEMENT, TYPE=C3D8, ELSET=CELLS"));
            assert_non_null(strstr(x, "*HYPERELASTIC, NEO HOOKE\n0., 4.\n"));
            free(x);
        } else if (f == CF_EXPORT_FEBIO) { /* 8 hex8 of U(J) = (k/2)(J - 1)^2, k = kappa */
            if (rc != 0)
                fail_msg("%s: exit %d: %s", args, rc, errb);
            char *x = tu_slurp(p);
            const char *el = strstr(x, "<Elements type=\"hex8\" name=\"volume\">");
            assert_non_null(el);
            assert_non_null(strstr(el, "<elem id=\"8\">"));
            assert_null(strstr(el, "<elem id=\"9\">"));
            assert_non_null(strstr(x, "type=\"Mooney-Rivlin\">"));
            assert_non_null(strstr(x, "<c1>0</c1>"));
            assert_non_null(strstr(x, "<k>0.5</k>"));
            assert_non_null(strstr(x, "<pressure_model>2</pressure_model>"));
            assert_non_null(strstr(x, "<SolidDomain name=\"volume\" mat=\"volume\"/>"));
            free(x);
        } else {
            if (rc != 65 || !strstr(errb, "volume term") || !strstr(errb, fi->name))
                fail_msg("%s: exit %d, '%s' (expected 65 naming the volume term and %s)", args, rc,
                         errb, fi->name);
            assert_int_equal(stat(p, &st), -1);
        }
        snprintf(name, sizeof name, "pair0_lat.%s", fi->name);
        snprintf(args, sizeof args, "--lattice %s/pair0_lat.json --format %s", dir, fi->name);
        char *x = export_file(fit0, name, args);
        assert_non_null(strstr(x, "extension spring"));
        free(x);
    }
    char errb[2048];
    snprintf(p, sizeof p, "%s/pair_example.inp", dir);
    assert_int_equal(tu_run(NULL, 0, errb, sizeof errb, "export %s --format calculix --example "
                            "-o %s", fit, p),
                     65);
    assert_non_null(strstr(errb, "volume term"));
    struct stat st;
    assert_int_equal(stat(p, &st), -1);
    free(export_file(fit0, "pair0_example.inp", "--format calculix --example"));
}

static void calculix_runs_the_lattice_and_matches_conifit_simulate_at_every_step(void **state)
{
    (void)state;
    if (!have_ccx())
        skip(); /* CI installs calculix-ccx (Makefile DEBS) */
    cf_law law;
    law_of(&law, &TEL);
    ccx_lattice_matches_simulate("fit.json", &TEL, 0.45 * law.travel_mm / TEL.H_mm, "lat");
    /* the same for a lattice of tailed springs (the scalar law in the lattice's step), loaded far
    ** enough that the edges along the load are in region 2 of the series law */
    law_of(&law, &TAIL);
    const double to = 0.45 * law.travel_mm / TAIL.H_mm;
    assert_true(to * TAIL.H_mm > law.u_T_mm);
    ccx_lattice_matches_simulate("tail.json", &TAIL, to, "lat_tail");
}

/* Every format's lattice of spring P (the test's fit file `fit`) parsed back: node count, one
** table per group and every number of it against the law at that group's rest length and weight. */
static void lattice_models_hold_the_law(const char *fit, const cf_spring *P, const char *tag)
{
    cf_law law;
    law_of(&law, P);
    char scene[48], ffile[96];
    snprintf(scene, sizeof scene, "%s.json", tag);
    snprintf(ffile, sizeof ffile, "%s/%s", dir, fit);
    write_scene_of(fit, scene, 0.3 * law.travel_mm / P->H_mm, 4);
    for (int f = 0; f < CF_EXPORT_FORMAT_COUNT; f++) {
        const cf_export_format_info *fi = cf_export_format_get((cf_export_format)f);
        if (!fi->model)
            continue;
        char args[160], name[32];
        snprintf(args, sizeof args, "--lattice %s/%s --format %s --tol 1e-3", dir, scene,
                 fi->name);
        snprintf(name, sizeof name, "%s.%s", tag, fi->name);
        char *x = export_file(ffile, name, args);
        /* groups from the header */
        double L0[16], w[16];
        size_t ng = 0, cnt[16];
        for (const char *p = strstr(x, "  group "); p && ng < 16; p = strstr(p + 1, "  group ")) {
            size_t gi, rows;
            if (sscanf(p, "  group %zu: L0 = %lf mm, weight = %lf, %zu springs, %zu rows", &gi,
                       &L0[ng], &w[ng], &cnt[ng], &rows) == 5)
                ng++;
        }
        assert_true(ng >= 3); /* edges, face and body diagonals at least */
        size_t springs = 0;
        for (size_t g = 0; g < ng; g++)
            springs += cnt[g];
        /* 2x2x2 cells: 54 edges, 72 face diagonals, 32 body diagonals */
        assert_int_equal(springs, 54 + 72 + 32);
        assert_non_null(strstr(x, "27 nodes"));
        double dz[8], ref[8];
        assert_int_equal(header_steps(x, dz, ref, 8), 4);
        /* the tables of each group, in the format's own layout */
        size_t g = 0, checked = 0;
        const char *p = x;
        while (g < ng) {
            double e[512], T[512];
            size_t n = 0;
            if (f == CF_EXPORT_CALCULIX || f == CF_EXPORT_ABAQUS) { /* force, elongation */
                char key[48];
                snprintf(key, sizeof key, "*SPRING, ELSET=G%zu, NONLINEAR", g + 1);
                n = inp_pairs(x, key, T, e, 512);
            } else if (f == CF_EXPORT_FEBIO) { /* <pt>e,T</pt> inside each discrete_material */
                char key[64];
                snprintf(key, sizeof key, "name=\"G%zu\" type=\"nonlinear spring\"", g + 1);
                p = strstr(x, key);
                assert_non_null(p);
                const char *end = strstr(p, "</discrete_material>");
                for (const char *q = strstr(p, "<pt>"); q && q < end && n < 512;
                     q = strstr(q + 4, "<pt>")) {
                    assert_int_equal(sscanf(q, "<pt>%lf,%lf</pt>", &e[n], &T[n]), 2);
                    n++;
                }
            } else if (f == CF_EXPORT_LSDYNA) { /* the curve after the group's LCINT card */
                char key[32];
                snprintf(key, sizeof key, "$ group %zu:", g + 1);
                p = strstr(x, key);
                assert_non_null(p);
                p = strstr(p, "*DEFINE_CURVE\n");
                p = strchr(strchr(p, '\n') + 1, '\n') + 1; /* past the comment */
                double c[8];
                fields(p, 10, 8, c);
                const double lcint = c[7];
                p = strchr(strchr(p, '\n') + 1, '\n') + 1; /* past the points' comment */
                while (*p != '*' && *p != '$' && n < 512) {
                    fields(p, 20, 2, c);
                    e[n] = c[0];
                    T[n++] = c[1];
                    p = strchr(p, '\n') + 1;
                }
                assert_true(lcint >= (double)n);
            } else if (f == CF_EXPORT_SOFA) { /* the force of the group's summed springs */
                static sofa_field sf[8192];
                const size_t nf = sofa_fields(x, sf, 8192);
                assert_true(nf < 8192);
                /* the fields of this group act on the group's first spring's nodes */
                char key[32];
                snprintf(key, sizeof key, "name=\"G%zu_rest\"", g + 1);
                const char *q = strstr(x, key);
                assert_non_null(q);
                const unsigned a = (unsigned)atoi(strstr(q, "firstObjectPoints=\"") + 19);
                const unsigned b = (unsigned)atoi(strstr(q, "secondObjectPoints=\"") + 20);
                const double u_end = cf_export_table_end(&law, 1e-3);
                for (int i = 0; i <= 400; i++) {
                    const double u = -u_end + 2.0 * u_end * i / 400.0;
                    e[n] = -u * L0[g] / P->H_mm;
                    double sum = 0.0;
                    for (size_t k = 0; k < nf; k++)
                        if (sf[k].first == a && sf[k].second == b)
                            sum += sofa_force(L0[g] + e[n], sf[k].l0, sf[k].a, sf[k].compressible);
                    T[n++] = sum;
                }
            } else {
                fail_msg("format %s writes models, but this test cannot read them back", fi->name);
            }
            assert_true(n > 10);
            for (size_t i = 0; i < n; i++) {
                const double want = -w[g] * cf_law_force(&law, CF_LAW_EXACT, -e[i] * P->H_mm / L0[g],
                                                         NULL, NULL);
                if (!(fabs(T[i] - want) <= 1.01e-3 * w[g] * law.F_C_N))
                    fail_msg("%s group %zu: %g N at elongation %g mm, law %g N", fi->name, g + 1,
                             T[i], e[i], want);
                checked++;
            }
            g++;
        }
        assert_true(checked > 100);
        free(x);
    }
}

static void lattice_models_of_every_format_hold_the_law_in_every_group(void **state)
{
    (void)state;
    lattice_models_hold_the_law("fit.json", &TEL, "latf");
}

/* Every format's lattice of tailed springs: their tables hold the series law, region 3 included
** (the tables run to the whole spring's solid, past where the cone closes). */
static void lattice_models_of_every_format_hold_the_tailed_law_in_every_group(void **state)
{
    (void)state;
    cf_law law;
    law_of(&law, &TAIL);
    assert_true(cf_export_table_end(&law, 1e-3) > law.u_C_mm);
    lattice_models_hold_the_law("tail.json", &TAIL, "latt");
}


/* What the one-spring model of each format must hold: its loading. */
static const char *example_must(cf_export_format f)
{
    switch (f) {
    case CF_EXPORT_CALCULIX:
        return "*STEP";
    case CF_EXPORT_ABAQUS:
        return "*STEP, NLGEOM=YES";
    case CF_EXPORT_FEBIO:
        return "type=\"prescribed displacement\"";
    case CF_EXPORT_LSDYNA:
        return "*BOUNDARY_PRESCRIBED_MOTION_SET";
    case CF_EXPORT_SOFA:
        return "PartialLinearMovementProjective";
    default:
        return NULL;
    }
}

static void every_format_has_a_runnable_example(void **state)
{
    (void)state;
    for (int f = 0; f < CF_EXPORT_FORMAT_COUNT; f++) {
        const cf_export_format_info *fi = cf_export_format_get((cf_export_format)f);
        if (!fi->model)
            continue;
        const char *must = example_must(fi->format);
        if (!must)
            fail_msg("format %s writes models, but this test does not know their loading",
                     fi->name);
        char args[64], name[32];
        snprintf(args, sizeof args, "--format %s --example --tol 1e-3", fi->name);
        snprintf(name, sizeof name, "ex.%s", fi->name);
        char *x = export_to(name, args);
        assert_non_null(strstr(x, must));
        assert_non_null(strstr(x, "2 nodes, 1 springs in 1 groups"));
        if (f == CF_EXPORT_FEBIO) { /* FEBio 4 builds the mesh on reading MeshDomains: first */
            const char *order[] = {"</Mesh>", "<MeshDomains/>", "<Boundary>", "<Discrete>",
                                   "<LoadData>", "<Output>"};
            const char *at = x;
            for (int k = 0; k < 6; k++) {
                const char *hit = strstr(at, order[k]);
                if (!hit)
                    fail_msg("FEBio model lacks %s in order", order[k]);
                at = hit;
            }
        }
        free(x);
    }
}

/* ---- the registry of formats ------------------------------------------------------------------ */

/* Every entry names itself, parses back, and stands in the command's help with its extension and
** description; an unknown name is refused with the list of all of them. */
static void the_format_registry_is_whole_and_drives_the_help(void **state)
{
    (void)state;
    char help[16384], err[1024];
    assert_int_equal(tu_run(help, sizeof help, err, sizeof err, "export --help"), 0);
    cf_error e = {0};
    cf_export_format g;
    assert_int_equal(cf_export_format_parse("vtk", &g, &e), CF_E_DATA);
    for (int f = 0; f < CF_EXPORT_FORMAT_COUNT; f++) {
        const cf_export_format_info *fi = cf_export_format_get((cf_export_format)f);
        assert_non_null(fi);
        assert_int_equal(fi->format, f);
        assert_true(fi->name[0] != '\0' && fi->extension[0] == '.' && fi->extension[1] != '\0');
        assert_true(fi->description[0] != '\0' && !strchr(fi->description, '\n'));
        assert_true(strlen(fi->description) <= 72); /* one line of the help */
        assert_string_equal(cf_export_format_name((cf_export_format)f), fi->name);
        cf_error e2 = {0};
        assert_int_equal(cf_export_format_parse(fi->name, &g, &e2), CF_OK);
        assert_int_equal(g, f);
        for (int k = 0; k < f; k++)
            assert_string_not_equal(cf_export_format_get((cf_export_format)k)->name, fi->name);
        assert_non_null(strstr(e.msg, fi->name));
        char line[256];
        snprintf(line, sizeof line, "  %-9s %-6s %-7s %s\n", fi->name, fi->extension,
                 fi->model ? "yes" : "no", fi->description);
        if (!strstr(help, line))
            fail_msg("export --help lacks the line '%s'", line);
    }
    assert_null(cf_export_format_get(CF_EXPORT_FORMAT_COUNT));
    assert_string_equal(cf_export_format_name(CF_EXPORT_FORMAT_COUNT), "?");
    char list[256];
    assert_string_equal(cf_export_format_list(list, sizeof list, 1),
                        "calculix, abaqus, febio, lsdyna or sofa");
    assert_string_equal(cf_export_format_list(list, 8, 0), "json, c"); /* truncated, terminated */
}

/* Without --format, the extension of -o names the format when exactly one format has it. */
static void the_output_extension_names_the_format(void **state)
{
    (void)state;
    cf_export_format g = CF_EXPORT_JSON;
    cf_error e = {0};
    assert_int_equal(cf_export_format_of_path("out/a.b/s.FEB", &g, &e), CF_OK);
    assert_int_equal(g, CF_EXPORT_FEBIO);
    assert_int_equal(cf_export_format_of_path("s.inp", &g, &e), CF_E_DATA);
    assert_non_null(strstr(e.msg, "calculix or abaqus"));
    assert_int_equal(cf_export_format_of_path("a.k/s", &g, &e), CF_E_DATA);
    assert_int_equal(cf_export_format_of_path("s.txt", &g, &e), CF_E_DATA);
    char *x = export_to("byname.feb", "--tol 1e-3");
    assert_non_null(strstr(x, "<febio_spec version=\"4.0\">"));
    free(x);
    char err[1024], p[160];
    struct stat st;
    snprintf(p, sizeof p, "%s/which.inp", dir);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "export %s/fit.json -o %s", dir, p), 2);
    assert_non_null(strstr(err, "calculix or abaqus"));
    assert_int_equal(stat(p, &st), -1);
    /* a format that writes data only is refused for a model, naming those that write models */
    assert_int_equal(tu_run(NULL, 0, err, sizeof err, "export %s/fit.json --format json --lattice",
                            dir),
                     2);
    assert_non_null(strstr(err, "calculix, abaqus, febio, lsdyna or sofa"));
    /* and the library refuses it too */
    cf_fitted_spring fs;
    char fit[96];
    snprintf(fit, sizeof fit, "%s/fit.json", dir);
    assert_int_equal(cf_fitfile_load(fit, NULL, &fs, &e), CF_OK);
    cf_export_options opt = cf_export_default_options();
    opt.format = CF_EXPORT_CSV;
    opt.example = 1;
    FILE *devnull = fopen("/dev/null", "w");
    assert_non_null(devnull);
    assert_int_equal(cf_export_write(devnull, &fs, &opt, NULL, &e), CF_E_DATA);
    opt.example = 0;
    cf_law law;
    law_of(&law, &TEL);
    const cf_export_lattice lx = cf_export_lattice_default(&law);
    assert_int_equal(cf_export_write_lattice(devnull, &fs, &opt, &lx, NULL, &e), CF_E_DATA);
    assert_non_null(strstr(e.msg, "csv"));
    fclose(devnull);
}

static void an_unstable_lattice_loading_is_cut_where_it_stops_working(void **state)
{
    (void)state;
    cf_law law;
    law_of(&law, &TEL);
    /* deep compression: the lattice buckles (its tangent turns indefinite) before the end; the
    ** model holds the steps before, the header and a warning say where and why it is cut */
    write_scene("latbad.json", 0.9 * law.travel_mm / TEL.H_mm, 10);
    char err[2048], p[160];
    snprintf(p, sizeof p, "%s/latbad.inp", dir);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err,
                            "export %s/fit.json --lattice %s/latbad.json --format calculix -o %s",
                            dir, dir, p),
                     0);
    assert_non_null(strstr(err, "warning: the loading is cut after step "));
    assert_non_null(strstr(err, "loses stability"));
    assert_non_null(strstr(err, "negative pivots"));
    /* the limit it names is below the unstable step, and a loading just under it is whole */
    const char *lim = strstr(err, "stable up to strain ");
    assert_non_null(lim);
    const double limit = atof(lim + strlen("stable up to strain "));
    assert_true(limit > 0 && limit < 0.9 * law.travel_mm / TEL.H_mm);
    const char *cut = strstr(err, "cut after step ");
    const int kept = atoi(cut + strlen("cut after step "));
    assert_true(kept >= 1 && kept < 10);
    const double ok = atof(strstr(err, "works up to strain ") + strlen("works up to strain "));
    assert_true(ok > 0 && ok <= limit);
    char *x = tu_slurp(p);
    assert_non_null(x);
    assert_non_null(strstr(x, "** note: the loading is cut after step "));
    int steps = 0;
    for (const char *q = strstr(x, "*STEP"); q; q = strstr(q + 1, "*STEP"))
        steps++;
    assert_int_equal(steps, kept);
    char last[64];
    snprintf(last, sizeof last, "step %d: ", kept);
    assert_non_null(strstr(x, last));
    snprintf(last, sizeof last, "step %d: ", kept + 1);
    assert_null(strstr(x, last));
    free(x);
    write_scene("latlim.json", 0.99 * limit, 6);
    char largs[128];
    snprintf(largs, sizeof largs, "--lattice %s/latlim.json --format calculix", dir);
    x = export_to("latlim.inp", largs);
    assert_null(strstr(x, "note:")); /* nothing cut */
    free(x);
    /* not even the first step works: refused, nothing written */
    struct stat st;
    snprintf(p, sizeof p, "%s/latnone.inp", dir);
    write_scene("latnone.json", 0.9 * law.travel_mm / TEL.H_mm, 1);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err,
                            "export %s/fit.json --lattice %s/latnone.json --format calculix -o %s",
                            dir, dir, p),
                     65);
    assert_non_null(strstr(err, "not even the first step"));
    assert_int_equal(stat(p, &st), -1);
}

/* A scene's time protocol: load-unload cycles are written as the elastic lattice's displacement
** history, one step per sample (back to the rest state in between), its header and a warning
** naming the time effect it leaves out; a ramp under a stress drive is still refused. */
static void a_time_protocol_is_written_as_its_displacement_history(void **state)
{
    (void)state;
    char p[160], err[2048];
    snprintf(p, sizeof p, "%s/cyc.json", dir);
    FILE *f = fopen(p, "w");
    assert_non_null(f);
    fprintf(f, "{\"spring\": {\"params\": {\"D1_mm\": 10, \"D2_mm\": 30, \"n\": 4, \"d_mm\": 1, "
               "\"G_MPa\": 80000, \"H_mm\": 40}}, \"protocol\": {\"kind\": \"cycles\", "
               "\"to_strain\": 0.05, \"period_s\": 1, \"count\": 2}, \"samples_per_segment\": 2, "
               "\"effects\": {\"viscosity\": {\"prony\": [{\"g\": 0.3, \"tau_s\": 2}]}}}\n");
    fclose(f);
    char out[160];
    snprintf(out, sizeof out, "%s/cyc.inp", dir);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err,
                            "export %s/fit.json --lattice %s --format calculix -o %s", dir, p, out),
                     0);
    assert_non_null(strstr(err, "warning: protocol 'cycles'"));
    assert_non_null(strstr(err, "not carried: 1 Prony terms (viscosity)"));
    assert_non_null(strstr(err, "8 load steps"));
    char *x = tu_slurp(out);
    assert_non_null(x);
    assert_non_null(strstr(x, "** note: protocol 'cycles' written as its quasi-static"));
    /* 0.025, 0.05, 0.025, 0, twice */
    const double want[8] = {0.025, 0.05, 0.025, 0, 0.025, 0.05, 0.025, 0};
    const char *q = x;
    for (int k = 0; k < 8; k++) {
        char key[48];
        snprintf(key, sizeof key, "step %d: top z displacement ", k + 1);
        q = strstr(q, key);
        assert_non_null(q);
        const char *s = strstr(q, "(strain ");
        assert_non_null(s);
        assert_close(atof(s + strlen("(strain ")), want[k], 1e-9);
    }
    free(x);
    /* a ramp under a stress drive: validation's refusal, naming the key */
    f = fopen(p, "w");
    assert_non_null(f);
    fprintf(f, "{\"spring\": {\"params\": {\"D1_mm\": 10, \"D2_mm\": 30, \"n\": 4, \"d_mm\": 1, "
               "\"G_MPa\": 80000, \"H_mm\": 40}}, \"protocol\": {\"kind\": \"ramp\", "
               "\"to_stress_kPa\": 1, \"duration_s\": 1}}\n");
    fclose(f);
    assert_int_equal(tu_run(NULL, 0, err, sizeof err,
                            "export %s/fit.json --lattice %s --format calculix", dir, p),
                     65);
    assert_non_null(strstr(err, "to_stress_kPa"));
}

/* A body (a block of 2 x 2 x 2 cells, no volume term) exported to SOFA by cf_export_write_body:
** every edge's PolynomialSpringsForceField terms sum to its calibrated law (the factor c times
** the law in strain form) within the table's tolerance, the punch drives the nodes under its
** face, and a body with a volume term is refused. */
static void a_body_scene_for_sofa_holds_every_edge_law(void **state)
{
    (void)state;
    cf_law law;
    law_of(&law, &TEL);
    double g[3] = {0, 20, 40};
    cf_mesh m;
    assert_int_equal(cf_mesh_block(&m, g, 2, g, 2, g, 2, NULL), CF_OK);
    cf_body b;
    cf_error err = {0};
    assert_int_equal(cf_body_create(&b, &m, &law, CF_LAW_CLOSED, 0, &err), CF_OK);
    for (size_t i = 0; i < b.nn; i++)
        if (b.X[3 * i + 2] < 1e-9)
            b.fix[i] = CF_BODY_FIX_ALL;
    cf_probe pr = {CF_PROBE_PUNCH, 25, {20, 20, 40}, {0, 0, -1}, 1, 1};
    double depth = 1, force;
    cf_body_step bst;
    if (cf_body_solve(&b, &pr, depth, 0, &bst, &err) != CF_OK)
        fail_msg("%s", err.msg);
    force = bst.force_N;
    uint8_t contact[27];
    assert_int_equal(b.nn, 27);
    assert_int_equal(cf_body_contact_set(&b, contact), 5);
    const cf_export_body_run run = {1, &depth, &force, b.x, contact};
    char *x = NULL;
    size_t len = 0;
    FILE *mem = open_memstream(&x, &len);
    assert_non_null(mem);
    cf_export_options opt = cf_export_default_options();
    opt.format = CF_EXPORT_SOFA;
    opt.tol = 1e-4;
    cf_export_report rep;
    if (cf_export_write_body(mem, &b, &pr, &run, &opt, &rep, &err) != CF_OK)
        fail_msg("%s", err.msg);
    fclose(mem);
    assert_int_equal(rep.groups, b.ns);
    /* the punch of radius 25 on the top's centre pushes 5 nodes, (20, 20) and its 4 neighbours:
    ** each driven along z as conifit solved it */
    int idx = 0;
    for (const char *d = x; (d = strstr(d, "movedDirections=\"0 0 1\" indices=\"")); d++) {
        unsigned i;
        assert_int_equal(sscanf(d, "movedDirections=\"0 0 1\" indices=\"%u\"", &i), 1);
        assert_true(i < 27 && contact[i]);
        char want[96];
        snprintf(want, sizeof want, "movements=\"0 0 0  0 0 %.17g\"", b.x[3 * i + 2] - b.X[3 * i + 2]);
        assert_non_null(strstr(d, want));
        idx++;
    }
    assert_int_equal(idx, 5);
    static sofa_field f[1 << 17];
    const size_t n = sofa_fields(x, f, 1 << 17);
    assert_true(n <= 1 << 17);
    /* from full stretch to near solid, as for one spring: u = H (L0 - l)/L0 */
    const double H = TEL.H_mm, u_end = cf_export_table_end(&law, 1e-4);
    size_t *mine = malloc(n * sizeof *mine);
    assert_non_null(mine);
    double worst = 0;
    for (size_t s = 0; s < b.ns; s++) {
        const unsigned i = b.si[s], j = b.sj[s];
        size_t terms = 0;
        for (size_t k = 0; k < n; k++)
            if ((f[k].first == i && f[k].second == j) || (f[k].first == j && f[k].second == i))
                mine[terms++] = k;
        assert_true(terms >= 2);
        for (int q = -400; q <= 400; q++) {
            const double u = u_end * q / 400, l = b.L0[s] * (1 - u / H);
            double T = 0;
            for (size_t k = 0; k < terms; k++)
                T += sofa_force(l, f[mine[k]].l0, f[mine[k]].a, f[mine[k]].compressible);
            const double want = b.c[s] * tension(&law, -u);
            worst = fmax(worst, fabs(T - want) / (b.c[s] * law.F_C_N));
        }
    }
    free(mine);
    print_message("body for SOFA: %zu springs, %zu force fields, worst %.3g of c F_C\n", b.ns, n,
                  worst);
    if (worst > 1e-4)
        fail_msg("SOFA springs of the body off their laws by %g of c F_C", worst);
    assert_true(worst > 1e-7); /* the comparison sees the tables, not a copy of the law */
    free(x);
    /* with a volume term: refused, naming sofa and the way out */
    cf_body bv;
    assert_int_equal(cf_body_create(&bv, &m, &law, CF_LAW_CLOSED, 1e-3, &err), CF_OK);
    FILE *null = fopen("/dev/null", "w");
    assert_int_equal(cf_export_write_body(null, &bv, &pr, &run, &opt, &rep, &err), CF_E_DATA);
    fclose(null);
    assert_non_null(strstr(err.msg, "volume term"));
    cf_body_free(&bv);
    cf_body_free(&b);
    cf_mesh_free(&m);
    cf_law_free(&law);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(tables_stay_within_tolerance_on_a_dense_grid_for_both_types),
        cmocka_unit_test(tables_of_a_tailed_spring_stay_within_tolerance_through_region_3),
        cmocka_unit_test(a_tail_too_stiff_to_tabulate_is_refused_naming_n_tail),
        cmocka_unit_test(row_count_grows_like_inverse_square_root_of_tolerance),
        cmocka_unit_test(every_spring_from_rho_0_05_fits_200_rows_at_1e_4),
        cmocka_unit_test(a_range_covers_only_what_is_asked_and_stays_within_tolerance),
        cmocka_unit_test(cylindrical_spring_needs_three_rows),
        cmocka_unit_test(shipped_fits_export_for_calculix_at_1e_4_within_200_pairs),
        cmocka_unit_test(febio_output_follows_the_febio4_layout_and_the_law),
        cmocka_unit_test(lsdyna_curve_carries_lcint_of_at_least_its_rows),
        cmocka_unit_test(sofa_scene_is_compressible_and_follows_the_law_within_tol),
        cmocka_unit_test(a_body_scene_for_sofa_holds_every_edge_law),
        cmocka_unit_test(inp_block_has_its_layout_and_the_law),
        cmocka_unit_test(json_round_trips_through_force_spring),
        cmocka_unit_test(bad_input_gives_its_exit_status_the_number_that_works_and_no_output),
        cmocka_unit_test(calculix_runs_the_one_spring_example_and_matches_the_law),
        cmocka_unit_test(calculix_holds_the_last_force_beyond_the_table),
        cmocka_unit_test(calculix_runs_the_lattice_and_matches_conifit_simulate_at_every_step),
        cmocka_unit_test(calculix_runs_the_pair_and_volume_lattice_and_matches_simulate),
        cmocka_unit_test(every_export_of_a_pair_holds_both_springs),
        cmocka_unit_test(lattice_models_of_every_format_hold_the_law_in_every_group),
        cmocka_unit_test(lattice_models_of_every_format_hold_the_tailed_law_in_every_group),
        cmocka_unit_test(every_format_has_a_runnable_example),
        cmocka_unit_test(the_format_registry_is_whole_and_drives_the_help),
        cmocka_unit_test(the_output_extension_names_the_format),
        cmocka_unit_test(an_unstable_lattice_loading_is_cut_where_it_stops_working),
        cmocka_unit_test(a_time_protocol_is_written_as_its_displacement_history),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
