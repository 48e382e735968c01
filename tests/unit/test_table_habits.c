/*
** Tests of the habits of real testing-machine exports that the table reader (src/io/measure.c,
** io/columns.c, io/header.c) accepts: unit spellings in any letter case where they are not
** ambiguous, strain in mm/mm or percent, stretch columns, comments in another encoding, a
** preamble before the header row, and columns picked by the caller. The shipped and published
** tables must read as before: that is tests/unit/test_measure.c and the golden outputs.
*/
#include <errno.h>
#include <sys/stat.h>

#include "testutil.h"

#include "conifit/measure.h"

static char tmpdir[256];
static int file_counter;

static int make_dir(void **state)
{
    (void)state;
    return tu_make_tmpdir(tmpdir, sizeof tmpdir, "conifit-habits");
}

static int drop_dir(void **state)
{
    (void)state;
    return tu_remove_tmpdir(tmpdir);
}

/* Writes the text (len bytes; (size_t)-1 for a C string) and reads it as a table. */
static cf_status read_table(const char *text, size_t len, const cf_measure_options *opt,
                            cf_table *m, cf_error *err, const char **path_out)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/h%03d.csv", tmpdir, ++file_counter);
    assert_int_equal(tu_write_bytes(path, text, len == (size_t)-1 ? strlen(text) : len), 0);
    if (path_out)
        *path_out = path;
    return cf_measure_load(path, opt, m, err);
}

static void must_read(const char *text, const cf_measure_options *opt, cf_table *m)
{
    cf_error err = {0};
    if (read_table(text, (size_t)-1, opt, m, &err, NULL) != CF_OK)
        fail_msg("refused: %s\n--- table ---\n%s", err.msg, text);
}

/* Refused with CF_E_DATA, the message starting "PATH:LINE:" (line 0: "PATH: ") and holding each of the words. */
static void must_refuse(const char *text, const cf_measure_options *opt, int line,
                        const char *w1, const char *w2)
{
    cf_error err = {0};
    cf_table m;
    const char *path;
    cf_status st = read_table(text, (size_t)-1, opt, &m, &err, &path);
    if (st != CF_E_DATA)
        fail_msg("status %d, expected CF_E_DATA (message: %s)\n%s", st, err.msg, text);
    char where[600];
    if (line > 0)
        snprintf(where, sizeof where, "%s:%d:", path, line);
    else /* a message about an option names the file only */
        snprintf(where, sizeof where, "%s: ", path);
    if (strncmp(err.msg, where, strlen(where)) != 0)
        fail_msg("message does not start '%s': %s", where, err.msg);
    if (w1 && !strstr(err.msg, w1))
        fail_msg("message lacks '%s': %s", w1, err.msg);
    if (w2 && !strstr(err.msg, w2))
        fail_msg("message lacks '%s': %s", w2, err.msg);
}

/* Six rows x = 0..5 (times xs), y = 0..5, after the header. */
static const char *six_rows(const char *header)
{
    static char buf[1024];
    snprintf(buf, sizeof buf, "%s\n0,0\n1,1\n2,2\n3,3\n4,4\n5,5\n", header);
    return buf;
}

/* ---- units ----------------------------------------------------------------------------------- */

static void unit_prefixes_ignore_case_unless_m_or_M(void **state)
{
    (void)state;
    static const struct {
        const char *header, *canon;
        double to_mpa;
    } ok[] = {
        {"strain,stress_Mpa", "MPa", 1.0},   {"strain,stress (MPA)", "MPa", 1.0},
        {"strain,stress_kpa", "kPa", 1e-3},  {"strain,stress (KPA)", "kPa", 1e-3},
        {"strain,stress [gpa]", "GPa", 1e3}, {"strain,stress [pa]", "Pa", 1e-6},
    };
    for (size_t k = 0; k < sizeof ok / sizeof ok[0]; k++) {
        cf_table m;
        must_read(six_rows(ok[k].header), NULL, &m);
        assert_string_equal(m.y_unit, ok[k].canon);
        assert_close(m.y[5], 5.0 * ok[k].to_mpa, 1e-15 * ok[k].to_mpa);
        cf_table_free(&m);
    }
    /* a leading m or M in another case: never taken for the other, both readings named */
    must_refuse(six_rows("strain,stress [mPa]"), NULL, 1, "'mPa' is ambiguous", "'MPa'");
    must_refuse(six_rows("strain,stress_mpa"), NULL, 1, "milli", "mega");
    must_refuse(six_rows("displacement_mm,force [MN]"), NULL, 1, "'MN' is ambiguous", "'mN'");
    must_refuse(six_rows("displacement [MM],force_N"), NULL, 1, "'MM' is ambiguous", "'mm'");
    cf_measure_options o = cf_measure_default_options();
    o.stress_unit = "mPa";
    must_refuse(six_rows("strain,stress"), &o, 0, "option stress_unit", "'MPa'");
}

static void strain_units_mm_per_mm_and_percent(void **state)
{
    (void)state;
    static const struct {
        const char *header;
        double scale;
    } t[] = {
        {"strain (mm/mm),stress (MPa)", 1.0}, {"strain [in/in],stress_MPa", 1.0},
        {"strain (m/m),stress_MPa", 1.0},     {"strain (%),stress_MPa", 0.01},
        {"strain_percent,stress_MPa", 0.01},  {"strain_pct,stress_MPa", 0.01},
        {"Strain %,stress_MPa", 0.01},        {"strain percent,stress_MPa", 0.01},
        {"Strain (IN/IN),Stress (Mpa)", 1.0},
    };
    for (size_t k = 0; k < sizeof t / sizeof t[0]; k++) {
        cf_table m;
        must_read(six_rows(t[k].header), NULL, &m);
        assert_int_equal(m.kind, CF_TABLE_STRESS_STRAIN);
        assert_close(m.x[5], 5.0 * t[k].scale, 1e-15);
        assert_string_equal(m.x_unit, "-");
        cf_table_free(&m);
    }
    /* percent is never a stretch */
    must_refuse(six_rows("stretch (%),stress_MPa"), NULL, 1, "'stretch (%)'", "%");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(unit_prefixes_ignore_case_unless_m_or_M),
        cmocka_unit_test(strain_units_mm_per_mm_and_percent),
    };
    return cmocka_run_group_tests_name("table_habits", tests, make_dir, drop_dir);
}
