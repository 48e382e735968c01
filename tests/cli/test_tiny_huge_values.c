/*
** Tiny, huge and denormal values in a table: stresses or weights that would underflow the fit's
** sums of squares and strains no spring could follow are refused (exit 65) naming the data point;
** one huge outlier below the documented limit (1e100) fits (never exit 70), and nothing any of
** them prints or writes holds a nan or an inf.
*/
#include "testutil.h"

#include <ctype.h>

static char out[1 << 16], errb[1 << 14], file[1 << 18];
TU_SCRATCH_GROUP("tinyhuge")

/* data/telescoping.csv with row i's (strain, stress) mapped by kind, into dir/NAME.csv; a weight
** column of `weight` when it is not NULL. */
static void table(const char *name, char kind, const char *weight)
{
    FILE *in = fopen("data/telescoping.csv", "rb");
    assert_non_null(in);
    char p[512], line[256];
    snprintf(p, sizeof p, "%s/%s.csv", dir, name);
    FILE *o = fopen(p, "wb");
    assert_non_null(o);
    fprintf(o, "strain,stress_kPa%s\n", weight ? ",weight" : "");
    int row = 0;
    while (fgets(line, sizeof line, in)) {
        double x, y;
        if (line[0] == '#' || sscanf(line, "%lf,%lf", &x, &y) != 2)
            continue;
        if (kind == 't')
            y *= 1e-19;
        else if (kind == 'T')
            y *= 1e-160;
        else if (kind == 'o' && row == 30)
            y = 1e20;
        else if (kind == 'd')
            x *= 1e-310;
        fprintf(o, "%.17g,%.17g%s%s\n", x, y, weight ? "," : "", weight ? weight : "");
        row++;
    }
    fclose(in);
    assert_int_equal(fclose(o), 0);
}

/* Whether text holds "nan" or "inf" as a word (not "infeasible"). */
static int has_nonfinite(const char *text)
{
    for (const char *p = text; *p; p++) {
        const int start = p == text || !isalpha((unsigned char)p[-1]);
        if (start && (strncasecmp(p, "nan", 3) == 0 || strncasecmp(p, "inf", 3) == 0) &&
            !isalpha((unsigned char)p[3]))
            return 1;
    }
    return 0;
}

static void read_file(const char *name)
{
    char p[512];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    FILE *f = fopen(p, "rb");
    file[0] = '\0';
    if (!f)
        return;
    size_t n = fread(file, 1, sizeof file - 1, f);
    file[n] = '\0';
    fclose(f);
}

/* Refused with 65 naming the data point, with and without -o, writing nothing. */
static void refused(const char *name, const char *what)
{
    for (int with_o = 0; with_o < 2; with_o++) {
        char o[600] = "";
        if (with_o)
            snprintf(o, sizeof o, "-o %s/%s.json", dir, name);
        const int st = tu_run(out, sizeof out, errb, sizeof errb, "fit %s/%s.csv %s", dir, name, o);
        if (st != 65 || !strstr(errb, "data point") || !strstr(errb, what))
            fail_msg("%s%s: exit %d: %s", name, with_o ? " -o" : "", st, errb);
        assert_false(has_nonfinite(out) || has_nonfinite(errb));
    }
    char json[128];
    snprintf(json, sizeof json, "%s.json", name);
    read_file(json);
    assert_true(file[0] == '\0'); /* nothing written */
}

static void underflowing_tables_are_refused_naming_the_point(void **state)
{
    (void)state;
    table("tiny19", 't', NULL); /* stresses below 1e-18 kPa */
    refused("tiny19", "stress_kPa");
    table("tiny160", 'T', NULL);
    refused("tiny160", "stress_kPa");
    table("wdenorm", 'w', "5e-324"); /* equal denormal weights */
    refused("wdenorm", "weight");
    table("dstrain", 'd', NULL); /* denormal strains */
    refused("dstrain", "strain");
}

/* One outlier of 1e20 kPa, far below the documented limit of 1e100: a fit, with -o and without,
** whose report and file hold only finite numbers. */
static void a_huge_outlier_fits_with_finite_numbers(void **state)
{
    (void)state;
    table("outlier", 'o', NULL);
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb, "fit %s/outlier.csv", dir), 0);
    assert_false(has_nonfinite(out));
    assert_false(has_nonfinite(errb));
    assert_int_equal(tu_run(out, sizeof out, errb, sizeof errb,
                            "fit %s/outlier.csv -o %s/outlier.json", dir, dir),
                     0);
    assert_false(has_nonfinite(out));
    read_file("outlier.json");
    assert_true(file[0] != '\0');
    assert_false(has_nonfinite(file));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(underflowing_tables_are_refused_naming_the_point),
        cmocka_unit_test(a_huge_outlier_fits_with_finite_numbers),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
