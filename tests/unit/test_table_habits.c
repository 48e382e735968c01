/*
** Tests of the habits of real testing-machine exports that the table reader (src/io/measure.c,
** io/columns.c, io/header.c) accepts: unit spellings in any letter case where they are not
** ambiguous, strain in mm/mm or percent, stretch columns, comments in another encoding, a
** preamble before the header row, a units row under it, and columns picked by the caller. The shipped and published
** tables must read as before: that is tests/unit/test_measure.c and the golden outputs.
*/
#include <errno.h>
#include <sys/stat.h>

#include "testutil.h"

#include "io/measure.h"

TU_SCRATCH_GROUP("habits")
static int file_counter;

/* Writes the text (len bytes; (size_t)-1 for a C string) and reads it as a table. */
static cf_status read_table(const char *text, size_t len, const cf_measure_options *opt,
                            cf_table *m, cf_error *err, const char **path_out)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/h%03d.csv", dir, ++file_counter);
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

/* Refused with CF_E_DATA, the message starting "PATH:LINE:" (line 0: "PATH: ") and holding each
** of the words. */
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

/* ---- stretch ---------------------------------------------------------------------------------- */

static void stretch_columns_and_strain_that_looks_like_stretch(void **state)
{
    (void)state;
    static const char *const names[] = {"stretch", "lambda", "\xce\xbb", "Lambda [-]"};
    for (size_t k = 0; k < 4; k++) {
        char t[256];
        snprintf(t, sizeof t, "%s,stress_kPa\n1,0\n1.1,1\n1.2,2\n1.3,3\n1.4,5\n1.5,8\n", names[k]);
        cf_table m;
        must_read(t, NULL, &m);
        assert_int_equal(m.x_from_stretch, 1);
        assert_int_equal(m.measures.strain, CF_STRAIN_STRETCH);
        assert_close(m.x[5], 0.5, 1e-15);
        assert_string_equal(m.notes, "");
        cf_table_free(&m);
    }
    /* stretch values in a column named strain: read as strain (the file says so), with a note */
    static const char looks[] = "strain,stress_kPa\n1,0\n1.1,1\n1.2,2\n1.3,3\n1.4,5\n1.5,8\n";
    cf_table m;
    must_read(looks, NULL, &m);
    assert_close(m.x[5], 1.5, 0);
    assert_non_null(strstr(m.notes, "column 'strain' holds strain 1 where the stress is least"));
    assert_non_null(strstr(m.notes, "looks like stretch"));
    cf_table_free(&m);
    /* the same sorted the other way, and in percent */
    must_read("strain (%),stress_kPa\n150,8\n140,5\n130,3\n120,2\n110,1\n100,0.001\n", NULL, &m);
    assert_non_null(strstr(m.notes, "row 6"));
    cf_table_free(&m);
    /* no note when the caller said what the column holds, nor for ordinary strain */
    cf_measure_options o = cf_measure_default_options();
    o.strain_measure = CF_STRAIN_ENGINEERING;
    must_read(looks, &o, &m);
    assert_string_equal(m.notes, "");
    cf_table_free(&m);
    must_read("strain,stress_kPa\n0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,5\n1.0,8\n", NULL, &m);
    assert_string_equal(m.notes, "");
    cf_table_free(&m);
    /* a unit read in another letter case is noted too */
    must_read(six_rows("strain,stress_Mpa"), NULL, &m);
    assert_non_null(strstr(m.notes, "unit 'Mpa' read as MPa"));
    cf_table_free(&m);
}

/* ---- comments and preambles ------------------------------------------------------------------ */

static void comments_and_preambles_may_hold_any_bytes(void **state)
{
    (void)state;
    /* a degree sign in Windows-1252 (0xB0), in a comment line and after a value */
    cf_table m;
    must_read("# specimen 3, 23 \xb0" "C\nstrain,stress_kPa\n0,0\n0.1,1 # 23.5 \xb0" "C\n0.2,2\n"
              "0.3,3\n0.4,4\n0.5,5\n",
              NULL, &m);
    assert_int_equal(m.count, 6);
    cf_table_free(&m);
    /* and in a preamble line before the header */
    must_read("Temperature,23 \xb0" "C\nStrain (mm/mm),Stress (MPa)\n0,0\n1,1\n2,2\n3,3\n4,4\n"
              "5,5\n",
              NULL, &m);
    assert_int_equal(m.count, 6);
    cf_table_free(&m);
    /* but not in a data row, nor in the header */
    must_refuse("strain,stress_kPa\n0,0\n0.1,1\xb0\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n", NULL, 3,
                "0xB0", "binary");
    must_refuse("strain,stress \xb0kPa\n0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n", NULL, 1,
                "0xB0", "binary");
}

/* An export as an Instron or Zwick program writes it: metadata lines, then the header row. */
static const char instron[] =
    "\"Sample ID:\",\"SPEC-3\"\n"
    "\"Test date:\",\"2026-11-02\"\n"
    "\"Width (mm)\",10.2,\"Thickness (mm)\",2.1\n"
    "\n"
    "Time (s),Strain (mm/mm),Stress (MPa)\n"
    "0,0,0\n1,0.1,1\n2,0.2,2\n3,0.3,3\n4,0.4,4\n5,0.5,5\n";

static void a_preamble_before_the_header_row_is_skipped(void **state)
{
    (void)state;
    cf_table m;
    must_read(instron, NULL, &m);
    assert_int_equal(m.count, 6);
    assert_string_equal(m.x_column, "Strain (mm/mm)");
    assert_string_equal(m.y_column, "Stress (MPa)");
    assert_close(m.y[5], 5.0, 1e-15);
    assert_non_null(m.t); /* the time column is read: --columns leaves it out (below) */
    assert_non_null(strstr(m.notes, "lines 1 to 4 before the header row (line 5) were skipped"));
    cf_table_free(&m);
    /* a preamble whose first line names a known column (strain) */
    must_read("Strain rate,0.01,1/s\nGauge length (mm),25.0\nStrain (%),Stress (kPa)\n0,0\n"
              "10,1\n20,2\n30,3\n40,4\n50,5\n",
              NULL, &m);
    assert_close(m.x[5], 0.5, 1e-15);
    assert_non_null(strstr(m.notes, "lines 1 to 2 before the header row (line 3)"));
    cf_table_free(&m);
    /* a header naming known columns with a bad row after it: refused at that row, as before */
    must_refuse("strain,stress_kPa\nabc,def\n0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n", NULL,
                2, "not a number", "'abc'");
    /* the option names the header's line; the preamble before it is skipped */
    cf_measure_options o = cf_measure_default_options();
    o.header_row = 5;
    must_read(instron, &o, &m);
    assert_int_equal(m.count, 6);
    cf_table_free(&m);
    /* a header row of names the reader does not know: found with the option, and without it
    ** the message names that line (5), not the first */
    static const char unknown[] = "Operator,Smith\nMachine,5944\n\nStation A\ne,s [kPa]\n0,0\n"
                                  "0.1,1\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n";
    must_refuse(unknown, NULL, 5, "no header row", "line 6");
    o.header_row = 5;
    must_read(unknown, &o, &m);
    assert_string_equal(m.y_unit, "kPa");
    assert_close(m.x[5], 0.5, 1e-15);
    cf_table_free(&m);
    /* the option on a comment, a blank line or beyond the file */
    static const char commented[] = "# a comment\nstrain,stress_kPa\n\n0,0\n0.1,1\n0.2,2\n0.3,3\n"
                                    "0.4,4\n0.5,5\n";
    o.header_row = 1;
    must_refuse(commented, &o, 1, "header_row 1", "a comment");
    o.header_row = 3;
    must_refuse(commented, &o, 3, "header_row 3", "blank");
    o.header_row = 99;
    must_refuse(commented, &o, 9, "header_row 99", "9 lines");
    /* a table without preamble is read from its first line as before, also with the option */
    o.header_row = 2;
    must_read(commented, &o, &m);
    assert_int_equal(m.count, 6);
    cf_table_free(&m);
}

/* ---- a units row under the header ------------------------------------------------------------ */

/* The three styles of testing machines: Instron Bluehill (quoted, units in parentheses, after a
** preamble), ZwickRoell testXpert (semicolons, units in brackets, decimal commas) and MTS
** TestSuite (bare units, "sec"). */
static const char bluehill[] =
    "\"Results Table 1\"\n\"Specimen label\",\"Sample-4\"\n\"Gauge length (mm)\",\"24.48\"\n\n"
    "\"Time\",\"Extension\",\"Load\",\"Tensile strain (Extension)\",\"Tensile stress\"\n"
    "\"(s)\",\"(mm)\",\"(N)\",\"(mm/mm)\",\"(MPa)\"\n"
    "\"0.00\",\"0.000\",\"0.000\",\"0.0000\",\"0.000\"\n\"0.01\",\"0.245\",\"0.10\",\"0.0100\",\"1.0\"\n"
    "\"0.02\",\"0.490\",\"0.30\",\"0.0200\",\"3.1\"\n\"0.03\",\"0.734\",\"0.62\",\"0.0300\",\"6.3\"\n"
    "\"0.04\",\"0.979\",\"1.05\",\"0.0400\",\"10.7\"\n\"0.05\",\"1.224\",\"1.60\",\"0.0500\",\"16.4\"\n";
static const char testxpert[] = "Standard travel;Standard force;Strain;Stress\n[mm];[kN];[%];[MPa]\n"
                                "0;0;0;0\n0,5;0,010;1;0,4\n1;0,030;2;1,2\n1,5;0,062;3;2,5\n"
                                "2;0,105;4;4,2\n2,5;0,160;5;6,4\n";
static const char mts[] = "Time,Displacement,Force\nsec,mm,N\n0,0,0\n1,0.5,10\n2,1,30\n"
                          "3,1.5,62\n4,2,105\n5,2.5,160\n";

static void a_units_row_gives_the_units_the_header_lacks(void **state)
{
    (void)state;
    cf_table m;
    cf_measure_options o = cf_measure_default_options();
    o.columns = "4,5"; /* Instron's strain and stress, after its preamble */
    must_read(bluehill, &o, &m);
    assert_int_equal(m.count, 6);
    assert_int_equal(m.kind, CF_TABLE_STRESS_STRAIN);
    assert_string_equal(m.y_unit, "MPa");
    assert_close(m.x[5], 0.05, 1e-15);
    assert_close(m.y[5], 16.4, 1e-12);
    assert_non_null(strstr(m.notes, "lines 1 to 4 before the header row (line 5)"));
    assert_non_null(strstr(m.notes, "column 'Tensile stress': unit 'MPa' read from the units "
                                    "row under the header (line 6)"));
    assert_non_null(strstr(m.notes, "'Tensile strain (Extension)': unit 'mm/mm'"));
    cf_table_free(&m);
    o.columns = "Extension,Load"; /* its crosshead: force against displacement */
    must_read(bluehill, &o, &m);
    assert_true(cf_table_is_force(&m));
    assert_string_equal(m.y_unit, "N");
    assert_close(m.x[5], 1.224, 1e-15);
    cf_table_free(&m);
    must_read(testxpert, NULL, &m); /* percent and MPa in brackets, decimal commas */
    assert_int_equal(m.kind, CF_TABLE_STRESS_STRAIN);
    assert_close(m.x[5], 0.05, 1e-15);
    assert_close(m.y[5], 6.4, 1e-15);
    assert_non_null(strstr(m.notes, "column 'Strain': unit '%' read from the units row"));
    cf_table_free(&m);
    o.columns = "Standard travel,Standard force"; /* its crosshead, in kN */
    must_read(testxpert, &o, &m);
    assert_true(cf_table_is_force(&m));
    assert_string_equal(m.y_unit, "kN");
    assert_close(m.x[1], 0.5, 1e-15);
    assert_close(m.y[5] * m.y_to_file, 0.16, 1e-15);
    assert_non_null(strstr(m.notes, "column 'Standard force': unit 'kN' read from the units row"));
    cf_table_free(&m);
    o.columns = "Displacement,Force";
    must_read(mts, &o, &m); /* "sec" is seconds; the time column left out */
    assert_null(m.t);
    assert_close(m.y[5], 160.0, 0);
    cf_table_free(&m);
    must_read(mts, NULL, &m); /* with it: a time series whose time unit came from the row */
    assert_non_null(m.t);
    assert_close(m.t[5], 5.0, 0);
    cf_table_free(&m);
    /* a units row that agrees with the header's units (another case of the same unit) */
    must_read("strain (%),stress (kPa)\n(%),(KPA)\n0,0\n10,1\n20,2\n30,3\n40,4\n50,5\n", NULL, &m);
    assert_close(m.x[5], 0.5, 1e-15);
    assert_null(strstr(m.notes, "units row"));
    cf_table_free(&m);
    /* without a units row, nothing changes: the header row without units is refused as before */
    must_refuse("Strain,Stress\n0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n", NULL, 1, "no unit",
                "'Stress'");
}

static void a_bad_or_contradicting_units_row_is_refused(void **state)
{
    (void)state;
    /* a unit conifit does not know, in a column the table reads: that line and column */
    must_refuse("Time,Extension,Load\n(s),(mm),(lbf)\n0,0,0\n1,1,1\n2,2,2\n3,3,3\n4,4,4\n5,5,5\n",
                &(cf_measure_options){.columns = "Extension,Load"}, 2, "units row",
                "column 'Load' has unit 'lbf'");
    /* ... and the column is the third */
    cf_error err = {0};
    cf_table m;
    cf_measure_options o = cf_measure_default_options();
    o.columns = "Extension,Load";
    assert_int_equal(read_table("Time,Extension,Load\n(s),(mm),(lbf)\n0,0,0\n1,1,1\n2,2,2\n"
                                "3,3,3\n4,4,4\n5,5,5\n",
                                (size_t)-1, &o, &m, &err, NULL),
                     CF_E_DATA);
    assert_non_null(strstr(err.msg, ":2:3:"));
    /* an unknown unit in a column the table does not read is let be */
    must_read("Temperature,Strain,Stress\n(degC),(-),(MPa)\n20,0,0\n20,0.1,1\n20,0.2,2\n"
              "20,0.3,3\n20,0.4,4\n20,0.5,5\n",
              NULL, &m);
    assert_close(m.y[5], 5.0, 0);
    cf_table_free(&m);
    /* "mPa" under a header saying MPa: milli against mega, a contradiction */
    must_refuse("strain,stress (MPa)\n(-),(mPa)\n0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n", NULL,
                2, "has unit 'mPa', but its header (line 1) says 'MPa'", NULL);
    /* kPa under a header saying MPa; percent under a header saying mm/mm */
    must_refuse("strain,stress_MPa\n[-],[kPa]\n0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n", NULL, 2,
                "column 'stress_MPa' has unit 'kPa'", "says 'MPa'");
    must_refuse("strain (mm/mm);stress (MPa)\n(%);(MPa)\n0;0\n1;1\n2;2\n3;3\n4;4\n5;5\n", NULL,
                2, "column 'strain (mm/mm)' has unit '%'", NULL);
    /* more cells than the header has columns */
    must_refuse("strain,stress\n(-),(MPa),(N)\n0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n", NULL,
                2, "units row: 3 cells", NULL);
}

/* The raw tendon table (an Instron Bluehill export) written back in Bluehill's own layout, its
** crosshead columns made from its gauge length and cross-section: the units row gives every unit,
** and strain, stress and the crosshead read back the published rows. */
static void the_tendon_export_in_bluehill_layout(void **state)
{
    (void)state;
    const char *datasets = tu_datasets();
    if (!datasets) {
        print_message("skipped: ../shared/datasets is absent\n");
        skip();
    }
    char path[512];
    snprintf(path, sizeof path, "%s/tendon_fascicle_tension_raw.csv", datasets);
    cf_table ref;
    cf_error err = {0};
    if (cf_measure_load(path, NULL, &ref, &err) != CF_OK)
        fail_msg("%s: %s", path, err.msg);
    const double gauge = 24.48, area = 3.14159265358979 * 0.353 * 0.353 / 4.0; /* mm, mm2 */
    size_t cap = 512 + ref.count * 128, o = 0;
    char *text = malloc(cap);
    assert_non_null(text);
    o += (size_t)snprintf(text + o, cap - o,
                          "\"Specimen label\",\"Sample-4\"\n\"Gauge length\",\"24.48\",\"mm\"\n\n"
                          "\"Time\",\"Extension\",\"Load\",\"Tensile strain (Extension)\","
                          "\"Tensile stress\"\n\"(s)\",\"(mm)\",\"(N)\",\"(mm/mm)\",\"(MPa)\"\n");
    for (size_t k = 0; k < ref.count; k++)
        o += (size_t)snprintf(text + o, cap - o,
                              "\"%.2f\",\"%.17g\",\"%.17g\",\"%.17g\",\"%.17g\"\n", 0.01 * (double)k,
                              ref.x[k] * gauge, ref.y[k] * area, ref.x[k], ref.y[k]);
    cf_table m;
    cf_measure_options opt = cf_measure_default_options();
    opt.columns = "Tensile strain (Extension),Tensile stress";
    must_read(text, &opt, &m);
    assert_int_equal(m.count, ref.count);
    for (size_t k = 0; k < ref.count; k++) {
        assert_close(m.x[k], ref.x[k], 0.0);
        assert_close(m.y[k], ref.y[k], 0.0);
    }
    assert_non_null(strstr(m.notes, "(line 5)"));
    cf_table_free(&m);
    opt.columns = "2,3";
    must_read(text, &opt, &m);
    assert_true(cf_table_is_force(&m));
    assert_int_equal(m.count, ref.count);
    for (size_t k = 0; k < ref.count; k++)
        assert_close(m.y[k], ref.y[k] * area, 0.0);
    cf_table_free(&m);
    cf_table_free(&ref);
    free(text);
}

/* ---- columns picked by the caller ------------------------------------------------------------ */

static void columns_option_picks_x_y_and_weight(void **state)
{
    (void)state;
    static const char t[] = "time_s,weight,strain,stress_kPa,sd\n0,1,0,0,3\n1,2,0.1,1,3\n"
                            "2,1,0.2,2,3\n3,1,0.3,3,3\n4,1,0.4,4,3\n5,1,0.5,5,3\n";
    cf_table m;
    cf_measure_options o = cf_measure_default_options();
    must_read(t, NULL, &m); /* by names: a time series with weights */
    assert_non_null(m.t);
    assert_close(m.w[1], 2.0, 0);
    cf_table_free(&m);
    o.columns = "strain,stress_kPa"; /* only those: no time, every weight 1 */
    must_read(t, &o, &m);
    assert_null(m.t);
    assert_close(m.w[1], 1.0, 0);
    assert_close(m.y[5], 5e-3, 1e-18);
    cf_table_free(&m);
    o.columns = "3, 4, sd"; /* numbers, names, blanks around them; sd as the weight */
    must_read(t, &o, &m);
    assert_null(m.t);
    assert_close(m.w[1], 3.0, 0);
    assert_string_equal(m.x_column, "strain");
    cf_table_free(&m);
    o.columns = "strain,6";
    must_refuse(t, &o, 1, "no y column named '6'", "time_s, weight");
    o.columns = "strain,stress_kPa,strain";
    must_refuse(t, &o, 1, "the x and the weight are one column", "'strain'");
    o.columns = "strain";
    must_refuse(t, &o, 0, "option columns 'strain'", "X,Y");
    o.columns = "1,2,3,4";
    must_refuse(t, &o, 0, "option columns '1,2,3,4'", "X,Y");
}

/* ---- the published tables -------------------------------------------------------------------- */

/* The published tables read as before (their values: test_measure.c) and none draws a note. */
static void published_tables_draw_no_note(void **state)
{
    (void)state;
    const char *datasets = tu_datasets();
    if (!datasets) {
        print_message("skipped: ../shared/datasets is absent\n");
        skip();
    }
    for (size_t k = 0; k < TU_PUBLISHED_COUNT; k++) {
        char path[512];
        snprintf(path, sizeof path, "%s/%s", datasets, tu_published_tables[k]);
        cf_table m;
        cf_error err = {0};
        if (cf_measure_load(path, NULL, &m, &err) != CF_OK)
            fail_msg("%s: %s", path, err.msg);
        if (m.notes[0])
            fail_msg("%s: unexpected note: %s", path, m.notes);
        cf_table_free(&m);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(unit_prefixes_ignore_case_unless_m_or_M),
        cmocka_unit_test(strain_units_mm_per_mm_and_percent),
        cmocka_unit_test(stretch_columns_and_strain_that_looks_like_stretch),
        cmocka_unit_test(comments_and_preambles_may_hold_any_bytes),
        cmocka_unit_test(a_preamble_before_the_header_row_is_skipped),
        cmocka_unit_test(columns_option_picks_x_y_and_weight),
        cmocka_unit_test(a_units_row_gives_the_units_the_header_lacks),
        cmocka_unit_test(a_bad_or_contradicting_units_row_is_refused),
        cmocka_unit_test(the_tendon_export_in_bluehill_layout),
        cmocka_unit_test(published_tables_draw_no_note),
    };
    return cmocka_run_group_tests_name("table_habits", tests, setup, teardown);
}
