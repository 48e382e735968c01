/*
** A fit file's name is text from outside, and every export writes it into a comment: whatever the
** name holds, it must stay inside that comment. For each format (the spring block, --example and
** --lattice models) and hostile names (a newline followed by a CalculiX/Abaqus keyword, "--" and
** "-->" that end XML comments, a byte that is not UTF-8, a tab and a carriage return), the export
** has exactly the lines of the same export from a plain name, no line the name made, and the XML
** (FEBio, SOFA) and JSON outputs parse. The control: an XML comment holding "--" does not parse.
*/
#include <errno.h>
#include <limits.h>
#include <sys/stat.h>

#include <jansson.h>
#include <libxml/parser.h>

#include "testutil.h"

static char scratch[] = "/tmp/conifit-xnames-XXXXXX";
static char conifit_abs[PATH_MAX], fit_text_path[PATH_MAX];

static const char *const hostile[] = {
    "nl\n*INCLUDE,INPUT=secret.inp\n*STEP\n.json",
    "fit--v2.json",
    "x--><!-- y-.json",
    "deg\xb0-.json",
    "tab\there\rcr.json",
};
#define NHOSTILE (sizeof hostile / sizeof hostile[0])

typedef struct format {
    const char *name;
    int models; /* --example and --lattice apply */
    int xml;
} format;

static const format formats[] = {
    {"calculix", 1, 0}, {"abaqus", 1, 0}, {"lsdyna", 1, 0}, {"febio", 1, 1},
    {"sofa", 1, 1},     {"json", 0, 0},   {"csv", 0, 0},
};
#define NFORMATS (sizeof formats / sizeof formats[0])

static int setup(void **state)
{
    (void)state;
    if (!mkdtemp(scratch))
        return -1;
    if (!realpath(tu_conifit(), conifit_abs) || !realpath("fits/telescoping.json", fit_text_path))
        return -1;
    xmlInitParser();
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[PATH_MAX + 16];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", scratch);
    xmlCleanupParser();
    return system(cmd) == 0 ? 0 : -1;
}

/* Copies the shipped fit file into the scratch folder as name. */
static void place_fit(const char *name)
{
    char *text = tu_slurp(fit_text_path);
    assert_non_null(text);
    char p[PATH_MAX];
    snprintf(p, sizeof p, "%s/%s", scratch, name);
    FILE *f = fopen(p, "wb");
    if (!f)
        fail_msg("cannot create %s: %s", p, strerror(errno));
    fputs(text, f);
    assert_int_equal(fclose(f), 0);
    free(text);
}

/* Exports fit (a name in the scratch folder) as format, variant "" / "--example" / "--lattice",
** into scratch/out; the text, or fails. */
static char *export_text(const char *fit, const format *fm, const char *variant)
{
    char *argv[10];
    int a = 0;
    argv[a++] = conifit_abs;
    argv[a++] = "export";
    argv[a++] = (char *)fit;
    argv[a++] = "--format";
    argv[a++] = (char *)fm->name;
    if (*variant)
        argv[a++] = (char *)variant;
    argv[a++] = "-o";
    argv[a++] = "out";
    argv[a] = NULL;
    int rc = tu_exec(scratch, NULL, argv, "stderr.txt");
    char p[PATH_MAX];
    if (rc != 0) {
        snprintf(p, sizeof p, "%s/stderr.txt", scratch);
        char *e = tu_slurp(p);
        fail_msg("export %s %s: exit %d: %s", fm->name, variant, rc, e ? e : "");
    }
    snprintf(p, sizeof p, "%s/out", scratch);
    char *text = tu_slurp(p);
    assert_non_null(text);
    return text;
}

static size_t count_lines(const char *s)
{
    size_t n = 0;
    for (; *s; s++)
        n += *s == '\n';
    return n;
}

static void check_parses(const format *fm, const char *text, const char *what)
{
    if (fm->xml) {
        xmlDocPtr doc = xmlReadMemory(text, (int)strlen(text), "out.xml", NULL,
                                      XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING);
        if (!doc)
            fail_msg("%s: the %s export is not well-formed XML", what, fm->name);
        xmlFreeDoc(doc);
    } else if (strcmp(fm->name, "json") == 0) {
        json_error_t e;
        json_t *j = json_loads(text, 0, &e);
        if (!j)
            fail_msg("%s: the JSON export does not parse: %s", what, e.text);
        json_decref(j);
    }
}

static void control_double_hyphen_breaks_xml(void **state)
{
    (void)state;
    const char *bad = "<?xml version=\"1.0\"?>\n<!-- fit--v2.json -->\n<a/>\n";
    xmlDocPtr doc = xmlReadMemory(bad, (int)strlen(bad), "bad.xml", NULL,
                                  XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING);
    assert_null(doc);
}

static void hostile_fit_names_stay_in_their_comments(void **state)
{
    (void)state;
    place_fit("plain.json");
    const char *variants[] = {"", "--example", "--lattice"};
    for (size_t f = 0; f < NFORMATS; f++) {
        const format *fm = &formats[f];
        for (size_t v = 0; v < (fm->models ? 3u : 1u); v++) {
            char *ref = export_text("plain.json", fm, variants[v]);
            const size_t lines = count_lines(ref);
            check_parses(fm, ref, "plain.json");
            free(ref);
            for (size_t h = 0; h < NHOSTILE; h++) {
                place_fit(hostile[h]);
                char *text = export_text(hostile[h], fm, variants[v]);
                char what[300];
                snprintf(what, sizeof what, "%s %s, name %zu", fm->name, variants[v], h);
                if (count_lines(text) != lines)
                    fail_msg("%s: %zu lines, %zu with a plain name", what, count_lines(text),
                             lines);
                assert_null(strstr(text, "\n*INCLUDE"));
                assert_null(strstr(text, "\n*STEP\n.json"));
                assert_null(strchr(text, '\r'));
                check_parses(fm, text, what);
                free(text);
                char p[PATH_MAX];
                snprintf(p, sizeof p, "%s/%s", scratch, hostile[h]);
                unlink(p);
            }
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(control_double_hyphen_breaks_xml),
        cmocka_unit_test(hostile_fit_names_stay_in_their_comments),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
