/*
** What every command of the command line shares: --help, -o/--output, -q/--quiet, '-' for
** standard input and output where documented, usage errors (exit 2) that name the option, and
** library messages shown with the command line's flag names.
*/
#include "testutil.h"

#include <sys/stat.h>

#include <jansson.h>

#include "model/law_internal.h"

static char out[1 << 16], err[1 << 14];

static const char *const commands[] = {"force", "curve", "info", "fit", "export", "synth",
                                       "simulate", "predict"};
#define NCOMMANDS (sizeof commands / sizeof commands[0])
#define SPRING "--D1 8 --D2 20 --n 2.5 --d 1 --G 80000 --H 12"

/* Runs a shell pipeline (through sh -c), stdout into out; returns the exit status. */
static int sh(const char *fmt, ...)
{
    char cmd[4096], file[] = "/tmp/conifit-cli-XXXXXX";
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    int fd = mkstemp(file);
    assert_true(fd >= 0);
    close(fd);
    char full[4200];
    snprintf(full, sizeof full, "(%s) >%s 2>/dev/null", cmd, file);
    int st = system(full);
    FILE *f = fopen(file, "rb");
    size_t n = f ? fread(out, 1, sizeof out - 1, f) : 0;
    out[n] = '\0';
    if (f)
        fclose(f);
    remove(file);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static void every_command_has_help_with_output_and_quiet(void **state)
{
    (void)state;
    for (size_t i = 0; i < NCOMMANDS; i++) {
        assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "%s --help", commands[i]), 0);
        if (!strstr(out, "usage: conifit") || !strstr(out, "-o") || !strstr(out, "--quiet") ||
            !strstr(out, "--progress"))
            fail_msg("%s --help lacks usage, -o, --quiet or --progress:\n%s", commands[i], out);
        assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "%s -h", commands[i]), 0);
        /* an unknown option is a usage error that names it */
        assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "%s --no-such-option",
                                commands[i]),
                         2);
        if (!strstr(err, "'--no-such-option'"))
            fail_msg("%s: the usage error does not name the option: %s", commands[i], err);
    }
    /* the help of force states its unit without a stray number */
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "force --help"), 0);
    assert_null(strstr(out, "(0)"));
    assert_non_null(strstr(out, "in N"));
}

static void a_missing_value_names_its_option(void **state)
{
    (void)state;
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "curve " SPRING " --points"), 2);
    assert_non_null(strstr(err, "--points needs a value"));
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "fit data/telescoping.csv -o"), 2);
    assert_non_null(strstr(err, "-o needs a value"));
}

static void output_goes_to_a_file_or_to_standard_output(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-cli-o-XXXXXX", path[300];
    assert_non_null(mkdtemp(dir));
    /* curve: -o FILE, and the same bytes on standard output without it or with -o - */
    snprintf(path, sizeof path, "%s/c.csv", dir);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "curve " SPRING " --points 5 -o %s",
                            path),
                     0);
    assert_string_equal(out, "");
    char file[4096] = "";
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    file[fread(file, 1, sizeof file - 1, f)] = '\0';
    fclose(f);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "curve " SPRING " --points 5 -o -"),
                     0);
    assert_string_equal(out, file);
    remove(path);
    /* force and info with --output */
    snprintf(path, sizeof path, "%s/f.txt", dir);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "force " SPRING " --u 1 --output=%s",
                            path),
                     0);
    assert_string_equal(out, "");
    remove(path);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "info " SPRING " -o -"), 0);
    assert_non_null(strstr(out, "F_C (solid load)"));
    /* synth: standard output by default */
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "synth " SPRING " --points 6"), 0);
    assert_non_null(strstr(out, "strain,stress_kPa\n"));
    rmdir(dir);
}

/* A table on standard input, the fit file on standard output, read back by export from standard
** input: a pipeline without a file. */
static void fit_and_export_work_as_a_pipe(void **state)
{
    (void)state;
    assert_int_equal(sh("%s fit - -o - < data/telescoping.csv", tu_conifit()), 0);
    json_error_t je;
    json_t *root = json_loads(out, 0, &je);
    if (!root)
        fail_msg("fit -o - did not write JSON: %s\n%s", je.text, out);
    assert_string_equal(json_string_value(json_object_get(json_object_get(root, "data"), "file")),
                        "(standard input)");
    json_decref(root);
    assert_int_equal(sh("%s fit - -o - < data/telescoping.csv | %s export - --format csv -q",
                        tu_conifit(), tu_conifit()),
                     0);
    assert_non_null(strstr(out, "u_mm,force_N"));
    /* '-' must be the only table */
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "fit - data/telescoping.csv"), 2);
}

/* --quiet leaves the result and nothing else. */
static void quiet_means_the_result_only(void **state)
{
    (void)state;
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "fit data/telescoping.csv -q"), 0);
    assert_string_equal(out, "");
    char dir[] = "/tmp/conifit-cli-q-XXXXXX", path[300];
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/fit.json", dir);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err,
                            "fit data/telescoping.csv -o %s --quiet", path),
                     0);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "export %s --format csv -q", path),
                     0);
    assert_string_equal(err, "");
    assert_non_null(strstr(out, "u_mm,force_N"));
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "export %s --format csv", path), 0);
    assert_non_null(strstr(err, "rows, max error"));
    remove(path);
    rmdir(dir);
}

/* The reader says "option stress_unit"; the command line shows its flag. */
static void library_option_names_are_shown_as_flags(void **state)
{
    (void)state;
    char dir[] = "/tmp/conifit-cli-m-XXXXXX", path[300];
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/t.csv", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("strain,stress\n0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n", f);
    fclose(f);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "fit %s -q", path), 65);
    assert_non_null(strstr(err, "--stress-unit"));
    assert_null(strstr(err, "option stress_unit"));
    remove(path);
    /* a spreadsheet gets told what to do */
    snprintf(path, sizeof path, "%s/t.xlsx", dir);
    f = fopen(path, "wb");
    assert_non_null(f);
    fwrite("PK\003\004\024\000\006\000", 1, 8, f);
    fclose(f);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "fit %s", path), 65);
    assert_non_null(strstr(err, "save the sheet as CSV"));
    remove(path);
    rmdir(dir);
}

/* The tail's --n_tail and --H_tail reach force, curve, info and synth: the force in region 3 is the
** tail's straight line, the curve ends at the solid force, info prints the tail and its regions,
** synth's rows are the series law; a negative tail is a usage error naming it. */
#define TAIL_SPRING "--D1 10 --D2 30 --n 4 --d 1 --G 80000 --H 40 --n_tail 1 --H_tail 10"

static void the_tail_options_reach_force_curve_info_and_synth(void **state)
{
    (void)state;
    const cf_spring p = {10, 30, 4, 1, 80000, 40, 1, 10};
    cf_law law;
    cf_error e = {0};
    assert_int_equal(cf_law_init(&law, &p, &e), CF_OK);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "force " TAIL_SPRING " --u 37"), 0);
    const double F = strtod(out, NULL);
    assert_close(F, law.F_C_N + law.k_tail_N_per_mm * (37 - law.u_C_mm), 1e-14 * F);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err,
                            "curve " TAIL_SPRING " --points 5 --method exact"),
                     0);
    const char *last = strrchr(out, '\n');
    while (last > out && last[-1] != '\n')
        last--;
    double u, Fs, k;
    assert_int_equal(sscanf(last, "%lf,%lf,%lf", &u, &Fs, &k), 3);
    assert_true(u == law.travel_mm && Fs == law.F_solid_N && k == 0);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "info " TAIL_SPRING), 0);
    char line[128];
    snprintf(line, sizeof line, "%.10g N/mm", law.k_tail_N_per_mm);
    assert_non_null(strstr(out, line));
    assert_non_null(strstr(out, "3 linear, the tail alone"));
    snprintf(line, sizeof line, "F = %.10g N", law.F_solid_N);
    assert_non_null(strstr(out, line));
    /* synth: stress = F(strain H)/H^2 with the tail, to the solid strain's 0.95 */
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err,
                            "synth " TAIL_SPRING " --points 20 --stress-unit MPa"),
                     0);
    assert_non_null(strstr(out, "# tail: "));
    int rows = 0;
    for (const char *q = strchr(out, '\n'); q && q[1]; q = strchr(q + 1, '\n')) {
        double x, y;
        if (q[1] == '#' || sscanf(q + 1, "%lf,%lf", &x, &y) != 2)
            continue;
        const double want = cf_law_force(&law, CF_LAW_EXACT, x * p.H_mm, NULL, NULL) /
                            (p.H_mm * p.H_mm);
        assert_close(y, want, 1e-12 * fabs(want) + 1e-300);
        rows++;
    }
    assert_int_equal(rows, 20);
    /* the plain spring's info has no tail block */
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "info " SPRING), 0);
    assert_null(strstr(out, "tail"));
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err,
                            "force " SPRING " --n_tail -1 --H_tail 3 --u 1"),
                     2);
    assert_non_null(strstr(err, "n_tail"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(every_command_has_help_with_output_and_quiet),
        cmocka_unit_test(a_missing_value_names_its_option),
        cmocka_unit_test(output_goes_to_a_file_or_to_standard_output),
        cmocka_unit_test(fit_and_export_work_as_a_pipe),
        cmocka_unit_test(quiet_means_the_result_only),
        cmocka_unit_test(library_option_names_are_shown_as_flags),
        cmocka_unit_test(the_tail_options_reach_force_curve_info_and_synth),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
