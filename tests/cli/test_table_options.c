/*
** Tests of the table options of `conifit fit` through the program: --columns picks the x, y (and
** weight) columns so that a time column of a single ramp is ignored, --header-row names the
** header of an export with a preamble; a malformed value is a usage error (2), a column or line
** the table does not have is bad data (65), each message naming what it refused; the reader's
** notes (strain that looks like stretch) are warnings on stderr.
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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(columns_option_ignores_a_time_column),
        cmocka_unit_test(header_row_option_reads_an_export_with_a_preamble),
        cmocka_unit_test(table_notes_are_warnings),
    };
    return cmocka_run_group_tests_name("table_options", tests, setup, teardown);
}
