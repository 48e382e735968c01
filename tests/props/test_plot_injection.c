/*
** Input is data, never code: text from a table (column names, units, comments), from file names,
** scene strings and output names reaches gnuplot only as escaped string literals. Each payload below
** runs `touch PWNED...` when pasted into a gnuplot script the naive way (the control test proves
** it); through every command that plots (fit, simulate, predict), none of them may run. The runs
** happen in a scratch folder so that the markers are plain names there.
*/
#include <fcntl.h>
#include <limits.h>
#include <sys/stat.h>

#include "testutil.h"

#include "report/gnuplot.h"

static char scratch[] = "/tmp/conifit-inject-XXXXXX";
static char conifit_abs[PATH_MAX], table_abs[PATH_MAX], series_abs[PATH_MAX];

/* The payloads: each breaks out of a gnuplot string its own way and creates the marker. */
typedef struct payload {
    const char *name;
    const char *text; /* %s: the marker's name */
} payload;

static const payload payloads[] = {
    {"single quote", "'.system('touch %s').'"},
    {"double quote", "\".system(\"touch %s\").\""},
    {"backtick", "`touch %s`"},
    {"newline", "x'\n!touch %s\n#"},
};
#define NPAYLOADS (sizeof payloads / sizeof payloads[0])

static void make_payload(char *out, size_t cap, size_t k, const char *marker)
{
    snprintf(out, cap, payloads[k].text, marker);
}

static int exists_in_scratch(const char *name)
{
    char p[PATH_MAX];
    struct stat s;
    snprintf(p, sizeof p, "%s/%s", scratch, name);
    return lstat(p, &s) == 0;
}

static void write_in_scratch(const char *name, const char *text)
{
    char p[PATH_MAX];
    snprintf(p, sizeof p, "%s/%s", scratch, name);
    FILE *f = fopen(p, "wb");
    assert_non_null(f);
    fputs(text, f);
    assert_int_equal(fclose(f), 0);
}

/* Runs argv (argv[0] a full path, no shell) in the scratch folder with env_extra ("NAME=VALUE" or
** NULL) added to the environment; stderr goes to scratch/stderr.txt. Returns the exit status. */
static int run(const char *env_extra, char *const argv[])
{
    return tu_exec(scratch, env_extra, argv, "stderr.txt");
}

static const char *last_stderr(void)
{
    static char buf[4096];
    char p[PATH_MAX];
    snprintf(p, sizeof p, "%s/stderr.txt", scratch);
    FILE *f = fopen(p, "rb");
    size_t n = f ? fread(buf, 1, sizeof buf - 1, f) : 0;
    buf[n] = '\0';
    if (f)
        fclose(f);
    return buf;
}

/* The shipped table with its header line replaced. */
/* The whole of a shipped file (at most 64 KiB) in a static buffer. */
static char *shipped_text(const char *path)
{
    static char text[1 << 16];
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = '\0';
    return text;
}

static void table_with_header(const char *name, const char *header, const char *comment)
{
    static char out[1 << 16];
    char *text = shipped_text(table_abs);
    char *h = strstr(text, "\nstrain,stress_kPa\n");
    assert_non_null(h);
    snprintf(out, sizeof out, "%s%.*s\n%s\n%s", comment ? comment : "", (int)(h - text), text,
             header, h + strlen("\nstrain,stress_kPa\n"));
    write_in_scratch(name, out);
}

static int have_gnuplot(void)
{
    return system("command -v gnuplot >/dev/null 2>&1") == 0;
}

static int setup(void **state)
{
    (void)state;
    if (!mkdtemp(scratch))
        return -1;
    if (!realpath(tu_conifit(), conifit_abs) || !realpath("data/telescoping.csv", table_abs) ||
        !realpath("data/series/synthetic_relaxation.csv", series_abs))
        return -1;
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[PATH_MAX + 16];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", scratch);
    return system(cmd) == 0 ? 0 : -1;
}

/* Control: pasted into a script without the escaping rule, each payload does run. Without this,
** the tests below could pass because the payloads were inert. */
static void control_payloads_run_when_pasted_raw(void **state)
{
    (void)state;
    if (!have_gnuplot())
        skip();
    static const char *const wrap[NPAYLOADS] = {
        "set ylabel '%s'\n", "set title \"%s\"\n", "set title \"x%s\"\n", "set title '%s'\n"};
    for (size_t k = 0; k < NPAYLOADS; k++) {
        char marker[32], p[256], script[512];
        snprintf(marker, sizeof marker, "CONTROL%zu", k);
        make_payload(p, sizeof p, k, marker);
        snprintf(script, sizeof script, wrap[k], p);
        write_in_scratch("control.gp", script);
        char *argv[] = {"/bin/sh", "-c", "gnuplot control.gp", NULL};
        run(NULL, argv);
        if (!exists_in_scratch(marker))
            fail_msg("payload '%s' did not run when pasted raw: the test would prove nothing",
                     payloads[k].name);
    }
}

/* The rule itself: %q writes only plain bytes and octal escapes; %s, a newline in the format,
** a non-finite number and a bad data block name invalidate the script. */
static void escaping_rule(void **state)
{
    (void)state;
    cf_gp g;
    cf_gp_init(&g);
    cf_gp_cmd(&g, "set title %q", "a'b\"c`d@e\\f\ng\xc2\xb5");
    assert_int_equal(g.st, CF_OK);
    assert_string_equal(g.buf, "set title \"a\\047b\\042c\\140d\\100e\\134f\\012g\\302\\265\"\n");
    cf_gp_free(&g);

    const char *bad_formats[] = {"set title %s", "set title 'x'\nsystem('y')", "%n", "%p"};
    for (size_t i = 0; i < sizeof bad_formats / sizeof bad_formats[0]; i++) {
        cf_gp_init(&g);
        cf_gp_cmd(&g, bad_formats[i], "x");
        assert_int_equal(g.st, CF_E_INTERNAL);
        cf_gp_free(&g);
    }
    cf_gp_init(&g);
    cf_gp_cmd(&g, "set xrange [%g:%.3f]", 0.5, NAN);
    assert_int_equal(g.st, CF_E_INTERNAL);
    cf_gp_free(&g);
    cf_gp_init(&g);
    cf_gp_block_begin(&g, "D;system");
    assert_int_equal(g.st, CF_E_INTERNAL);
    cf_gp_free(&g);
    cf_gp_init(&g);
    double row[2] = {1, INFINITY};
    cf_gp_block_begin(&g, "D");
    cf_gp_block_row(&g, 2, row);
    assert_int_equal(g.st, CF_E_INTERNAL);
    cf_gp_free(&g);
    /* an invalid script never starts gnuplot and leaves no file */
    cf_gp_init(&g);
    cf_gp_cmd(&g, "%s", "x");
    cf_atomic a;
    cf_error err = {0};
    char path[PATH_MAX];
    snprintf(path, sizeof path, "%s/never.png", scratch);
    assert_int_equal(cf_gp_render(&g, path, NULL, &a, &err), CF_E_INTERNAL);
    assert_false(exists_in_scratch("never.png"));
    cf_gp_free(&g);
}

static void no_marker_left(const char *what)
{
    for (size_t k = 0; k < 16; k++) {
        char m[32];
        snprintf(m, sizeof m, "PWNED%zu", k);
        if (exists_in_scratch(m))
            fail_msg("%s: a payload ran (%s exists)", what, m);
    }
}

/* conifit fit --plot with payloads in the column names (single and double quotes, backticks),
** in a '#' comment that states the unit, and in an option's unit. */
static void fit_column_names_comments_units(void **state)
{
    (void)state;
    if (!have_gnuplot())
        skip();
    for (size_t k = 0; k < 3; k++) {
        char marker[32], p[256], header[1024];
        snprintf(marker, sizeof marker, "PWNED%zu", k);
        make_payload(p, sizeof p, k, marker);
        if (k == 1) /* a double quote needs a quoted CSV field, with quotes doubled */
            snprintf(header, sizeof header,
                     "\"strain x\"\".system(\"\"touch %s\"\").\"\"\",\"stress x\"\".system("
                     "\"\"touch %s\"\").\"\" [kPa]\"",
                     marker, marker);
        else
            snprintf(header, sizeof header, "strain %s,stress %s [kPa]", p, p);
        table_with_header("cols.csv", header, NULL);
        char *argv[] = {conifit_abs, "fit", "cols.csv", "-o", "cols.json", "--plot", "cols.png",
                        "--quiet", NULL};
        int rc = run(NULL, argv);
        if (rc != 0)
            fail_msg("%s in column names: exit %d: %s", payloads[k].name, rc, last_stderr());
        assert_true(exists_in_scratch("cols.png"));
        no_marker_left(payloads[k].name);
    }
    /* a comment giving the unit, with a payload in the same clause */
    table_with_header("comment.csv", "strain,stress",
                      "# stress [kPa] '.system('touch PWNED5').' `touch PWNED6`\n");
    char *argv[] = {conifit_abs, "fit", "comment.csv", "--plot", "comment.png", "--quiet", NULL};
    int rc = run(NULL, argv);
    if (rc != 0)
        fail_msg("comment: exit %d: %s", rc, last_stderr());
    assert_true(exists_in_scratch("comment.png"));
    /* a unit option is checked against the known units before anything is drawn */
    char *argv2[] = {conifit_abs,   "fit",     "comment.csv", "--stress-unit",
                     "kPa'.system('touch PWNED7').'",   "--plot", "unit.png", "--quiet", NULL};
    assert_int_equal(run(NULL, argv2), 65);
    assert_false(exists_in_scratch("unit.png"));
    no_marker_left("comment or unit");
}

/* gnuplot reads no initialisation file: a ~/.gnuplot that runs a command (as a hostile or merely
** unusual one could) is live when gnuplot starts the ordinary way (the control), and conifit's
** plots run without it (gnuplot -d). */
static void gnuplot_init_file_is_not_read(void **state)
{
    (void)state;
    if (!have_gnuplot())
        skip();
    write_in_scratch(".gnuplot", "system('touch PWNED8')\n");
    char cmd[PATH_MAX + 96], home[PATH_MAX + 8];
    snprintf(cmd, sizeof cmd, "cd '%s' && HOME='%s' gnuplot </dev/null >/dev/null 2>&1", scratch,
             scratch);
    assert_int_equal(system(cmd), 0);
    assert_true(exists_in_scratch("PWNED8")); /* the control: the file is read by default */
    snprintf(cmd, sizeof cmd, "%s/PWNED8", scratch);
    assert_int_equal(unlink(cmd), 0);
    table_with_header("init.csv", "strain,stress_kPa", NULL);
    snprintf(home, sizeof home, "HOME=%s", scratch);
    char *argv[] = {conifit_abs, "fit", "init.csv", "--plot", "init.png", "--quiet", NULL};
    int rc = run(home, argv);
    if (rc != 0)
        fail_msg("fit with a ~/.gnuplot: exit %d: %s", rc, last_stderr());
    const int ran = exists_in_scratch("PWNED8");
    snprintf(cmd, sizeof cmd, "%s/.gnuplot", scratch);
    unlink(cmd);
    snprintf(cmd, sizeof cmd, "%s/PWNED8", scratch);
    unlink(cmd); /* so that a failure here does not show in the tests after it */
    assert_true(exists_in_scratch("init.png"));
    assert_false(ran);
}

/* conifit fit with payloads in the table's file name and in the plot's own name. */
static void fit_file_names(void **state)
{
    (void)state;
    if (!have_gnuplot())
        skip();
    for (size_t k = 0; k < NPAYLOADS; k++) {
        char marker[32], p[256], name[300], png[300];
        snprintf(marker, sizeof marker, "PWNED%zu", k);
        make_payload(p, sizeof p, k, marker);
        snprintf(name, sizeof name, "t%s.csv", p);
        snprintf(png, sizeof png, "o%s.png", p);
        table_with_header(name, "strain,stress_kPa", NULL);
        char *argv[] = {conifit_abs, "fit", name, "--plot", png, "--quiet", NULL};
        int rc = run(NULL, argv);
        if (rc != 0)
            fail_msg("%s in file names: exit %d: %s", payloads[k].name, rc, last_stderr());
        assert_true(exists_in_scratch(png));
        no_marker_left(payloads[k].name);
    }
}

/* conifit predict --plot with payloads in the table's file name (a panel's title) and in the
** plot's and the CSV's own names. */
static void predict_file_names(void **state)
{
    (void)state;
    if (!have_gnuplot())
        skip();
    char fit[PATH_MAX];
    assert_non_null(realpath("fits/telescoping.json", fit));
    for (size_t k = 0; k < NPAYLOADS; k++) {
        char marker[32], p[256], name[300], png[300], csv[300];
        snprintf(marker, sizeof marker, "PWNED%zu", k);
        make_payload(p, sizeof p, k, marker);
        snprintf(name, sizeof name, "p%s.csv", p);
        snprintf(png, sizeof png, "q%s.png", p);
        snprintf(csv, sizeof csv, "r%s.csv", p);
        table_with_header(name, "strain,stress_kPa", NULL);
        char *argv[] = {conifit_abs, "predict", fit, name, "-o", csv, "--plot", png, "--quiet",
                        NULL};
        int rc = run(NULL, argv);
        if (rc != 0)
            fail_msg("%s in predict's file names: exit %d: %s", payloads[k].name, rc,
                     last_stderr());
        assert_true(exists_in_scratch(png));
        assert_true(exists_in_scratch(csv));
        no_marker_left(payloads[k].name);
    }
}

/* conifit fit --plot of a time series (its own figure: stress against time and strain) with
** payloads in the file name (the default title), the column names (axis labels) and --title. */
static void fit_series_names(void **state)
{
    (void)state;
    if (!have_gnuplot())
        skip();
    static char out[1 << 16];
    const char *text = shipped_text(series_abs);
    const char *hdr = "time_s,strain,stress_kPa\n";
    char *h = strstr(text, hdr);
    assert_non_null(h);
    for (size_t k = 0; k < NPAYLOADS; k++) {
        if (k == 1 || k == 3) /* a double quote or newline cannot stand unquoted in a CSV name */
            continue;
        char marker[32], p[256], name[300], png[300];
        snprintf(marker, sizeof marker, "PWNED%zu", k);
        make_payload(p, sizeof p, k, marker);
        snprintf(name, sizeof name, "s%s.csv", p);
        snprintf(png, sizeof png, "s%zu.png", k);
        snprintf(out, sizeof out, "%.*stime_s,strain %s,stress %s [kPa]\n%s", (int)(h - text),
                 text, p, p, h + strlen(hdr));
        write_in_scratch(name, out);
        char *argv[] = {conifit_abs, "fit",   name, "--branches", "1", "--relaxation", "qlv",
                        "--plot",    png,     "--quiet", NULL};
        int rc = run(NULL, argv);
        if (rc != 0)
            fail_msg("%s in a series' names: exit %d: %s", payloads[k].name, rc, last_stderr());
        assert_true(exists_in_scratch(png));
        char *argv2[] = {conifit_abs, "fit",   name, "--branches", "1", "--relaxation", "qlv",
                         "--title",   p,       "--plot", png,      "--quiet", NULL};
        rc = run(NULL, argv2);
        if (rc != 0)
            fail_msg("%s in a series' title: exit %d: %s", payloads[k].name, rc, last_stderr());
        no_marker_left(payloads[k].name);
    }
}

/* conifit simulate --plot with payloads in the output names, the scene's file name and the fit
** file the scene names (shown in the figure's key). */
static void simulate_names(void **state)
{
    (void)state;
    if (!have_gnuplot())
        skip();
    /* a fit file to name from the scenes */
    table_with_header("base.csv", "strain,stress_kPa", NULL);
    char *fit[] = {conifit_abs, "fit", "base.csv", "--type", "telescoping", "-o", "base.json",
                   "--quiet", NULL};
    assert_int_equal(run(NULL, fit), 0);
    for (size_t k = 0; k < NPAYLOADS; k++) {
        char marker[32], p[256], fitname[300], scene[300], csv[300], png[300], cmd[1200];
        snprintf(marker, sizeof marker, "PWNED%zu", k);
        make_payload(p, sizeof p, k, marker);
        snprintf(fitname, sizeof fitname, "f%s.json", p);
        snprintf(scene, sizeof scene, "s%s.json", p);
        snprintf(csv, sizeof csv, "o%s.csv", p);
        snprintf(png, sizeof png, "o%s.png", p);
        char fitpath[PATH_MAX], basepath[PATH_MAX];
        snprintf(fitpath, sizeof fitpath, "%s/%s", scratch, fitname);
        snprintf(basepath, sizeof basepath, "%s/base.json", scratch);
        assert_int_equal(link(basepath, fitpath), 0);
        /* the fit file's name as a JSON string: escape quotes, backslashes and newlines */
        char js[700];
        size_t o = 0;
        for (const char *c = fitpath; *c && o + 3 < sizeof js; c++) {
            if (*c == '"' || *c == '\\')
                js[o++] = '\\', js[o++] = *c;
            else if (*c == '\n')
                js[o++] = '\\', js[o++] = 'n';
            else
                js[o++] = *c;
        }
        js[o] = '\0';
        snprintf(cmd, sizeof cmd,
                 "{\"spring\": {\"fit\": \"%s\", \"type\": \"telescoping\"},\n"
                 " \"lattice\": {\"nx\": 1, \"ny\": 1, \"nz\": 1},\n"
                 " \"protocol\": {\"kind\": \"ramp\", \"to_strain\": 0.3},\n"
                 " \"samples_per_segment\": 5}\n",
                 js);
        write_in_scratch(scene, cmd);
        char *argv[] = {conifit_abs, "simulate", scene, "-o", csv, "--plot", png, NULL};
        int rc = run(NULL, argv);
        if (rc != 0)
            fail_msg("%s in simulate names: exit %d: %s", payloads[k].name, rc, last_stderr());
        assert_true(exists_in_scratch(csv));
        assert_true(exists_in_scratch(png));
        no_marker_left(payloads[k].name);
    }
}

/* What gnuplot receives: captured by a stand-in gnuplot that keeps its script, then draws with
** the real one. The script holds none of the bytes that could end a string or start a
** substitution, however the names were made. */
static void script_holds_no_live_text(void **state)
{
    (void)state;
    if (!have_gnuplot())
        skip();
    write_in_scratch("gp.sh", "#!/bin/sh\ntee captured.gp | gnuplot\n");
    char gp[PATH_MAX];
    snprintf(gp, sizeof gp, "%s/gp.sh", scratch);
    assert_int_equal(chmod(gp, 0755), 0);
    char env[PATH_MAX + 32];
    snprintf(env, sizeof env, "CONIFIT_GNUPLOT=%s", gp);
    table_with_header("t'`@\".csv", "strain '`@,stress ' `@ [kPa]", NULL);
    char *argv[] = {conifit_abs, "fit",       "t'`@\".csv", "--validate", "--plot",
                    "o'`@\".svg", "--quiet", NULL};
    int rc = run(env, argv);
    if (rc != 0)
        fail_msg("exit %d: %s", rc, last_stderr());
    char p[PATH_MAX];
    snprintf(p, sizeof p, "%s/captured.gp", scratch);
    FILE *f = fopen(p, "rb");
    assert_non_null(f);
    static char script[1 << 20];
    size_t n = fread(script, 1, sizeof script - 1, f);
    fclose(f);
    script[n] = '\0';
    assert_true(n > 1000);
    assert_null(strchr(script, '\''));
    assert_null(strchr(script, '`'));
    assert_null(strchr(script, '@'));
    assert_null(strstr(script, "set output"));
    /* the names did arrive, escaped */
    assert_non_null(strstr(script, "t\\047\\140\\100\\042")); /* the title: the table's name */
    /* the axes name the fitted measure, with the unit read from the column */
    assert_non_null(strstr(script, "nominal stress [kPa]"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(control_payloads_run_when_pasted_raw),
        cmocka_unit_test(escaping_rule),
        cmocka_unit_test(fit_column_names_comments_units),
        cmocka_unit_test(fit_file_names),
        cmocka_unit_test(gnuplot_init_file_is_not_read),
        cmocka_unit_test(fit_series_names),
        cmocka_unit_test(predict_file_names),
        cmocka_unit_test(simulate_names),
        cmocka_unit_test(script_holds_no_live_text),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
