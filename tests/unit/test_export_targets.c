/*
** Tests of what the FEBio exports tell their simulator and their reader
** (src/report/export_model.c, export_table.c, conifit export):
**  - FEBio: the log file of the top reactions is named after the output (-o), so two models in
**    one folder do not share it; an output's name from outside is written XML-escaped with no
**    folder in it (the XML parsed back by libxml2 gives the name); the header says what FEBio
**    writes (one line per top node and step) and the sign of Rz; the convergence tolerances are
**    ones FEBio can meet in double precision (no dtol of 1e-9);
*/
#include <limits.h>

#include "testutil.h"

#include <libxml/parser.h>
#include <libxml/tree.h>

#include "conifit/export.h"
#include "conifit/law.h"
#include "report/export_model.h"

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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(febio_log_name_is_the_output_base_name_written_safely),
        cmocka_unit_test(febio_log_file_follows_the_output_so_two_models_do_not_share_it),
        cmocka_unit_test(febio_header_says_what_febio_writes_and_the_sign_of_rz),
        cmocka_unit_test(febio_tolerances_can_be_met_in_double_precision_and_keep_the_tolerance),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
