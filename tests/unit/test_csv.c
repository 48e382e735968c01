/*
** Tests of the lexer of measurement tables (src/io/csv.c) on its own: fields and their quoting,
** the delimiter of a header, comments, cells as numbers, bytes that are not text, and the
** printable quotations and names that messages and reports carry. The reader's tests
** (test_measure.c) check the same rules through whole tables.
*/
#include "testutil.h"

#include "io/csv.h"

/* Splits s and checks the fields, joined with '|', or the column (from 1) and reason of a
** refusal. */
static void split_is(const char *s, char delim, const char *fields, size_t bad, const char *why)
{
    cf_csv_fields f = {0};
    size_t bad_col = 0;
    const char *reason = NULL;
    int rc = cf_csv_split(s, strlen(s), delim, &f, &bad_col, &reason);
    if (!fields) {
        assert_int_equal(rc, -1);
        assert_int_equal(bad_col, bad);
        assert_string_equal(reason, why);
    } else {
        char joined[256] = "";
        assert_int_equal(rc, 0);
        for (size_t i = 0; i < f.count; i++)
            snprintf(joined + strlen(joined), sizeof joined - strlen(joined), "%s%s", i ? "|" : "",
                     cf_csv_field(&f, i));
        assert_string_equal(joined, fields);
    }
    cf_csv_fields_free(&f);
}

static void fields_are_split_and_unquoted(void **state)
{
    (void)state;
    split_is("a, b ,c", ',', "a|b|c", 0, NULL);
    split_is("\"x, \"\"y\"\"\" ,2,", ',', "x, \"y\"|2|", 0, NULL);
    split_is("1;;3", ';', "1||3", 0, NULL);
    split_is("a b\t c", '\t', "a b|c", 0, NULL);
    split_is("strain  stress [kPa]\t\"w 1\"", ' ', "strain|stress [kPa]|w 1", 0, NULL);
    split_is("a,\"b", ',', NULL, 2, "unterminated double quote");
    split_is("a,\"b\" c", ',', NULL, 2, "text after a closing double quote");
    split_is("a,b\"c", ',', NULL, 2, "double quote inside an unquoted field");
    split_is("a b\"c", ' ', NULL, 2, "double quote inside an unquoted field");
}

static void delimiters_comments_and_content_are_found(void **state)
{
    (void)state;
    assert_int_equal(cf_csv_delimiter("a,b;c", 5), ',');   /* a tie goes to ',' */
    assert_int_equal(cf_csv_delimiter("a;b\tc", 5), ';');  /* then to ';' */
    assert_int_equal(cf_csv_delimiter("a\tb\tc;d", 7), '\t');
    assert_int_equal(cf_csv_delimiter("\"a,b\";c", 7), ';'); /* quoted commas do not count */
    assert_int_equal(cf_csv_delimiter("strain stress", 13), ' ');
    assert_int_equal(cf_csv_delimiter("stress [kPa]", 12), 0);
    const char *line = "1,\"#2\" # note  ";
    assert_int_equal(cf_csv_content_length(line, strlen(line)), 6);
    cf_csv_line comment = {"  \t# x", 6, 1}, data = {"1,2 # x", 7, 2};
    assert_true(cf_csv_is_comment(&comment));
    assert_false(cf_csv_is_comment(&data));
    char t[8];
    cf_csv_trim_copy(t, sizeof t, "  stress kPa ", 13);
    assert_string_equal(t, "stress ");
}

static void cells_are_finite_decimal_numbers(void **state)
{
    (void)state;
    double v = 0.0;
    assert_int_equal(cf_csv_number("-1.5e-3", ',', &v), CF_CSV_NUM_OK);
    assert_close(v, -1.5e-3, 0.0);
    assert_int_equal(cf_csv_number("2,5", ';', &v), CF_CSV_NUM_OK); /* decimal comma */
    assert_close(v, 2.5, 0.0);
    assert_int_equal(cf_csv_number("2,5", ',', &v), CF_CSV_NUM_NOT_NUMBER);
    assert_int_equal(cf_csv_number("1,5,5", ';', &v), CF_CSV_NUM_NOT_NUMBER);
    assert_int_equal(cf_csv_number("", ',', &v), CF_CSV_NUM_EMPTY);
    assert_int_equal(cf_csv_number("0x10", ',', &v), CF_CSV_NUM_NOT_NUMBER);
    assert_int_equal(cf_csv_number("1 2", ',', &v), CF_CSV_NUM_NOT_NUMBER);
    assert_int_equal(cf_csv_number("-inf", ',', &v), CF_CSV_NUM_NOT_FINITE);
    assert_int_equal(cf_csv_number("NaN", ',', &v), CF_CSV_NUM_NOT_FINITE);
    assert_int_equal(cf_csv_number("1e999", ',', &v), CF_CSV_NUM_NOT_FINITE);
    assert_int_equal(cf_csv_number("1e-999", ',', &v), CF_CSV_NUM_OK); /* underflow: 0 */
}

static void bytes_that_are_not_text_are_found(void **state)
{
    (void)state;
    static const struct {
        const char *s;
        size_t bad;
    } c[] = {
        {"plain\ttext", 10},     {"\xc2\xb5m \xce\xbcN", 7}, {"a\rb", 1},
        {"ok\x7f", 2},           {"\xc0\xaf", 0},            {"x\xed\xa0\x80", 1},
        {"\xf4\x90\x80\x80", 0}, {"ab\xe2\x82", 2},          {"\xc2\x85", 0},
    };
    for (size_t k = 0; k < sizeof c / sizeof c[0]; k++)
        if (cf_csv_bad_byte((const unsigned char *)c[k].s, strlen(c[k].s)) != c[k].bad)
            fail_msg("case %zu: expected the bad byte at %zu", k, c[k].bad);
}

static void quotations_and_names_are_printable(void **state)
{
    (void)state;
    char q[256], n[8];
    cf_csv_quote(q, sizeof q, "a\tb\xff", 4);
    assert_string_equal(q, "a\\x09b\\xFF");
    char longer[100];
    memset(longer, 'x', sizeof longer);
    cf_csv_quote(q, sizeof q, longer, sizeof longer);
    assert_int_equal(strlen(q), 63);
    assert_string_equal(q + 60, "...");
    cf_csv_utf8_copy(n, sizeof n, "a\xff\x01\xc2\xb5m");
    assert_string_equal(n, "a??\xc2\xb5m");
    cf_csv_utf8_copy(n, 7, "abcde\xc2\xb5");
    assert_string_equal(n, "abcde"); /* cut before the character, not inside it */
}

/* A message points at the file, the line and the column. */
static void errors_name_the_place(void **state)
{
    (void)state;
    cf_error err = {0};
    assert_int_equal(cf_csv_error(&err, "t.csv", 3, 2, "bad ('%s')", "x"), CF_E_DATA);
    assert_string_equal(err.msg, "t.csv:3:2: bad ('x')");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(fields_are_split_and_unquoted),
        cmocka_unit_test(delimiters_comments_and_content_are_found),
        cmocka_unit_test(cells_are_finite_decimal_numbers),
        cmocka_unit_test(bytes_that_are_not_text_are_found),
        cmocka_unit_test(quotations_and_names_are_printable),
        cmocka_unit_test(errors_name_the_place),
    };
    return cmocka_run_group_tests_name("csv", tests, NULL, NULL);
}
