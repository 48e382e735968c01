/*
** No nan or inf in what the commands print: force, curve, info and synth on hard springs (the
** corners of the field table's bounds that the law accepts, nearly cylindrical and strongly
** conical springs, huge and tiny G) at hard displacements (solid and one ulp either side of it,
** one ulp either side of u_T, the smallest subnormal, -1e300), with the evaluators. Each run must
** succeed, and any "nan" or "inf" on standard output fails the test, naming the command.
*/
#include <ctype.h>
#include <math.h>
#include <strings.h>

#include "testutil.h"

#include "model/law_internal.h"

static char out[1 << 20], errb[1 << 14];

/* 1 when text holds the word nan, inf or infinity in any letter case, as printf writes them
** (names that merely contain the letters, such as "infeasible" or "g_inf", do not count). */
static int has_nonfinite(const char *text)
{
    for (const char *p = text; *p; p++) {
        if (p > text && (isalnum((unsigned char)p[-1]) || p[-1] == '_'))
            continue;
        size_t n = strncasecmp(p, "infinity", 8) == 0 ? 8
                   : strncasecmp(p, "nan", 3) == 0 || strncasecmp(p, "inf", 3) == 0 ? 3
                                                                                   : 0;
        if (n && !isalnum((unsigned char)p[n]) && p[n] != '_')
            return 1;
    }
    return 0;
}

static int checked;

/* Runs one command on a spring the law accepts: it must succeed (a subnormal --u was refused as
** "not a finite number") and print only finite numbers. */
static void scan(const char *args)
{
    int st = tu_run(out, sizeof out, errb, sizeof errb, "%s", args);
    if (st != 0)
        fail_msg("conifit %s: exit %d: %s", args, st, errb);
    if (has_nonfinite(out))
        fail_msg("conifit %s printed a non-finite number:\n%.2000s", args, out);
    checked++;
}

static void commands_print_only_finite_numbers(void **state)
{
    (void)state;
    /* the scan itself */
    assert_true(has_nonfinite("1,nan,2") && has_nonfinite("-inf\n") && has_nonfinite("NaN") &&
                has_nonfinite("x = -Infinity"));
    assert_false(has_nonfinite("infeasible, financial, g_inf = 0.2, 1e-300"));
    static const double corner[6][2] = {{1e-6, 1e6},  {1e-6, 1e9},   {2, 1e7},
                                        {1e-7, 1e5},  {1e-15, 1e15}, {1e-6, 1e6}};
    /* the corners of the bounds, and springs named for what makes them hard */
    cf_spring springs[64 + 8];
    int ns = 0;
    for (int m = 0; m < 64; m++) {
        double v[6];
        for (int k = 0; k < 6; k++)
            v[k] = corner[k][(m >> k) & 1];
        springs[ns++] = (cf_spring){v[0], v[1], v[2], v[3], v[4], v[5]};
    }
    springs[ns++] = (cf_spring){1 - 1e-12, 1, 2, 0.01, 100, 10};  /* nearly cylindrical */
    springs[ns++] = (cf_spring){1e-3, 1, 2, 1e-4, 100, 10};       /* strongly conical */
    springs[ns++] = (cf_spring){10, 30, 4, 1, 1e15, 40};          /* huge G */
    springs[ns++] = (cf_spring){10, 30, 4, 1, 1e-15, 40};         /* tiny G */
    springs[ns++] = (cf_spring){10, 30, 1e4, 1e-3, 80000, 40};    /* many coils */
    springs[ns++] = (cf_spring){1e-6, 1e-6 * (1 + 1e-9), 2, 1e-7, 1e15, 1e-6};
    static const char *const methods[] = {"exact", "closed", "closed+newton", "table"};
    int laws = 0;
    for (int i = 0; i < ns; i++) {
        const cf_spring *p = &springs[i];
        cf_law law;
        cf_error err = {0};
        if (cf_law_init(&law, p, &err) != CF_OK)
            continue; /* refused as a spring: the commands refuse it too (exit 2) */
        laws++;
        char sp[400];
        snprintf(sp, sizeof sp, "--D1 %.17g --D2 %.17g --n %.17g --d %.17g --G %.17g --H %.17g",
                 p->D1_mm, p->D2_mm, p->n, p->d_mm, p->G_MPa, p->H_mm);
        const double s = law.travel_mm, uT = law.u_T_mm;
        const double us[] = {nextafter(s, 0),  s,      nextafter(s, INFINITY), nextafter(uT, 0),
                             nextafter(uT, INFINITY), 5e-324, -1e300};
        char args[800];
        /* every evaluator on the named springs; the fitter's two on the corners */
        for (int m = 0; m < (i < 64 ? 2 : 4); m++) {
            for (size_t j = 0; j < sizeof us / sizeof us[0]; j++) {
                snprintf(args, sizeof args, "force %s --u %.17g --method %s", sp, us[j],
                         methods[m]);
                scan(args);
            }
            snprintf(args, sizeof args, "curve %s --points 9 --method %s", sp, methods[m]);
            scan(args);
        }
        snprintf(args, sizeof args, "info %s", sp);
        scan(args);
        snprintf(args, sizeof args, "synth %s --points 9 --spacing solid", sp);
        scan(args);
        snprintf(args, sizeof args, "synth %s --points 9 --compression --noise 0.01", sp);
        scan(args);
        cf_law_free(&law);
    }
    print_message("%d springs the law accepts; %d runs scanned\n", laws, checked);
    assert_true(laws >= 10);
    assert_true(checked > 100);
}

/* The reports and files of the other commands that print numbers: fit (every shipped table and
** series, hard ones among them: a spring on rho_min, one through the lattice's cell), export in
** every format of a fit at a limit, simulate's summary of a dashpot cycle. */
static void reports_print_only_finite_numbers(void **state)
{
    (void)state;
    static const char *const runs[] = {
        "fit data/telescoping.csv",
        "fit data/strongly_conical.csv",
        "fit data/nearly_cylindrical.csv --target lattice",
        "fit data/telescoping_compression.csv --validate",
        "fit data/series/synthetic_relaxation_noise1pct.csv --branches 1",
        "export fits/strongly_conical.json --format json",
        "export fits/strongly_conical.json --format csv",
        "export fits/strongly_conical.json --format calculix --example",
        "export fits/strongly_conical.json --format abaqus --example",
        "export fits/strongly_conical.json --format febio --example",
        "export fits/strongly_conical.json --format lsdyna --example",
        "export fits/strongly_conical.json --format sofa",
        "info --spring fits/nearly_cylindrical.json:telescoping",
    };
    for (size_t i = 0; i < sizeof runs / sizeof runs[0]; i++)
        scan(runs[i]);
    char dir[] = "/tmp/conifit-finite-XXXXXX", sc[300];
    assert_non_null(mkdtemp(dir));
    snprintf(sc, sizeof sc, "%s/s.json", dir);
    FILE *f = fopen(sc, "w");
    assert_non_null(f);
    fprintf(f, "{\"spring\": {\"params\": {\"D1_mm\": 6, \"D2_mm\": 15, \"n\": 2.5, \"d_mm\": 2, "
               "\"G_MPa\": 26, \"H_mm\": 10}}, \"lattice\": {\"nx\": 1, \"ny\": 1, \"nz\": 1},"
               " \"protocol\": {\"kind\": \"cycles\", \"to_strain\": 0.2, \"period_s\": 10,"
               " \"count\": 1}, \"effects\": {\"damping\": {\"eta_kPa_s\": 5}},"
               " \"samples_per_segment\": 10}\n");
    fclose(f);
    char args[400];
    snprintf(args, sizeof args, "simulate %s -o -", sc);
    scan(args);
    remove(sc);
    rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(commands_print_only_finite_numbers),
        cmocka_unit_test(reports_print_only_finite_numbers),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
