/*
** Tests of the measured table as a type (src/model/table.c): built from arrays (copies, weights 1
** unless given, names and units of the kind), named, released (twice, and NULL).
*/
#include "testutil.h"

#include "model/table.h"

static void arrays_are_copied_with_names_and_units_of_their_kind(void **state)
{
    (void)state;
    double x[3] = {0.0, 0.1, 0.2}, y[3] = {0.0, 1.5, 4.0}, w[3] = {1.0, 2.0, 0.5};
    cf_table m, f;
    cf_error err = {0};
    assert_int_equal(cf_table_from_arrays(CF_TABLE_STRESS_STRAIN, 3, x, y, NULL, &m, &err), CF_OK);
    assert_int_equal(cf_table_from_arrays(CF_TABLE_FORCE_DISPLACEMENT, 3, x, y, w, &f, &err), 0);
    x[1] = y[1] = 99.0;
    assert_true(m.count == 3 && m.x[1] == 0.1 && m.y[1] == 1.5 && m.w[2] == 1.0 && !m.t);
    assert_true(m.y_to_file == 1.0 && !cf_table_is_force(&m) && cf_table_is_force(&f));
    assert_true(f.w[1] == 2.0 && f.w[2] == 0.5);
    assert_string_equal(m.path, "(table in memory)");
    assert_true(!strcmp(m.x_column, "x") && !strcmp(m.y_column, "y"));
    assert_true(!strcmp(m.x_unit, "-") && !strcmp(m.y_unit, "MPa"));
    assert_true(!strcmp(f.x_unit, "mm") && !strcmp(f.y_unit, "N"));
    cf_table_free(&f);
    cf_table_free(&m);
    assert_true(!m.x && !m.y && !m.w && m.count == 0);
    cf_table_free(&m);
    cf_table_free(NULL);
}

/* compression = 1 only when some x < 0 and none > 0; an empty table is not in compression. */
static void compression_needs_a_negative_x_and_no_positive_one(void **state)
{
    (void)state;
    static const double x[][3] = {{0, -0.1, -0.2}, {-0.1, -0.2, -0.3}, {-0.1, 0, 0.1},
                                  {0, 0.1, 0.2},   {0, 0, 0},          {-1, -1, -1}};
    static const size_t count[] = {3, 3, 3, 3, 3, 0};
    static const int compression[] = {1, 1, 0, 0, 0, 0};
    for (size_t k = 0; k < sizeof count / sizeof count[0]; k++) {
        cf_table m;
        cf_error err = {0};
        cf_status st = cf_table_from_arrays(CF_TABLE_STRESS_STRAIN, count[k], x[k], x[k], NULL, &m,
                                            &err);
        assert_int_equal(st, CF_OK);
        if (m.compression != compression[k])
            fail_msg("case %zu: compression %d, expected %d", k, m.compression, compression[k]);
        cf_table_free(&m);
    }
}

static void the_name_is_the_file_without_folder_and_extension(void **state)
{
    (void)state;
    static const char *const c[][2] = {{"data/series/creep.csv", "creep"}, {"/t/a.b.csv", "a.b"},
                                       {"plain", "plain"}, {"d/.hidden", ".hidden"},
                                       {"longer.csv", "long"}};
    for (size_t k = 0; k < sizeof c / sizeof c[0]; k++) {
        cf_table m = {0};
        char out[64];
        snprintf(m.path, sizeof m.path, "%s", c[k][0]);
        cf_table_name(&m, out, k == 4 ? 5 : sizeof out);
        assert_string_equal(out, c[k][1]);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(arrays_are_copied_with_names_and_units_of_their_kind),
        cmocka_unit_test(compression_needs_a_negative_x_and_no_positive_one),
        cmocka_unit_test(the_name_is_the_file_without_folder_and_extension),
    };
    return cmocka_run_group_tests_name("table", tests, NULL, NULL);
}
