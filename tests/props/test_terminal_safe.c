/*
** Nothing from outside reaches a terminal as a command: file names, column names and a scene's fit
** name holding escape sequences (ESC [ ... m, an OSC title ESC ] ... BEL, the C1 introducer U+009B)
** go through fit, simulate and export, as successes and as failures, and neither standard output
** nor standard error carries a control character other than a line break, nor a C1 control.
*/
#include "testutil.h"

#include <sys/stat.h>

TU_SCRATCH_GROUP("term")

/* The hostile pieces (no single quote: the runs pass names through sh in single quotes). */
#define ESC_NAME "t\x1b[31mred\x1b]0;title\x07"
#define C1_NAME "c\xc2\x9b" "2J"

static void write_file(const char *name, const char *text)
{
    char p[600];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    FILE *f = fopen(p, "wb");
    assert_non_null(f);
    fputs(text, f);
    assert_int_equal(fclose(f), 0);
}

/* Fails when text holds a control character other than a line break (or the carriage return and
** erase-line a progress line uses, "\r\x1b[K", which conifit writes itself), or a C1 control. */
static void assert_terminal_safe(const char *text, const char *what)
{
    const unsigned char *u = (const unsigned char *)text;
    for (size_t i = 0; u[i]; i++) {
        if (u[i] == '\r' && u[i + 1] == 0x1b && u[i + 2] == '[' && u[i + 3] == 'K') {
            i += 3;
            continue;
        }
        const int control = (u[i] < 0x20 && u[i] != '\n' && u[i] != '\r') || u[i] == 0x7f;
        const int c1 = u[i] == 0xc2 && u[i + 1] >= 0x80 && u[i + 1] <= 0x9f;
        if (control || c1)
            fail_msg("%s: byte 0x%02X at offset %zu: ...%.40s", what, u[i], i,
                     text + (i > 20 ? i - 20 : 0));
    }
}

static char out[1 << 17], err[1 << 15];

static void run_and_check(const char *what, const char *fmt, const char *a, const char *b)
{
    tu_run(out, sizeof out, err, sizeof err, fmt, a, b);
    assert_terminal_safe(out, what);
    assert_terminal_safe(err, what);
}

static void hostile_names_never_reach_the_terminal(void **state)
{
    (void)state;
    char *table = tu_slurp("data/telescoping.csv");
    assert_non_null(table);
    char *body = strstr(table, "\nstrain,stress_kPa\n");
    assert_non_null(body);
    char text[1 << 16];
    /* a good table with a hostile file name, and one with hostile column names */
    write_file(ESC_NAME ".csv", table);
    snprintf(text, sizeof text, "strain " C1_NAME ",stress " ESC_NAME " [kPa]\n%s",
             body + strlen("\nstrain,stress_kPa\n"));
    write_file("cols.csv", text);
    free(table);
    char path[700], other[700];
    snprintf(path, sizeof path, "%s/" ESC_NAME ".csv", dir);
    run_and_check("fit (name)", "fit '%s' -o '%s/a.json' --progress", path, dir);
    run_and_check("fit (name, two tables)", "fit '%s' '%s' --progress -j 2", path, path);
    snprintf(other, sizeof other, "%s/cols.csv", dir);
    run_and_check("fit (columns)", "fit '%s' --progress%s", other, "");
    snprintf(other, sizeof other, "%s/" C1_NAME ".csv", dir); /* missing: an error message */
    run_and_check("fit (missing)", "fit '%s'%s", other, "");
    run_and_check("unknown option", "fit --'%s' x%s", ESC_NAME, "");

    /* a fit file with a hostile name: export (its summary and a CSV on standard output) and a
    ** scene naming it (simulate's summary) */
    char *fit = tu_slurp("fits/telescoping.json");
    assert_non_null(fit);
    write_file(ESC_NAME ".json", fit);
    free(fit);
    snprintf(path, sizeof path, "%s/" ESC_NAME ".json", dir);
    run_and_check("export", "export '%s' --format csv%s", path, "");
    snprintf(text, sizeof text,
             "{\"spring\": {\"fit\": \"%s/t\\u001b[31mred\\u001b]0;title\\u0007.json\"},\n"
             " \"lattice\": {\"nx\": 2, \"ny\": 2, \"nz\": 2},\n"
             " \"protocol\": {\"kind\": \"ramp\", \"to_strain\": 0.2, \"duration_s\": 1},\n"
             " \"samples_per_segment\": 4}\n",
             dir);
    write_file("scene.json", text);
    snprintf(path, sizeof path, "%s/scene.json", dir);
    snprintf(other, sizeof other, "%s/sim.csv", dir);
    assert_int_equal(tu_run(out, sizeof out, err, sizeof err, "simulate '%s' -o '%s'", path,
                            other),
                     0);
    assert_terminal_safe(out, "simulate");
    assert_terminal_safe(err, "simulate");
    char *csv = tu_slurp(other);
    assert_non_null(csv);
    assert_terminal_safe(csv, "simulate's CSV");
    free(csv);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(hostile_names_never_reach_the_terminal),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
