/*
** Tests of what the FEBio and LS-DYNA exports tell their simulator and their reader
** (src/export/export_model.c, export_table.c, conifit export):
**  - FEBio: the log file of the top reactions is named after the output (-o), so two models in
**    one folder do not share it; an output's name from outside is written XML-escaped with no
**    folder in it (the XML parsed back by libxml2 gives the name); the header says what FEBio
**    writes (one line per top node and step) and the sign of Rz; the convergence tolerances are
**    ones FEBio can meet in double precision (no dtol of 1e-9);
**  - LS-DYNA: every curve is evenly spaced with LCINT = rows, so LS-DYNA's rediscretization to
**    LCINT equally spaced points gives the rows back; resampled here as LS-DYNA does, the curve is
**    within the stated tolerance over the stated range, and the header and the summary on stderr
**    state that range and what happens past it.
*/
#include <limits.h>

#include "testutil.h"

#include <libxml/parser.h>
#include <libxml/tree.h>

#include "export/export.h"
#include "model/law_internal.h"
#include "export/export_model.h"

static char dir[] = "/tmp/conifit-xtargets-XXXXXX";
static char conifit_abs[PATH_MAX], fit[PATH_MAX + 16], scene[PATH_MAX + 16];

static const cf_spring TEL = {10, 30, 4, 1, 80000, 40}; /* telescoping, rho = 1/3, s = 39 mm */

static int setup(void **state)
{
    (void)state;
    if (!mkdtemp(dir) || !realpath(tu_conifit(), conifit_abs))
        return -1;
    snprintf(fit, sizeof fit, "%s/fit.json", dir);
    FILE *f = fopen(fit, "w");
    if (!f)
        return -1;
    fprintf(f, "{\"fits\":[{\"type\":\"telescoping\",\"params\":{\"D1_mm\":10,\"D2_mm\":30,\"n\":4,"
               "\"d_mm\":1,\"G_MPa\":80000,\"H_mm\":40}}]}\n");
    fclose(f);
    /* a small lattice loaded to 0.3 of the solid strain, which it follows stably */
    char p[PATH_MAX + 16];
    snprintf(p, sizeof p, "%s/scene.json", dir);
    if (!(f = fopen(p, "w")))
        return -1;
    fprintf(f, "{\"spring\": {\"fit\": \"%s\", \"type\": \"telescoping\"},\n"
               " \"lattice\": {\"nx\": 2, \"ny\": 2, \"nz\": 2, \"diagonals\": \"face+body\", "
               "\"bottom\": \"axial\"},\n"
               " \"protocol\": {\"kind\": \"ramp\", \"to_strain\": %.17g, \"duration_s\": 1},\n"
               " \"samples_per_segment\": 4}\n",
               fit, 0.3 * 39.0 / 40.0);
    fclose(f);
    snprintf(scene, sizeof scene, "%s/scene.json", dir);
    xmlInitParser();
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[PATH_MAX + 16];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    xmlCleanupParser();
    return system(cmd) == 0 ? 0 : -1;
}

/* Runs conifit export FIT ARGS... (no shell: names may hold any byte) in the scratch folder with
** -o out (NULL: standard output, discarded); the file's text (caller frees), or NULL for stdout.
** The standard error goes to dir/stderr.txt. */
static char *export_run(const char *out, const char *const *args)
{
    char *argv[16];
    int a = 0;
    argv[a++] = conifit_abs;
    argv[a++] = "export";
    argv[a++] = fit;
    for (; *args; args++)
        argv[a++] = (char *)*args;
    if (out) {
        argv[a++] = "-o";
        argv[a++] = (char *)out;
    }
    argv[a] = NULL;
    const int rc = tu_exec(dir, NULL, argv, "stderr.txt");
    if (rc != 0) {
        char p[PATH_MAX];
        snprintf(p, sizeof p, "%s/stderr.txt", dir);
        char *e = tu_slurp(p);
        fail_msg("conifit export exited %d: %s", rc, e ? e : "");
    }
    if (!out)
        return NULL;
    char p[PATH_MAX + 300];
    snprintf(p, sizeof p, "%s/%s", dir, out);
    char *text = tu_slurp(p);
    assert_non_null(text);
    return text;
}

static char *stderr_text(void)
{
    char p[PATH_MAX];
    snprintf(p, sizeof p, "%s/stderr.txt", dir);
    char *e = tu_slurp(p);
    assert_non_null(e);
    return e;
}

/* The file attribute of the FEBio model's node_data log request, as an XML parser reads it
** (entities decoded; caller frees). Fails unless text is well-formed XML with one such element. */
static char *febio_log_file(const char *text)
{
    xmlDocPtr doc = xmlReadMemory(text, (int)strlen(text), "model.feb", NULL,
                                  XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING);
    if (!doc)
        fail_msg("the FEBio model is not well-formed XML");
    xmlNodePtr n = xmlDocGetRootElement(doc);
    const char *path[] = {"Output", "logfile", "node_data"};
    for (int k = 0; k < 3 && n; k++) {
        xmlNodePtr c = n->children;
        while (c && !(c->type == XML_ELEMENT_NODE && strcmp((const char *)c->name, path[k]) == 0))
            c = c->next;
        n = c;
    }
    assert_non_null(n);
    xmlChar *v = xmlGetProp(n, (const xmlChar *)"file");
    assert_non_null(v);
    char *s = strdup((const char *)v);
    xmlFree(v);
    xmlFreeDoc(doc);
    return s;
}

/* ---- FEBio ------------------------------------------------------------------------------------ */

static void febio_log_name_is_the_output_base_name_written_safely(void **state)
{
    (void)state;
    char b[2048];
    assert_string_equal(cf_export_febio_log_name(b, sizeof b, NULL), "conifit_top_Rz.txt");
    assert_string_equal(cf_export_febio_log_name(b, sizeof b, ""), "conifit_top_Rz.txt");
    assert_string_equal(cf_export_febio_log_name(b, sizeof b, "runs/a/lattice.feb"),
                        "lattice_top_Rz.txt");
    assert_string_equal(cf_export_febio_log_name(b, sizeof b, "runs/"), "conifit_top_Rz.txt");
    assert_string_equal(cf_export_febio_log_name(b, sizeof b, "C:\\runs\\x.y.feb"),
                        "x.y_top_Rz.txt");
    assert_string_equal(cf_export_febio_log_name(b, sizeof b, "noext"), "noext_top_Rz.txt");
    /* markup as entities, separators and control bytes as '_', UTF-8 kept, bad bytes '_' */
    assert_string_equal(cf_export_febio_log_name(b, sizeof b, "a:b<c>&\"'\n\x1b\xff\xc3\xa9.feb"),
                        "a_b&lt;c&gt;&amp;&quot;&apos;___\xc3\xa9_top_Rz.txt");
    /* a long name is cut, never inside a character, and always keeps the suffix */
    char longname[600];
    memset(longname, 'a', 199);
    strcpy(longname + 199, "\xc3\xa9\xc3\xa9.feb");
    cf_export_febio_log_name(b, sizeof b, longname);
    assert_int_equal(strlen(b), 199 + strlen("_top_Rz.txt"));
    /* a small buffer: cut, still the suffix */
    char s[24];
    assert_string_equal(cf_export_febio_log_name(s, sizeof s, "abcdefghijklmnop.feb"),
                        "abcdefghijkl_top_Rz.txt");
}

static void febio_log_file_follows_the_output_so_two_models_do_not_share_it(void **state)
{
    (void)state;
    const char *lat[] = {"--lattice", scene, "--format", "febio", "--tol", "1e-3", NULL};
    const char *ex[] = {"--example", "--format", "febio", "--tol", "1e-3", NULL};
    char *a = export_run("first.feb", lat);
    char *b = export_run("second.feb", lat);
    char *c = export_run("spring.feb", ex);
    char *la = febio_log_file(a), *lb = febio_log_file(b), *lc = febio_log_file(c);
    assert_string_equal(la, "first_top_Rz.txt");
    assert_string_equal(lb, "second_top_Rz.txt");
    assert_string_equal(lc, "spring_top_Rz.txt");
    assert_string_not_equal(la, lb);
    free(la), free(lb), free(lc), free(a), free(b), free(c);
    /* a name from outside: parsed back, it is the name's base with markup intact and no folder */
    const char *hostile = "we\"ird <&> 'name'.feb";
    char *h = export_run(hostile, ex);
    char *lh = febio_log_file(h);
    assert_string_equal(lh, "we\"ird <&> 'name'_top_Rz.txt");
    assert_null(strchr(lh, '/'));
    free(lh), free(h);
    const char *nl = "x\ny\x1b[31m.feb";
    h = export_run(nl, ex);
    lh = febio_log_file(h);
    assert_string_equal(lh, "x_y_[31m_top_Rz.txt");
    free(lh), free(h);
}

static void febio_header_says_what_febio_writes_and_the_sign_of_rz(void **state)
{
    (void)state;
    const char *ex[] = {"--example", "--format", "febio", "--tol", "1e-3", NULL};
    char *x = export_run("sign.feb", ex);
    assert_null(strstr(x, "column sums"));
    const char *must[] = {"one line 'node,Rz' per top node",
                          "the top reaction of step k is the sum of Rz over those lines",
                          "negative under compression",
                          "conifit's compressive reaction above is minus that sum"};
    for (int i = 0; i < 4; i++)
        if (!strstr(x, must[i]))
            fail_msg("the FEBio header lacks \"%s\"", must[i]);
    free(x);
}

/* Reads the number inside <tag>...</tag> of x. */
static double xml_number(const char *x, const char *tag)
{
    char open[64];
    snprintf(open, sizeof open, "<%s>", tag);
    const char *p = strstr(x, open);
    if (!p)
        fail_msg("no <%s> in the FEBio model", tag);
    return strtod(p + strlen(open), NULL);
}

static void febio_tolerances_can_be_met_in_double_precision_and_keep_the_tolerance(void **state)
{
    (void)state;
    cf_law law;
    cf_error err = {0};
    assert_int_equal(cf_law_init(&law, &TEL, &err), CF_OK);
    const char *ex[] = {"--example", "--format", "febio", "--tol", "1e-4", NULL};
    char *x = export_run("tols.feb", ex);
    /* FEBio tests |du|^2 <= dtol^2 |dU|^2: the correction must be reachable far above round-off
    ** (1e-9 was not: the residual passed under FEBio's floor first) */
    const double dtol = xml_number(x, "dtol");
    assert_true(dtol >= 1e-7 && dtol <= 1e-4);
    /* |R|^2 <= rtol |R0|^2: the unbalanced force at most 1e-2 of the tolerance, of R0 */
    const double rtol = xml_number(x, "rtol");
    assert_true(rtol > 0 && sqrt(rtol) <= 1e-2 * 1e-4 * (1 + 1e-9) && sqrt(rtol) >= 1e-13);
    /* the residual floor well below what the tolerance leaves, well above round-off */
    const double floor_N = sqrt(xml_number(x, "min_residual"));
    assert_true(floor_N <= 1e-6 * 1e-4 * law.F_C_N && floor_N >= 1e-15 * law.F_C_N);
    assert_int_equal((int)xml_number(x, "max_ups"), 0); /* full Newton */
    free(x);
    cf_law_free(&law);
}

/* ---- LS-DYNA ---------------------------------------------------------------------------------- */

/* Splits a fixed-width card into fields of `w` characters. */
static void fields(const char *line, int w, int count, double *out)
{
    char f[24];
    for (int k = 0; k < count; k++) {
        snprintf(f, (size_t)w + 1, "%.*s", w, line + w * k);
        out[k] = atof(f);
    }
}

typedef struct curve {
    size_t n, lcint;
    double *x, *y; /* elongation (mm), tension (N) */
} curve;

/* Reads the *DEFINE_CURVE after position p: its LCINT and its points. Returns the position past
** them. */
static const char *read_curve(const char *p, curve *c)
{
    p = strstr(p, "*DEFINE_CURVE\n");
    assert_non_null(p);
    p = strchr(strchr(p, '\n') + 1, '\n') + 1; /* past the keyword and the comment */
    double f[8];
    fields(p, 10, 8, f);
    c->lcint = (size_t)f[7];
    p = strchr(strchr(p, '\n') + 1, '\n') + 1; /* past the card and the points' comment */
    size_t cap = 1024;
    c->n = 0;
    c->x = malloc(cap * sizeof *c->x);
    c->y = malloc(cap * sizeof *c->y);
    while (*p && *p != '*' && *p != '$') {
        if (c->n == cap) {
            cap *= 2;
            c->x = realloc(c->x, cap * sizeof *c->x);
            c->y = realloc(c->y, cap * sizeof *c->y);
        }
        fields(p, 20, 2, f);
        c->x[c->n] = f[0];
        c->y[c->n++] = f[1];
        p = strchr(p, '\n') + 1;
    }
    return p;
}

/* Linear interpolation of the points (x ascending) at v, the end values outside. */
static double interp(const double *x, const double *y, size_t n, double v)
{
    if (v <= x[0])
        return y[0];
    if (v >= x[n - 1])
        return y[n - 1];
    size_t lo = 0, hi = n - 1;
    while (hi - lo > 1) {
        size_t mid = (lo + hi) / 2;
        if (x[mid] <= v)
            lo = mid;
        else
            hi = mid;
    }
    return y[lo] + (v - x[lo]) / (x[hi] - x[lo]) * (y[hi] - y[lo]);
}

/* The curve as LS-DYNA uses it: rediscretized to m equally spaced points between its first and
** last abscissa (LSTC FAQ "discretization of curves"), then interpolated linearly. Returns the
** largest distance from the law in tension, -scale F(-e L0 ... ), over [x_lo, x_hi] on a dense
** grid of its own (uniform, and crowded towards both ends), as a fraction of F_C. */
static double resampled_error(const curve *c, size_t m, const cf_law *law, double stretch,
                              double weight, double x_lo, double x_hi)
{
    double *rx = malloc(m * sizeof *rx), *ry = malloc(m * sizeof *ry);
    assert_true(rx && ry);
    const double a = c->x[0], b = c->x[c->n - 1];
    for (size_t j = 0; j < m; j++) {
        rx[j] = a + (b - a) * (double)j / (double)(m - 1);
        ry[j] = interp(c->x, c->y, c->n, rx[j]);
    }
    double worst = 0.0;
    const int N = 200003;
    for (int i = 0; i <= N; i++) {
        const double w = (double)i / N, q = w * w * w;
        const double xs[3] = {x_lo + (x_hi - x_lo) * w, x_hi - (x_hi - x_lo) * 0.5 * q,
                              x_lo + (x_hi - x_lo) * 0.5 * q};
        for (int k = 0; k < 3; k++) {
            const double law_T =
                -weight * cf_law_force(law, CF_LAW_EXACT, -xs[k] * stretch, NULL, NULL);
            worst = fmax(worst, fabs(interp(rx, ry, m, xs[k]) - law_T) / (weight * law->F_C_N));
        }
    }
    free(rx), free(ry);
    return worst;
}

/* The rows are evenly spaced (as printed: 13 significant digits) and LCINT is their count. */
static void assert_even_with_lcint(const curve *c)
{
    assert_true(c->n >= 2);
    if (c->lcint != c->n)
        fail_msg("LCINT %zu for a curve of %zu rows", c->lcint, c->n);
    const double a = c->x[0], b = c->x[c->n - 1];
    for (size_t i = 0; i < c->n; i++) {
        const double want = a + (b - a) * (double)i / (double)(c->n - 1);
        if (fabs(c->x[i] - want) > 1e-11 * (b - a))
            fail_msg("row %zu at %.15g, not evenly spaced (%.15g)", i, c->x[i], want);
    }
}

/* The range and tolerance the header states: "table: N rows over u in [lo, hi] mm ... within
** TOL F_C". */
static void stated_range(const char *x, size_t *rows, double *lo, double *hi, double *tol)
{
    const char *p = strstr(x, "table: ");
    assert_non_null(p);
    assert_int_equal(sscanf(p, "table: %zu rows over u in [%lf, %lf] mm", rows, lo, hi), 3);
    p = strstr(p, "within ");
    assert_non_null(p);
    assert_int_equal(sscanf(p, "within %lf F_C", tol), 1);
}

static void lsdyna_curve_resampled_as_lsdyna_does_is_within_the_stated_tolerance(void **state)
{
    (void)state;
    cf_law law;
    cf_error err = {0};
    assert_int_equal(cf_law_init(&law, &TEL, &err), CF_OK);
    const char *full[] = {"--format", "lsdyna", "--tol", "1e-4", NULL};
    const char *part[] = {"--format", "lsdyna", "--tol", "1e-4", "--range", "-5:30", NULL};
    const char *const *cases[2] = {full, part};
    for (int k = 0; k < 2; k++) {
        char *x = export_run("spring.k", cases[k]);
        char *e = stderr_text();
        size_t rows;
        double lo, hi, tol;
        stated_range(x, &rows, &lo, &hi, &tol);
        assert_close(tol, 1e-4, 0);
        curve c;
        read_curve(x, &c);
        assert_int_equal(c.n, rows);
        assert_even_with_lcint(&c);
        /* the curve spans the stated range: elongation -hi .. -lo */
        assert_close(c.x[0], -hi, 1e-9 * hi);
        assert_close(c.x[c.n - 1], -lo, 1e-9 * hi);
        const double err_lcint = resampled_error(&c, c.lcint, &law, 1.0, 1.0, -hi, -lo);
        if (err_lcint > tol)
            fail_msg("resampled to LCINT = %zu points, the curve is %g F_C off the law", c.lcint,
                     err_lcint);
        assert_true(err_lcint > 0.3 * tol); /* the check sees the table, not the law */
        /* LS-DYNA's default of 100 points would not do */
        const double err_100 = resampled_error(&c, 100, &law, 1.0, 1.0, -hi, -lo);
        print_message("LS-DYNA curve of %zu rows over u in [%g, %g] mm: %.3g F_C off the law "
                      "resampled to LCINT points, %.3g F_C to 100\n",
                      rows, lo, hi, err_lcint, err_100);
        assert_true(err_100 > (k == 0 ? 10 : 1) * tol);
        if (k == 0) { /* the full range is shortened, within the row limit, and says so */
            assert_true(rows <= CF_EXPORT_LSDYNA_MAX_ROWS);
            assert_true(hi < cf_export_table_end(&law, 1e-4) && hi > 0.99 * law.travel_mm);
            assert_non_null(strstr(x, "$ range: u in ["));
            assert_non_null(strstr(x, "shortened from ["));
            assert_non_null(strstr(e, "shortened from ["));
        } else { /* a range the even rows meet is kept whole, with the fewest rows */
            assert_close(lo, -5, 0);
            assert_close(hi, 30, 0);
            assert_true(rows < CF_EXPORT_LSDYNA_MAX_ROWS);
            assert_null(strstr(x, "shortened from"));
        }
        assert_non_null(strstr(x, "LCINT = "));
        assert_non_null(strstr(x, "past them LS-DYNA extrapolates"));
        assert_non_null(strstr(e, "past them the curve is extrapolated"));
        free(c.x), free(c.y), free(x), free(e);
    }
    cf_law_free(&law);
}

/* Every group of the lattice model: an even curve with LCINT = rows, within the tolerance of the
** law at that group's rest length and weight once resampled as LS-DYNA does. */
static void lsdyna_lattice_curves_are_even_and_within_tolerance_in_every_group(void **state)
{
    (void)state;
    cf_law law;
    cf_error err = {0};
    assert_int_equal(cf_law_init(&law, &TEL, &err), CF_OK);
    const char *lat[] = {"--lattice", scene, "--format", "lsdyna", "--tol", "1e-3", NULL};
    char *x = export_run("lattice.k", lat);
    size_t rows;
    double lo, hi, tol;
    stated_range(x, &rows, &lo, &hi, &tol);
    size_t groups = 0;
    for (const char *p = strstr(x, "\n$ group "); p; p = strstr(p + 1, "\n$ group ")) {
        size_t g;
        double L0, w;
        assert_int_equal(sscanf(p, "\n$ group %zu: L0 = %lf mm, weight %lf", &g, &L0, &w), 3);
        curve c;
        read_curve(p, &c);
        assert_int_equal(c.n, rows);
        assert_even_with_lcint(&c);
        const double stretch = TEL.H_mm / L0; /* u = -e H / L0 */
        const double e_lo = -hi / stretch, e_hi = -lo / stretch;
        assert_close(c.x[0], e_lo, 1e-9 * fabs(e_lo));
        const double er = resampled_error(&c, c.lcint, &law, stretch, w, e_lo, e_hi);
        if (er > tol)
            fail_msg("group %zu resampled is %g F_C off the law", g, er);
        free(c.x), free(c.y);
        groups++;
    }
    assert_true(groups >= 3);
    free(x);
    cf_law_free(&law);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(febio_log_name_is_the_output_base_name_written_safely),
        cmocka_unit_test(febio_log_file_follows_the_output_so_two_models_do_not_share_it),
        cmocka_unit_test(febio_header_says_what_febio_writes_and_the_sign_of_rz),
        cmocka_unit_test(febio_tolerances_can_be_met_in_double_precision_and_keep_the_tolerance),
        cmocka_unit_test(lsdyna_curve_resampled_as_lsdyna_does_is_within_the_stated_tolerance),
        cmocka_unit_test(lsdyna_lattice_curves_are_even_and_within_tolerance_in_every_group),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
