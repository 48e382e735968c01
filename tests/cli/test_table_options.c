/*
** Tests of the table options of `conifit fit` through the program: --columns picks the x, y (and
** weight) columns so that a time column of a single ramp is ignored, --header-row names the
** header of an export with a preamble; a malformed value is a usage error (2), a column or line
** the table does not have is bad data (65), each message naming what it refused; the reader's
** notes (strain that looks like stretch, units from a units row) are warnings on stderr and are
** kept in the text report and the fit file.
*/
#include "testutil.h"

TU_SCRATCH_GROUP("tableopt")
static char errb[1 << 14];

/* Writes the table text as DIR/NAME into path (cap bytes). */
static void put_table(char *path, size_t cap, const char *name, const char *text, size_t len)
{
    snprintf(path, cap, "%s/%s", dir, name);
    assert_int_equal(tu_write_bytes(path, text, len), 0);
}

/* A single ramp with a time column: as a time series it cannot be fitted. */
static const char ramp[] = "time_s,strain,stress_kPa\n0,0,0\n1,0.1,1\n2,0.2,2\n3,0.3,3\n"
                           "4,0.4,5\n5,0.5,8\n6,0.6,12\n";

/* The same ramp after an Instron-like preamble, with a header of names conifit does not know
** (Ext, Ld). */
static const char preamble[] = "\"Sample ID:\",\"SPEC-3\"\n\"Rate (mm/min)\",5\n\n"
                               "Time,Ext,Ld (kPa)\n0,0,0\n1,0.1,1\n2,0.2,2\n3,0.3,3\n"
                               "4,0.4,5\n5,0.5,8\n6,0.6,12\n";

static void columns_option_ignores_a_time_column(void **state)
{
    (void)state;
    char table[512], fit[512];
    put_table(table, sizeof table, "ramp.csv", ramp, sizeof ramp - 1);
    snprintf(fit, sizeof fit, "%s/ramp.json", dir);
    /* today's reading: a time series with a single ramp, refused */
    assert_int_equal(tu_run(NULL, 0, errb, sizeof errb, "fit %s -q", table), 65);
    /* by name, by number, and a name with a number */
    const char *picks[] = {"strain,stress_kPa", "2,3", "strain,3"};
    for (size_t k = 0; k < 3; k++) {
        remove(fit);
        int rc = tu_run(NULL, 0, errb, sizeof errb, "fit %s --columns %s -q -o %s", table,
                        picks[k], fit);
        if (rc != 0)
            fail_msg("--columns %s: exit %d: %s", picks[k], rc, errb);
        char *json = tu_slurp(fit);
        assert_non_null(json);
        assert_non_null(strstr(json, "\"x_column\": \"strain\""));
        assert_non_null(strstr(json, "\"kind\": \"stress-strain\""));
        free(json);
    }
    /* usage errors: exit 2 naming the value */
    const char *bad[] = {"strain", "strain,", ",stress_kPa", "1,2,3,4"};
    for (size_t k = 0; k < 4; k++) {
        assert_int_equal(tu_run(NULL, 0, errb, sizeof errb, "fit %s --columns '%s'", table,
                                bad[k]), 2);
        assert_non_null(strstr(errb, "--columns"));
    }
    assert_int_equal(tu_run(NULL, 0, errb, sizeof errb, "fit %s --columns 2,3 --x-col strain",
                            table), 2);
    /* a column the table does not have, or the same one twice: 65 naming file and line */
    assert_int_equal(tu_run(NULL, 0, errb, sizeof errb, "fit %s --columns strain,force", table),
                     65);
    assert_non_null(strstr(errb, "ramp.csv:1:1:"));
    assert_non_null(strstr(errb, "'force'"));
    assert_int_equal(tu_run(NULL, 0, errb, sizeof errb, "fit %s --columns 2,strain", table), 65);
    assert_non_null(strstr(errb, "one column"));
    assert_int_equal(tu_run(NULL, 0, errb, sizeof errb, "fit %s --columns 2,9", table), 65);
    assert_non_null(strstr(errb, "'9'"));
}

static void header_row_option_reads_an_export_with_a_preamble(void **state)
{
    (void)state;
    char table[512];
    put_table(table, sizeof table, "instron.csv", preamble, sizeof preamble - 1);
    /* the header names no known column: the message names its line (4), not line 1 */
    assert_int_equal(tu_run(NULL, 0, errb, sizeof errb, "fit %s -q", table), 65);
    assert_non_null(strstr(errb, "instron.csv:4:1:"));
    assert_non_null(strstr(errb, "--header-row"));
    /* with the header's line and the columns named, it is read */
    int rc = tu_run(NULL, 0, errb, sizeof errb, "fit %s --header-row 4 --columns Ext,3 -q",
                    table);
    if (rc != 0)
        fail_msg("exit %d: %s", rc, errb);
    assert_int_equal(tu_run(NULL, 0, errb, sizeof errb, "fit %s --header-row 0", table), 2);
    assert_int_equal(tu_run(NULL, 0, errb, sizeof errb, "fit %s --header-row x", table), 2);
    assert_int_equal(tu_run(NULL, 0, errb, sizeof errb, "fit %s --header-row 3 -q", table), 65);
    assert_non_null(strstr(errb, "instron.csv:3:1:"));
    assert_non_null(strstr(errb, "blank"));
}

/* Notes of the reader reach stderr as warnings; the fit goes on. */
static void table_notes_are_warnings(void **state)
{
    (void)state;
    static const char looks[] = "strain,stress_Mpa\n1,0\n1.1,1\n1.2,2\n1.3,3\n1.4,5\n1.5,8\n";
    char table[512];
    put_table(table, sizeof table, "looks.csv", looks, sizeof looks - 1);
    assert_int_equal(tu_run(NULL, 0, errb, sizeof errb, "fit %s -q", table), 0);
    assert_non_null(strstr(errb, "conifit: warning: "));
    assert_non_null(strstr(errb, "looks.csv: column 'strain' holds strain 1"));
    assert_non_null(strstr(errb, "--strain-measure stretch"));
    assert_non_null(strstr(errb, "unit 'Mpa' read as MPa"));
}

/* Writes the shipped table data/NAME.csv as DIR/OUT with its header row "Strain,Stress" and a
** units row "[mm/mm],[kPa]" under it (comments kept), into path (cap bytes). */
static void with_units_row(char *path, size_t cap, const char *name, const char *out)
{
    char src[256];
    snprintf(src, sizeof src, "data/%s.csv", name);
    char *text = tu_slurp(src);
    assert_non_null(text);
    char *header = strstr(text, "\nstrain,stress_kPa\n");
    assert_non_null(header);
    size_t cap2 = strlen(text) + 64, o = 0;
    char *t = malloc(cap2);
    assert_non_null(t);
    o += (size_t)snprintf(t, cap2, "%.*s\nStrain,Stress\n[mm/mm],[kPa]\n",
                          (int)(header - text), text);
    o += (size_t)snprintf(t + o, cap2 - o, "%s", header + strlen("\nstrain,stress_kPa\n"));
    put_table(path, cap, out, t, o);
    free(t);
    free(text);
}

/* JSON text holds "notes" with the units-row note of column NAME. */
static void assert_units_note(const char *text, const char *name)
{
    char want[128];
    snprintf(want, sizeof want, "column '%s': unit '", name);
    const char *notes = strstr(text, "\"notes\": [");
    if (!notes || !strstr(notes, want) || !strstr(notes, "read from the units row"))
        fail_msg("no note on column '%s' in notes[]:\n%s", name, text);
}

/* The notes reach the text report's header block and the fit file (notes[]) of a spring fit, a
** series fit and a joint fit, besides standard error; and a fit file with or without notes[] is
** read back (an export of it). */
static void table_notes_are_kept_in_report_and_fit_file(void **state)
{
    (void)state;
    static char out[1 << 16];
    char table[512], table2[512], fit[512], feb[512];
    /* a spring fit */
    with_units_row(table, sizeof table, "telescoping", "tele.csv");
    snprintf(fit, sizeof fit, "%s/tele.json", dir);
    int rc = tu_run(out, sizeof out, errb, sizeof errb, "fit %s -o %s", table, fit);
    if (rc != 0)
        fail_msg("exit %d: %s", rc, errb);
    const char *block = strstr(out, " measures: ");
    assert_non_null(block);
    const char *end = strstr(block, "\n\n"); /* the header block ends at its blank line */
    const char *note = strstr(block, " note: column 'Stress': unit 'kPa' read from the units "
                                     "row under the header (line 12)");
    if (!end || !note || note > end)
        fail_msg("no note in the report's header block:\n%.600s", out);
    assert_non_null(strstr(errb, "warning: ")); /* still on standard error */
    assert_non_null(strstr(errb, "tele.csv: column 'Stress': unit 'kPa' read from the units"));
    char *json = tu_slurp(fit);
    assert_non_null(json);
    const char *data = strstr(json, "\"data\": {");
    assert_non_null(data);
    assert_units_note(data, "Strain");
    assert_units_note(data, "Stress");
    assert_null(strstr(json, "\"\"")); /* no empty string, in notes or anywhere */
    free(json);
    snprintf(feb, sizeof feb, "%s/tele.feb", dir);
    assert_int_equal(tu_run(NULL, 0, errb, sizeof errb, "export %s --format febio -o %s", fit,
                            feb), 0);
    /* a table without notes: no key, and its fit file is read back as well */
    rc = tu_run(NULL, 0, errb, sizeof errb, "fit data/telescoping.csv -q -o %s", fit);
    assert_int_equal(rc, 0);
    json = tu_slurp(fit);
    assert_non_null(json);
    assert_null(strstr(json, "\"notes\""));
    free(json);
    assert_int_equal(tu_run(NULL, 0, errb, sizeof errb, "export %s --format febio -o %s", fit,
                            feb), 0);
    /* a series fit (every fourth row of the shipped relaxation, one Prony term: quick) */
    char *series = tu_slurp("data/series/synthetic_relaxation.csv");
    assert_non_null(series);
    char *rows = strstr(series, "\ntime_s,strain,stress_kPa\n");
    assert_non_null(rows);
    rows += strlen("\ntime_s,strain,stress_kPa\n");
    static char thin[1 << 14];
    size_t o = (size_t)snprintf(thin, sizeof thin, "Time,Strain,Stress\n(s),(-),(kPa)\n");
    for (size_t k = 0; *rows; k++) {
        char *nl = strchr(rows, '\n');
        size_t n = nl ? (size_t)(nl - rows + 1) : strlen(rows);
        if (k % 4 == 0 && o + n < sizeof thin)
            o += (size_t)snprintf(thin + o, sizeof thin - o, "%.*s", (int)n, rows);
        rows += n;
    }
    free(series);
    put_table(table, sizeof table, "series.csv", thin, o);
    snprintf(fit, sizeof fit, "%s/series.json", dir);
    rc = tu_run(out, sizeof out, errb, sizeof errb, "fit %s --branches 1 -o %s", table, fit);
    if (rc != 0)
        fail_msg("series: exit %d: %s", rc, errb);
    const char *first = strstr(out, "time series of");
    note = strstr(out, " note: column 'Time': unit 's' read from the units row");
    const char *fitline = strstr(out, " viscoelastic fit:");
    if (!first || !note || !fitline || note > fitline)
        fail_msg("no note in the series report's header block:\n%.600s", out);
    json = tu_slurp(fit);
    assert_non_null(json);
    assert_units_note(strstr(json, "\"data\": {"), "Stress");
    free(json);
    assert_int_equal(tu_run(NULL, 0, errb, sizeof errb, "export %s --format febio -o %s", fit,
                            feb), 0);
    /* a joint fit: the notes under the first line, and in each entry of tables[] */
    with_units_row(table, sizeof table, "telescoping", "tension.csv");
    with_units_row(table2, sizeof table2, "telescoping_compression", "compression.csv");
    snprintf(fit, sizeof fit, "%s/joint.json", dir);
    rc = tu_run(out, sizeof out, errb, sizeof errb, "fit --joint %s %s -o %s", table, table2,
                fit);
    if (rc != 0)
        fail_msg("joint: exit %d: %s", rc, errb);
    const char *t2 = strstr(out, "compression.csv:\n  note: column 'Strain': unit 'mm/mm'");
    const char *spring = strstr(out, " spring: ");
    if (!t2 || !spring || t2 > spring)
        fail_msg("no notes before the joint report's springs:\n%.900s", out);
    json = tu_slurp(fit);
    assert_non_null(json);
    const char *tabs = strstr(json, "\n  \"tables\": [");
    assert_non_null(tabs);
    assert_units_note(tabs, "Stress");
    assert_non_null(strstr(strstr(tabs, "compression.csv"), "\"notes\": ["));
    free(json);
    assert_int_equal(tu_run(NULL, 0, errb, sizeof errb, "export %s --format febio -o %s", fit,
                            feb), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(columns_option_ignores_a_time_column),
        cmocka_unit_test(header_row_option_reads_an_export_with_a_preamble),
        cmocka_unit_test(table_notes_are_warnings),
        cmocka_unit_test(table_notes_are_kept_in_report_and_fit_file),
    };
    return cmocka_run_group_tests_name("table_options", tests, setup, teardown);
}
