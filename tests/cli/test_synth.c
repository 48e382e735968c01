/*
** Tests of `conifit synth`: the table it writes holds the law in kPa (in tension and in
** compression), its noise is deterministic and of the asked size, bad requests write nothing, and
** the example tables shipped in data/ are re-synthesised from the command each one documents and
** come from springs the fitter accepts.
*/
#include <sys/stat.h>

#include "testutil.h"

#include "model/law_internal.h"
#include "io/measure.h"

TU_SCRATCH_GROUP("synth")

static char out_buf[8192], err_buf[8192];

static int file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

static void synth_writes_the_law_in_kpa(void **state)
{
    (void)state;
    char path[512];
    snprintf(path, sizeof path, "%s/synth-tel.csv", dir);
    /* k0 = G d^4 / (2 n (D1 + D2)(D1^2 + D2^2)) = 100 16 / (2 2.5 28 464) = 1600/64960 N/mm;
    ** region 1 ends at strain u_T/H = 0.6 (1.4)(1.16)/4 = 0.2436 */
    int rc = tu_run(out_buf, sizeof out_buf, err_buf, sizeof err_buf,
                    "synth --D1 8 --D2 20 --n 2.5 --d 2 --G 100 --H 5 --strain-max 0.5 "
                    "--points 11 -o %s", path);
    assert_int_equal(rc, 0);
    cf_table m;
    cf_error err = {0};
    assert_int_equal(cf_measure_load(path, NULL, &m, &err), CF_OK);
    assert_int_equal(m.count, 11);
    assert_string_equal(m.y_unit, "kPa");
    const double k0 = 1600.0 / 64960.0;
    for (size_t i = 0; i <= 4; i++) { /* strains 0 .. 0.2: linear, sigma = k0 eps / H (MPa) */
        assert_close(m.x[i], 0.05 * (double)i, 1e-16);
        assert_close(m.y[i], k0 * m.x[i] / 5.0, 1e-15 * k0);
    }
    /* beyond the transition the law stiffens: stress above the linear extrapolation, and the
    ** points agree with the law itself */
    cf_spring p = {8, 20, 2.5, 2, 100, 5};
    cf_law law;
    assert_int_equal(cf_law_init(&law, &p, &err), CF_OK);
    for (size_t i = 5; i < 11; i++) {
        assert_true(m.y[i] > k0 * m.x[i] / 5.0);
        double F = cf_law_force(&law, CF_LAW_EXACT, m.x[i] * 5.0, NULL, NULL);
        assert_close(m.y[i], F / 25.0, 1e-14 * F);
    }
    assert_close(m.x[10], 0.5, 0.0);
    cf_table_free(&m);
    /* compression: the same table with both signs flipped */
    char cpath[512];
    snprintf(cpath, sizeof cpath, "%s/synth-comp.csv", dir);
    rc = tu_run(NULL, 0, err_buf, sizeof err_buf,
                "synth --D1 8 --D2 20 --n 2.5 --d 2 --G 100 --H 5 --strain-max 0.5 --points 11 "
                "--compression -o %s", cpath);
    assert_int_equal(rc, 0);
    cf_table c, t;
    assert_int_equal(cf_measure_load(cpath, NULL, &c, &err), CF_OK);
    assert_int_equal(cf_measure_load(path, NULL, &t, &err), CF_OK);
    assert_int_equal(c.compression, 1);
    for (size_t i = 0; i < 11; i++) {
        assert_close(c.x[i], -t.x[i], 0.0);
        assert_close(c.y[i], -t.y[i], 0.0);
    }
    cf_table_free(&c);
    cf_table_free(&t);
}

static void synth_noise_is_deterministic_and_of_the_asked_size(void **state)
{
    (void)state;
    const char *spring = "--D1 5 --D2 12 --n 4 --d 1.25 --G 500 --H 10 --points 400";
    char a[512], b[512], c[512], z[512];
    snprintf(a, sizeof a, "%s/noise-a.csv", dir);
    snprintf(b, sizeof b, "%s/noise-b.csv", dir);
    snprintf(c, sizeof c, "%s/noise-c.csv", dir);
    snprintf(z, sizeof z, "%s/noise-0.csv", dir);
    assert_int_equal(tu_run(NULL, 0, NULL, 0, "synth %s --noise 0.01 --seed 7 -o %s", spring, a),
                     0);
    assert_int_equal(tu_run(NULL, 0, NULL, 0, "synth %s --noise 0.01 --seed 7 -o %s", spring, b),
                     0);
    assert_int_equal(tu_run(NULL, 0, NULL, 0, "synth %s --noise 0.01 --seed 8 -o %s", spring, c),
                     0);
    assert_int_equal(tu_run(NULL, 0, NULL, 0, "synth %s -o %s", spring, z), 0);
    cf_table ma, mb, mc, mz;
    cf_error err = {0};
    assert_int_equal(cf_measure_load(a, NULL, &ma, &err), CF_OK);
    assert_int_equal(cf_measure_load(b, NULL, &mb, &err), CF_OK);
    assert_int_equal(cf_measure_load(c, NULL, &mc, &err), CF_OK);
    assert_int_equal(cf_measure_load(z, NULL, &mz, &err), CF_OK);
    double smax = 0.0, sum = 0.0, sum2 = 0.0;
    int differ = 0;
    for (size_t i = 0; i < mz.count; i++)
        smax = fmax(smax, fabs(mz.y[i]));
    for (size_t i = 0; i < mz.count; i++) {
        assert_close(ma.y[i], mb.y[i], 0.0);
        assert_close(ma.x[i], mz.x[i], 0.0);
        differ |= ma.y[i] != mc.y[i];
        double r = (ma.y[i] - mz.y[i]) / smax;
        sum += r;
        sum2 += r * r;
    }
    assert_true(differ);
    double n = (double)mz.count, mean = sum / n, sd = sqrt(sum2 / n - mean * mean);
    /* 400 draws: the sample sd is within 15 % of 0.01 and the mean within 4 standard errors,
    ** with overwhelming probability for any seed (and this seed is fixed) */
    assert_close(sd, 0.01, 0.0015);
    assert_close(mean, 0.0, 4 * 0.01 / sqrt(n));
    cf_table_free(&ma);
    cf_table_free(&mb);
    cf_table_free(&mc);
    cf_table_free(&mz);
}

static void synth_refuses_bad_requests_without_writing(void **state)
{
    (void)state;
    char path[512];
    snprintf(path, sizeof path, "%s/never.csv", dir);
    const char *sp = "--D1 8 --D2 20 --n 2.5 --d 2 --G 100 --H 5";
    assert_int_equal(tu_run(NULL, 0, err_buf, sizeof err_buf, "synth %s --points", sp), 2);
    assert_non_null(strstr(err_buf, "--points"));
    assert_int_equal(tu_run(NULL, 0, err_buf, sizeof err_buf, "synth %s --bogus", sp), 2);
    assert_non_null(strstr(err_buf, "'--bogus'"));
    assert_int_equal(
        tu_run(NULL, 0, err_buf, sizeof err_buf, "synth %s --strain-max 0.6 -o %s", sp, path), 2);
    assert_non_null(strstr(err_buf, "0.6"));
    assert_int_equal(
        tu_run(NULL, 0, err_buf, sizeof err_buf, "synth %s --stress-unit mpa -o %s", sp, path), 2);
    assert_non_null(strstr(err_buf, "'mpa'"));
    assert_int_equal(tu_run(NULL, 0, err_buf, sizeof err_buf,
                            "synth --D1 8 --D2 20 --n 2.5 --d 2 --G 100 -o %s", path),
                     2);
    assert_non_null(strstr(err_buf, "--H"));
    assert_int_equal(
        tu_run(NULL, 0, err_buf, sizeof err_buf, "synth %s --noise -1 -o %s", sp, path), 2);
    assert_false(file_exists(path));
    char nodir[600];
    snprintf(nodir, sizeof nodir, "%s/no/such/dir/t.csv", dir);
    assert_int_equal(tu_run(NULL, 0, err_buf, sizeof err_buf, "synth %s -o %s", sp, nodir), 73);
    assert_false(file_exists(nodir));
    assert_int_equal(tu_run(out_buf, sizeof out_buf, NULL, 0, "synth --help"), 0);
    assert_non_null(strstr(out_buf, "--strain-max"));
    assert_non_null(strstr(out_buf, "--D1"));
}

/* Re-runs the command documented in a shipped table's '# command:' line and compares. */
static void shipped_table_is_reproduced_by_its_documented_command(void **state)
{
    (void)state;
    static const char *const shipped[] = {"data/telescoping.csv", "data/non_telescoping.csv",
                                          "data/telescoping_noise1pct.csv"};
    for (size_t k = 0; k < sizeof shipped / sizeof shipped[0]; k++) {
        FILE *f = fopen(shipped[k], "r");
        if (!f)
            fail_msg("%s is missing (run the tests from the repository root)", shipped[k]);
        char line[1024], args[1024] = "";
        while (fgets(line, sizeof line, f))
            if (strncmp(line, "# command: conifit ", 19) == 0) {
                snprintf(args, sizeof args, "%s", line + 19);
                args[strcspn(args, "\n")] = '\0';
                break;
            }
        fclose(f);
        assert_true(args[0] != '\0');
        char path[512];
        snprintf(path, sizeof path, "%s/again-%zu.csv", dir, k);
        assert_int_equal(tu_run(NULL, 0, err_buf, sizeof err_buf, "%s -o %s", args, path), 0);
        cf_table a, b;
        cf_error err = {0};
        assert_int_equal(cf_measure_load(shipped[k], NULL, &a, &err), CF_OK);
        assert_int_equal(cf_measure_load(path, NULL, &b, &err), CF_OK);
        assert_int_equal(a.count, b.count);
        assert_true(a.count >= 40);
        for (size_t i = 0; i < a.count; i++) {
            assert_close(a.x[i], b.x[i], 1e-15);
            assert_close(a.y[i], b.y[i], 1e-13 * fabs(a.y[i]) + 1e-18);
        }
        cf_table_free(&a);
        cf_table_free(&b);
    }
}

/* Every shipped table is a valid conical spring by the fitter's rules: index >= 3, n >= 2. */
static void shipped_tables_come_from_valid_springs(void **state)
{
    (void)state;
    static const char *const shipped[] = {
        "data/telescoping.csv",         "data/telescoping_noise1pct.csv",
        "data/telescoping_compression.csv", "data/non_telescoping.csv",
        "data/non_telescoping_noise1pct.csv", "data/nearly_cylindrical.csv",
        "data/strongly_conical.csv"};
    int types[2] = {0, 0};
    for (size_t k = 0; k < sizeof shipped / sizeof shipped[0]; k++) {
        FILE *f = fopen(shipped[k], "r");
        if (!f)
            fail_msg("%s is missing", shipped[k]);
        char line[1024];
        cf_spring p = {0};
        int found = 0;
        while (fgets(line, sizeof line, f))
            if (sscanf(line, "# spring: D1_mm=%lf D2_mm=%lf n=%lf d_mm=%lf G_MPa=%lf H_mm=%lf",
                       &p.D1_mm, &p.D2_mm, &p.n, &p.d_mm, &p.G_MPa, &p.H_mm) == 6)
                found = 1;
        fclose(f);
        assert_true(found);
        cf_law law;
        cf_error err = {0};
        assert_int_equal(cf_law_init(&law, &p, &err), CF_OK);
        assert_true(law.index_c >= 3.0);
        assert_true(p.n >= 2.0);
        types[law.type] = 1;
        cf_table m;
        assert_int_equal(cf_measure_load(shipped[k], NULL, &m, &err), CF_OK);
        for (size_t i = 0; i < m.count; i++) /* inside the travel: never solid */
            assert_true(fabs(m.x[i]) < law.travel_mm / p.H_mm);
        cf_table_free(&m);
    }
    assert_true(types[CF_TELESCOPING] && types[CF_NON_TELESCOPING]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(synth_writes_the_law_in_kpa),
        cmocka_unit_test(synth_noise_is_deterministic_and_of_the_asked_size),
        cmocka_unit_test(synth_refuses_bad_requests_without_writing),
        cmocka_unit_test(shipped_table_is_reproduced_by_its_documented_command),
        cmocka_unit_test(shipped_tables_come_from_valid_springs),
    };
    return cmocka_run_group_tests_name("synth", tests, setup, teardown);
}
