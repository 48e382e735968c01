/*
** Tests of the measurement-table reader (src/io/measure.c, with io/csv.c and io/columns.c): every
** accepted variant of the CSV dialect and of unit spelling, every error of the catalogue with its
** status, line, column and offending text, and the published tables in ../shared/datasets (when
** present). `conifit synth` and the tables shipped in data/ are tested in tests/cli/test_synth.c.
*/
#include <errno.h>
#include <sys/stat.h>

#include "testutil.h"

#include "model/law_internal.h"
#include "io/measure.h"
#include "io/columns.h"

/* Relative tolerance for values that went through one unit conversion (a product of doubles). */
#define CONV_TOL 1e-15

static char tmpdir[256];
static int file_counter;

static int setup_tmpdir(void **state)
{
    (void)state;
    snprintf(tmpdir, sizeof tmpdir, "/tmp/conifit-measure-XXXXXX");
    return mkdtemp(tmpdir) ? 0 : -1;
}

static int remove_tmpdir(void **state)
{
    (void)state;
    char cmd[512];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    return system(cmd) == 0 ? 0 : -1;
}

/* Writes len bytes (len = (size_t)-1: a C string) into a fresh file; returns its path. */
static const char *write_bytes(const char *text, size_t len)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/t%03d.csv", tmpdir, ++file_counter);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    if (len == (size_t)-1)
        len = strlen(text);
    assert_int_equal(fwrite(text, 1, len, f), len);
    assert_int_equal(fclose(f), 0);
    return path;
}

static const char *write_text(const char *text)
{
    return write_bytes(text, (size_t)-1);
}

static void load_ok(const char *text, const cf_measure_options *opt, cf_table *m)
{
    cf_error err = {0};
    const char *path = write_text(text);
    cf_status st = cf_measure_load(path, opt, m, &err);
    if (st != CF_OK)
        fail_msg("refused a valid table: %s\n--- table ---\n%s", err.msg, text);
}

/* Loads a bad table and checks the status, that the message starts "PATH:LINE:COL:", and that
** it quotes the given text. */
static void expect_error_bytes(const char *text, size_t len, const cf_measure_options *opt,
                               cf_status status, int line, int col, const char *quoted)
{
    cf_error err = {0};
    cf_table m;
    const char *path = write_bytes(text, len);
    cf_status st = cf_measure_load(path, opt, &m, &err);
    if (st != status)
        fail_msg("status %d, expected %d (message: %s)", st, status, err.msg);
    assert_int_equal(err.status, status);
    assert_null(m.x);
    assert_null(m.y);
    assert_int_equal(m.count, 0);
    char where[600];
    snprintf(where, sizeof where, "%s:%d:%d: ", path, line, col);
    if (strncmp(err.msg, where, strlen(where)) != 0)
        fail_msg("message '%s' does not start with '%s'", err.msg, where);
    if (quoted && !strstr(err.msg, quoted))
        fail_msg("message '%s' does not quote '%s'", err.msg, quoted);
}

static void expect_error(const char *text, const cf_measure_options *opt, int line, int col,
                         const char *quoted)
{
    expect_error_bytes(text, (size_t)-1, opt, CF_E_DATA, line, col, quoted);
}

static const char rows6[] = "0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n";

/* A table: the header followed by six rows 0.1 i, i (i = 0..5). */
static const char *with_header(const char *header)
{
    static char buf[1024];
    snprintf(buf, sizeof buf, "%s\n%s", header, rows6);
    return buf;
}

/* ---- accepted variants -------------------------------------------------------------------- */

static void stress_units_are_read_from_every_decoration(void **state)
{
    (void)state;
    static const struct {
        const char *header;
        double to_mpa;
        const char *unit;
    } cases[] = {
        {"strain,stress_kPa", 1e-3, "kPa"},   {"strain,stress [kPa]", 1e-3, "kPa"},
        {"strain,stress (kPa)", 1e-3, "kPa"}, {"strain,stress_Pa", 1e-6, "Pa"},
        {"strain,stress_MPa", 1.0, "MPa"},    {"strain,stress [GPa]", 1e3, "GPa"},
        {"strain,stress [N/mm2]", 1.0, "N/mm2"}, {"strain,stress (N/m2)", 1e-6, "N/m2"},
        {"strain,stress_mmHg", 133.322387415e-6, "mmHg"},
        {"strain,nominal_stress_kPa", 1e-3, "kPa"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        cf_table m;
        load_ok(with_header(cases[k].header), NULL, &m);
        assert_int_equal(m.kind, CF_TABLE_STRESS_STRAIN);
        assert_int_equal(m.count, 6);
        assert_string_equal(m.y_unit, cases[k].unit);
        assert_string_equal(m.x_unit, "-");
        for (size_t i = 0; i < 6; i++) {
            assert_close(m.x[i], 0.1 * (double)i, 1e-15);
            assert_close(m.y[i], (double)i * cases[k].to_mpa, CONV_TOL * 5 * cases[k].to_mpa);
            assert_close(m.w[i], 1.0, 0.0);
        }
        assert_close(m.y_to_file * cases[k].to_mpa, 1.0, 1e-15);
        assert_null(m.t);
        cf_table_free(&m);
    }
}

static void force_and_length_units_make_a_force_displacement_table(void **state)
{
    (void)state;
    static const struct {
        const char *header;
        double x_to_mm, y_to_n;
        const char *yunit;
    } cases[] = {
        {"displacement_mm,force_N", 1.0, 1.0, "N"},
        {"displacement [cm],force [mN]", 10.0, 1e-3, "mN"},
        {"elongation (um),load (uN)", 1e-3, 1e-6, "uN"},
        {"displacement_m,force_kN", 1e3, 1e3, "kN"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        cf_table m;
        load_ok(with_header(cases[k].header), NULL, &m);
        assert_int_equal(m.kind, CF_TABLE_FORCE_DISPLACEMENT);
        assert_string_equal(m.x_unit, "mm");
        assert_string_equal(m.y_unit, cases[k].yunit);
        assert_close(m.x[3], 0.3 * cases[k].x_to_mm, 1e-15 * cases[k].x_to_mm);
        assert_close(m.y[5], 5.0 * cases[k].y_to_n, 1e-15 * cases[k].y_to_n);
        assert_close(m.y_to_file * cases[k].y_to_n, 1.0, 1e-15);
        cf_table_free(&m);
    }
}

static void options_override_and_supply_units(void **state)
{
    (void)state;
    cf_table m;
    cf_measure_options o = cf_measure_default_options();
    o.stress_unit = "MPa";
    load_ok(with_header("strain,stress_kPa"), &o, &m); /* the option wins over the name */
    assert_close(m.y[2], 2.0, 0.0);
    assert_string_equal(m.y_unit, "MPa");
    cf_table_free(&m);
    o.stress_unit = "Pa";
    load_ok(with_header("strain,stress"), &o, &m);
    assert_close(m.y[4], 4e-6, 1e-21);
    cf_table_free(&m);
    o = cf_measure_default_options();
    o.force_unit = "mN";
    o.length_unit = "um";
    load_ok(with_header("displacement,force"), &o, &m);
    assert_int_equal(m.kind, CF_TABLE_FORCE_DISPLACEMENT);
    assert_close(m.x[5], 0.5e-3, 1e-18);
    assert_close(m.y[5], 5e-3, 1e-18);
    cf_table_free(&m);
}

static void percent_strain_is_divided_by_100(void **state)
{
    (void)state;
    cf_table m;
    load_ok(with_header("strain_%,stress_kPa"), NULL, &m);
    assert_close(m.x[5], 0.005, 1e-18);
    cf_table_free(&m);
}

static void semicolon_tab_and_decimal_comma_are_read(void **state)
{
    (void)state;
    cf_table m;
    load_ok("strain;stress_kPa\n0;0\n0.1;1\n0.2;2\n0.3;3\n0.4;4\n0.5;5\n", NULL, &m);
    assert_close(m.y[3], 3e-3, 1e-18);
    cf_table_free(&m);
    load_ok("strain\tstress_kPa\n0\t0\n0.1\t1\n0.2\t2\n0.3\t3\n0.4\t4\n0.5\t5\n", NULL, &m);
    assert_close(m.x[4], 0.4, 0.0);
    cf_table_free(&m);
    load_ok("strain;stress_kPa\n0;0\n0,1;1,5\n0,2;2\n0,3;3\n0,4;4\n0,5;5\n", NULL, &m);
    assert_close(m.x[1], 0.1, 0.0);
    assert_close(m.y[1], 1.5e-3, 1e-18);
    cf_table_free(&m);
}

static void quoted_fields_with_escaped_quotes_are_read(void **state)
{
    (void)state;
    cf_table m;
    load_ok("\"note, free text\",\"strain\",\"stress [kPa]\"\n"
            "\"a \"\"quoted\"\" word\",\"0\",\"0\"\n"
            "\"x, y\",0.1,1\n,0.2,2\n\"\",0.3,3\n z ,0.4,4\n\"#not a comment\",0.5,5\n",
            NULL, &m);
    assert_int_equal(m.count, 6);
    assert_string_equal(m.x_column, "strain");
    assert_string_equal(m.y_column, "stress [kPa]");
    assert_close(m.y[5], 5e-3, 1e-18);
    cf_table_free(&m);
}

static void bom_crlf_comments_and_blank_lines_are_skipped(void **state)
{
    (void)state;
    cf_table m;
    load_ok("\xEF\xBB\xBF# made by hand\r\n\r\n# units in the names\r\nstrain,stress_kPa\r\n"
            "0,0\r\n  # a comment between rows\r\n0.1,1 # after a value\r\n\r\n0.2,2\r\n"
            ",\r\n0.3,3\r\n0.4,4\r\n0.5,5",
            NULL, &m);
    assert_int_equal(m.count, 6);
    assert_close(m.x[1], 0.1, 0.0);
    assert_close(m.y[5], 5e-3, 1e-18);
    cf_table_free(&m);
}

static void trailing_delimiter_is_accepted_when_every_line_has_it(void **state)
{
    (void)state;
    cf_table m;
    load_ok("strain,stress_kPa,\n0,0,\n0.1,1,\n0.2,2,\n0.3,3,\n0.4,4,\n0.5,5,\n", NULL, &m);
    assert_int_equal(m.count, 6);
    cf_table_free(&m);
    /* only on the header: the rows are short */
    expect_error("strain,stress_kPa,\n0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n", NULL, 2, 3,
                 "0,0");
    /* only on the rows: they are long */
    expect_error("strain,stress_kPa\n0,0,\n0.1,1,\n0.2,2,\n0.3,3,\n0.4,4,\n0.5,5,\n", NULL, 2, 3,
                 "0,0,");
}

static void weight_column_is_read(void **state)
{
    (void)state;
    cf_table m;
    load_ok("strain,stress_kPa,weight\n0,0,1\n0.1,1,2\n0.2,2,0.5\n0.3,3,1\n0.4,4,1\n0.5,5,3\n",
            NULL, &m);
    assert_close(m.w[1], 2.0, 0.0);
    assert_close(m.w[2], 0.5, 0.0);
    assert_close(m.w[5], 3.0, 0.0);
    cf_table_free(&m);
}

static void stretch_is_converted_to_strain(void **state)
{
    (void)state;
    cf_table m;
    load_ok("stretch,stress_kPa\n1,0\n1.1,1\n1.2,2\n1.3,3\n0.9,-1\n0.8,-2\n", NULL, &m);
    assert_int_equal(m.x_from_stretch, 1);
    assert_close(m.x[0], 0.0, 0.0);
    assert_close(m.x[3], 0.3, 1e-15);
    assert_close(m.x[5], -0.2, 1e-15);
    cf_table_free(&m);
    load_ok("lambda [-],stress_kPa\n1,0\n1.1,1\n1.2,2\n1.3,3\n1.4,4\n1.5,5\n", NULL, &m);
    assert_close(m.x[5], 0.5, 1e-15);
    cf_table_free(&m);
    /* by option, on a column whose name says nothing */
    cf_measure_options o = cf_measure_default_options();
    o.x_is_stretch = 1;
    load_ok("a,stress_kPa\n1,0\n1.1,1\n1.2,2\n1.3,3\n1.4,4\n1.5,5\n", &o, &m);
    assert_close(m.x[2], 0.2, 1e-15);
    cf_table_free(&m);
    /* and the option can say a column named stretch holds strain */
    o.x_is_stretch = 0;
    load_ok("stretch,stress_kPa\n0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n", &o, &m);
    assert_int_equal(m.x_from_stretch, 0);
    assert_close(m.x[2], 0.2, 0.0);
    cf_table_free(&m);
}

static const char time_table[] =
    "time_s,strain,stress_kPa\n0,0,0\n1,-0.01,-1\n2,-0.02,-2\n3,-0.03,-3\n4,-0.03,-2.5\n"
    "5,-0.03,-2.2\n";

static void columns_are_chosen_by_name_in_a_wider_table(void **state)
{
    (void)state;
    cf_table m;
    load_ok(time_table, NULL, &m);
    assert_string_equal(m.x_column, "strain");
    assert_string_equal(m.y_column, "stress_kPa");
    assert_non_null(m.t);
    assert_close(m.t[4], 4.0, 0.0);
    assert_close(m.x[4], -0.03, 0.0);
    assert_int_equal(m.compression, 1);
    cf_table_free(&m);
    /* by option: the base name or the whole header name */
    cf_measure_options o = cf_measure_default_options();
    o.x_col = "time";
    o.y_col = "stress";
    o.length_unit = NULL;
    o.stress_unit = NULL;
    cf_error err = {0};
    const char *path = write_text("time,strain,stress_kPa\n0,0,0\n1,-0.01,-1\n2,-0.02,-2\n"
                                  "3,-0.03,-3\n4,-0.03,-2.5\n5,-0.03,-2.2\n");
    /* time as x with a stress: time has no strain unit, but seconds are not a strain */
    assert_int_equal(cf_measure_load(path, &o, &m, &err), CF_OK);
    assert_string_equal(m.x_column, "time");
    assert_close(m.x[5], 5.0, 0.0);
    assert_null(m.t);
    cf_table_free(&m);
    /* a time column makes a time series: it needs a unit, and time must increase */
    const char *bare = write_text("time,strain,stress_kPa\n0,0,0\n1,-0.01,-1\n2,-0.02,-2\n"
                                  "3,-0.03,-3\n4,-0.03,-2.5\n5,-0.03,-2.2\n");
    assert_int_equal(cf_measure_load(bare, NULL, &m, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, ":1:1: time column 'time' has no unit"));
    const char *back = write_text("time_s,strain,stress_kPa\n0,0,0\n1,-0.01,-1\n2,-0.02,-2\n"
                                  "3,-0.03,-3\n2.5,-0.03,-2.5\n5,-0.03,-2.2\n");
    assert_int_equal(cf_measure_load(back, NULL, &m, &err), CF_E_DATA);
    assert_non_null(strstr(err.msg, ":6:1: column 'time_s': time 2.5 s does not increase"));
    o.x_col = "STRAIN";
    o.y_col = "stress_kPa";
    load_ok(time_table, &o, &m);
    assert_close(m.y[5], -2.2e-3, 1e-18);
    cf_table_free(&m);
    /* without recognisable names, the first two columns */
    load_ok(with_header("a,b [kPa]"), NULL, &m);
    assert_string_equal(m.x_column, "a");
    assert_string_equal(m.y_column, "b [kPa]");
    cf_table_free(&m);
    /* y named first, x second */
    load_ok(with_header("shear_stress [kPa],gamma"), NULL, &m);
    assert_string_equal(m.x_column, "gamma");
    assert_close(m.x[5], 5.0, 0.0);
    cf_table_free(&m);
}

static void repeated_strains_are_kept_and_sign_is_reported(void **state)
{
    (void)state;
    cf_table m;
    load_ok("strain,stress_kPa\n0.1,1\n0.1,1.1\n0.2,2\n0.2,1.9\n0.1,0.9\n0,0\n", NULL, &m);
    assert_int_equal(m.count, 6);
    assert_close(m.x[1], 0.1, 0.0);
    assert_close(m.y[1], 1.1e-3, 1e-18);
    assert_int_equal(m.compression, 0);
    cf_table_free(&m);
    load_ok("strain,stress_kPa\n0,0\n-0.1,-1\n-0.2,-2\n-0.3,-3\n-0.4,-4\n-0.5,-5\n", NULL, &m);
    assert_int_equal(m.compression, 1);
    assert_close(m.x[5], -0.5, 0.0); /* kept as it is */
    assert_close(m.y[5], -5e-3, 1e-18);
    cf_table_free(&m);
}

static void units_stated_in_comments_are_honoured(void **state)
{
    (void)state;
    cf_table m;
    load_ok("# columns: strain = engineering (nominal) strain [-], stress = nominal stress [kPa]\n"
            "strain,stress\n0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n",
            NULL, &m);
    assert_string_equal(m.y_unit, "kPa");
    assert_close(m.y[5], 5e-3, 1e-18);
    cf_table_free(&m);
    load_ok("# units (x, y): strain, MPa\nstrain,stress\n0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n",
            NULL, &m);
    assert_string_equal(m.y_unit, "MPa");
    cf_table_free(&m);
    load_ok("# (x, y) = (strain, [kPa])\nstrain,stress\n0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n",
            NULL, &m);
    assert_string_equal(m.y_unit, "kPa");
    cf_table_free(&m);
    load_ok("# column 1 = displacement [mm], column 2 = force [mN]\ndisplacement,force\n"
            "0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n",
            NULL, &m);
    assert_int_equal(m.kind, CF_TABLE_FORCE_DISPLACEMENT);
    assert_string_equal(m.y_unit, "mN");
    assert_close(m.y[5], 5e-3, 1e-18);
    cf_table_free(&m);
}

static void unit_lookup_knows_classes_and_factors(void **state)
{
    (void)state;
    double f = 0.0;
    assert_int_equal(cf_measure_unit("kPa", &f), CF_UNIT_STRESS);
    assert_close(f, 1e-3, 0.0);
    assert_int_equal(cf_measure_unit("mN", &f), CF_UNIT_FORCE);
    assert_close(f, 1e-3, 0.0);
    assert_int_equal(cf_measure_unit("cm", &f), CF_UNIT_LENGTH);
    assert_close(f, 10.0, 0.0);
    assert_int_equal(cf_measure_unit("%", &f), CF_UNIT_STRAIN);
    assert_close(f, 0.01, 0.0);
    assert_int_equal(cf_measure_unit("mPa", NULL), CF_UNIT_UNKNOWN); /* milli, not mega */
    assert_int_equal(cf_measure_unit("kpa", NULL), CF_UNIT_STRESS); /* case ignored */
    assert_int_equal(cf_measure_unit("MN", NULL), CF_UNIT_UNKNOWN);  /* mega, not milli */
    assert_int_equal(cf_measure_unit(NULL, NULL), CF_UNIT_UNKNOWN);
}

/* ---- the error catalogue ------------------------------------------------------------------ */

static void bad_tables_fail_with_line_column_and_value(void **state)
{
    (void)state;
    /* missing header */
    expect_error("# no names\n0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n0.6,6\n", NULL, 2, 1,
                 "'0,0'");
    /* unknown unit, in brackets and in the wrong case */
    expect_error(with_header("strain,stress [furlong]"), NULL, 1, 2, "'furlong'");
    expect_error(with_header("strain,stress_mpa"), NULL, 1, 2, "'mpa'");
    expect_error(with_header("strain,stress_MPa,time [fortnight]"), NULL, 1, 3, "'fortnight'");
    /* a unit of the wrong kind for the column */
    expect_error(with_header("strain,stress [mm]"), NULL, 1, 2, "'mm'");
    expect_error(with_header("displacement_mm,stress_kPa"), NULL, 1, 1, "'displacement_mm'");
    /* a y column without any unit names the column and the flag */
    expect_error(with_header("strain,stress"), NULL, 1, 2, "'stress'");
    expect_error(with_header("strain,stress"), NULL, 1, 2, "option stress_unit");
    expect_error(with_header("displacement,force_N"), NULL, 1, 1, "option length_unit");
    /* columns not found */
    cf_measure_options o = cf_measure_default_options();
    o.y_col = "load";
    expect_error(with_header("strain,stress_kPa"), &o, 1, 1, "'load'");
    o = cf_measure_default_options();
    o.x_col = "stretch";
    expect_error(with_header("strain,stress_kPa"), &o, 1, 1, "'stretch'");
    /* non-numeric and non-finite cells */
    const char *h = "# comment\nstrain,stress_kPa\n0,0\n0.1,1\n";
    char buf[512];
    static const struct {
        const char *cell;
        const char *quoted;
    } bad_cells[] = {{"abc", "not a number ('abc')"}, {"1.2.3", "'1.2.3'"},
                     {"0x10", "'0x10'"},              {"nan", "not a finite number ('nan')"},
                     {"-inf", "'-inf'"},              {"1e999", "'1e999'"},
                     {"", "empty cell ('')"},         {"Infinity", "'Infinity'"}};
    for (size_t k = 0; k < sizeof bad_cells / sizeof bad_cells[0]; k++) {
        snprintf(buf, sizeof buf, "%s0.2,%s\n0.3,3\n0.4,4\n0.5,5\n", h, bad_cells[k].cell);
        expect_error(buf, NULL, 5, 2, bad_cells[k].quoted);
    }
    snprintf(buf, sizeof buf, "%szero,2\n0.3,3\n0.4,4\n0.5,5\n", h);
    expect_error(buf, NULL, 5, 1, "'zero'");
    /* short and long rows */
    snprintf(buf, sizeof buf, "%s0.2\n0.3,3\n0.4,4\n0.5,5\n", h);
    expect_error(buf, NULL, 5, 2, "short row");
    snprintf(buf, sizeof buf, "%s0.2,2,77\n0.3,3\n0.4,4\n0.5,5\n", h);
    expect_error(buf, NULL, 5, 3, "'77'");
    /* fewer than 6 data rows */
    expect_error("strain,stress_kPa\n0,0\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n", NULL, 6, 1, "5 rows");
    /* empty, and only comments */
    expect_error("", NULL, 1, 1, "0 bytes");
    expect_error("# nothing here\n\n# at all\n", NULL, 3, 1, "bytes");
    /* a single column */
    expect_error("strain_percent\n0\n1\n", NULL, 1, 1, "'strain_percent'");
    /* blank-separated columns are read, so a missing unit is found in the second column */
    expect_error("strain stress\n0 0\n", NULL, 1, 2, "'stress'");
    /* a spreadsheet saved as such: told to save it as CSV */
    expect_error("PK\003\004\024\000\006\000", NULL, 1, 1, "save the sheet as CSV");
    /* broken quoting */
    expect_error(with_header("strain,\"stress_kPa"), NULL, 1, 2, "unterminated");
    /* weights must be > 0 */
    expect_error("strain,stress_kPa,weight\n0,0,1\n0.1,1,1\n0.2,2,0\n0.3,3,1\n0.4,4,1\n0.5,5,1\n",
                 NULL, 4, 3, "'0'");
    expect_error("strain,stress_kPa,weight\n0,0,1\n0.1,1,1\n0.2,2,1\n0.3,3,-2\n0.4,4,1\n0.5,5,1\n",
                 NULL, 5, 3, "'-2'");
    /* a column name that is empty */
    expect_error(with_header("strain,,stress_kPa"), NULL, 1, 2, "no name");
}

static void binary_content_is_refused(void **state)
{
    (void)state;
    static const char nul[] = "strain,stress_kPa\n0,0\n0.1,\0001\n0.2,2\n0.3,3\n0.4,4\n0.5,5\n";
    expect_error_bytes(nul, sizeof nul - 1, NULL, CF_E_DATA, 3, 5, "0x00");
    static const char ff[] = "strain,stress_kPa\n0,0\n0.1,1\n0.2,2\xff\xfe\n0.3,3\n0.4,4\n0.5,5\n";
    expect_error_bytes(ff, sizeof ff - 1, NULL, CF_E_DATA, 4, 6, "0xFF");
    /* control bytes in the header (in a comment they are allowed: test_table_habits.c) */
    static const char ctl[] = "strain,\x01\x02\x03\n0,0\n";
    expect_error_bytes(ctl, sizeof ctl - 1, NULL, CF_E_DATA, 1, 8, "0x01");
    /* a truncated UTF-8 sequence */
    static const char cut[] = "strain,stress [\xc2]\n0,0\n";
    expect_error_bytes(cut, sizeof cut - 1, NULL, CF_E_DATA, 1, 16, "0xC2");
    /* a real binary file: random bytes with NULs */
    unsigned char junk[512];
    for (size_t i = 0; i < sizeof junk; i++)
        junk[i] = (unsigned char)((i * 2654435761u) >> 13);
    junk[0] = 0;
    expect_error_bytes((const char *)junk, sizeof junk, NULL, CF_E_DATA, 1, 1, "binary");
}

static void missing_file_is_noinput(void **state)
{
    (void)state;
    cf_error err = {0};
    cf_table m;
    char path[512];
    snprintf(path, sizeof path, "%s/does-not-exist.csv", tmpdir);
    assert_int_equal(cf_measure_load(path, NULL, &m, &err), CF_E_NOINPUT);
    assert_non_null(strstr(err.msg, "does-not-exist.csv"));
    assert_null(m.x);
    assert_int_equal(cf_exit_code(err.status), 66);
    cf_table_free(&m); /* safe on the zeroed result */
    cf_table_free(NULL);
}

/* ---- the published tables ------------------------------------------------------------------ */

static void all_published_tables_load_with_their_units(void **state)
{
    (void)state;
    const char *dir = tu_datasets();
    if (!dir) {
        print_message("skipped: ../shared/datasets is absent\n");
        skip();
    }
    static const struct {
        const char *file;
        cf_table_kind kind;
        const char *yunit;
        size_t count;
        int compression, has_time;
        double last_x, last_y; /* in conifit units: strain or mm, MPa or N */
    } t[] = {
        {"brain_cortex_compression.csv", CF_TABLE_STRESS_STRAIN, "kPa", 17, 1, 0, -0.1,
         -1.1484e-3},
        {"brain_cortex_tension.csv", CF_TABLE_STRESS_STRAIN, "kPa", 17, 0, 0, 0.1, 0.4151e-3},
        {"brain_cortex_shear.csv", CF_TABLE_STRESS_STRAIN, "kPa", 17, 0, 0, 0.2, 0.5435e-3},
        {"brain_coronaradiata_compression.csv", CF_TABLE_STRESS_STRAIN, "kPa", 17, 1, 0, -0.1,
         -0.7591e-3},
        {"brain_coronaradiata_tension.csv", CF_TABLE_STRESS_STRAIN, "kPa", 17, 0, 0, 0.1,
         0.1582e-3},
        {"treloar1944_rubber_uniaxial.csv", CF_TABLE_STRESS_STRAIN, "MPa", 25, 0, 0, 6.69, 6.33},
        {"heart_myocardium_shear_fs.csv", CF_TABLE_STRESS_STRAIN, "kPa", 11, 0, 0, 0.5,
         5.783e-3},
        {"heart_myocardium_biaxial_1to1_fiber.csv", CF_TABLE_STRESS_STRAIN, "kPa", 11, 0, 0, 0.1,
         8.257e-3},
        {"skin_porcine_stripbiaxial_x.csv", CF_TABLE_STRESS_STRAIN, "MPa", 100, 0, 0, NAN, NAN},
        {"thrombus_pureshear_force_displacement.csv", CF_TABLE_FORCE_DISPLACEMENT, "mN", 1068, 0,
         0, 5.0025, 0.4766442},
        {"muscle_compression_relaxation_fiber30.csv", CF_TABLE_STRESS_STRAIN, "kPa", 50, 1, 1,
         NAN, NAN},
        {"muscle_compression_relaxation_crossfiber30.csv", CF_TABLE_STRESS_STRAIN, "kPa", 50, 1,
         1, NAN, NAN},
    };
    for (size_t k = 0; k < sizeof t / sizeof t[0]; k++) {
        char path[512];
        cf_table m;
        cf_error err = {0};
        snprintf(path, sizeof path, "%s/%s", dir, t[k].file);
        cf_status st = cf_measure_load(path, NULL, &m, &err);
        if (st != CF_OK)
            fail_msg("%s: %s", t[k].file, err.msg);
        assert_int_equal(m.kind, t[k].kind);
        assert_string_equal(m.y_unit, t[k].yunit);
        assert_int_equal(m.count, t[k].count);
        assert_int_equal(m.compression, t[k].compression);
        assert_int_equal(m.t != NULL, t[k].has_time);
        if (t[k].kind == CF_TABLE_STRESS_STRAIN)
            assert_string_equal(m.x_column, "strain");
        if (!isnan(t[k].last_x)) {
            assert_close(m.x[m.count - 1], t[k].last_x, 1e-15);
            assert_close(m.y[m.count - 1], t[k].last_y, 1e-15 * fabs(t[k].last_y) + 1e-19);
        }
        for (size_t i = 0; i < m.count; i++)
            assert_true(isfinite(m.x[i]) && isfinite(m.y[i]) && m.w[i] == 1.0);
        cf_table_free(&m);
    }
}

/* A .txt table whose columns are separated by blanks (and TABs mixed in) reads like its CSV
** twin; a unit decoration "[kPa]" after a name stays with it. */
static void blank_separated_tables_are_read(void **state)
{
    (void)state;
    cf_table m;
    load_ok("# specimen 2\nstrain   stress [kPa] weight\n0 0 1\n0.1  1.5 1\n0.2\t3 2\n"
            "0.3 4.5 1 # a comment\n0.4 6 1\n  0.5 7.5 1\n",
            NULL, &m);
    assert_int_equal(m.count, 6);
    assert_int_equal(m.kind, CF_TABLE_STRESS_STRAIN);
    assert_string_equal(m.y_column, "stress [kPa]");
    assert_string_equal(m.y_unit, "kPa");
    assert_close(m.y[5], 7.5e-3, 1e-18);
    assert_close(m.w[2], 2, 0);
    cf_table_free(&m);
    /* a short row is still a short row */
    expect_error("strain stress_kPa\n0 0\n0.1\n0.2 2\n0.3 3\n0.4 4\n0.5 5\n0.6 6\n", NULL, 3, 2,
                 "'0.1'");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(stress_units_are_read_from_every_decoration),
        cmocka_unit_test(force_and_length_units_make_a_force_displacement_table),
        cmocka_unit_test(options_override_and_supply_units),
        cmocka_unit_test(percent_strain_is_divided_by_100),
        cmocka_unit_test(semicolon_tab_and_decimal_comma_are_read),
        cmocka_unit_test(quoted_fields_with_escaped_quotes_are_read),
        cmocka_unit_test(bom_crlf_comments_and_blank_lines_are_skipped),
        cmocka_unit_test(trailing_delimiter_is_accepted_when_every_line_has_it),
        cmocka_unit_test(weight_column_is_read),
        cmocka_unit_test(stretch_is_converted_to_strain),
        cmocka_unit_test(columns_are_chosen_by_name_in_a_wider_table),
        cmocka_unit_test(repeated_strains_are_kept_and_sign_is_reported),
        cmocka_unit_test(units_stated_in_comments_are_honoured),
        cmocka_unit_test(unit_lookup_knows_classes_and_factors),
        cmocka_unit_test(bad_tables_fail_with_line_column_and_value),
        cmocka_unit_test(blank_separated_tables_are_read),
        cmocka_unit_test(binary_content_is_refused),
        cmocka_unit_test(missing_file_is_noinput),
        cmocka_unit_test(all_published_tables_load_with_their_units),
    };
    return cmocka_run_group_tests_name("measure", tests, setup_tmpdir, remove_tmpdir);
}
