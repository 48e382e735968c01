/*
** Tests of text made safe for messages (src/base/safetext.c) and of its use by every error
** message (cf_error_set): printable text and valid UTF-8 stay, control characters, C1 controls
** and bytes that are not UTF-8 are shown as \xNN, and a cut never splits a character or an escape.
*/
#include "testutil.h"

#include "base/safetext.h"
#include "conifit/error.h"

static void expect_safe(const char *in, size_t cap, const char *want)
{
    char out[256];
    cf_safe_text(out, cap, in, strlen(in));
    if (strcmp(out, want) != 0)
        fail_msg("cf_safe_text(\"%s\", %zu) gave \"%s\", expected \"%s\"", in, cap, out, want);
}

static void printable_text_and_utf8_stay(void **state)
{
    (void)state;
    expect_safe("data/plain_table.csv", 256, "data/plain_table.csv");
    expect_safe("Gewebe_\xc3\xa4 \xe2\x86\x92 \xf0\x9f\xa7\xaa.csv", 256,
                "Gewebe_\xc3\xa4 \xe2\x86\x92 \xf0\x9f\xa7\xaa.csv");
    expect_safe("", 256, "");
}

static void controls_and_stray_bytes_are_escaped(void **state)
{
    (void)state;
    expect_safe("a\nb\tc\rd", 256, "a\\x0Ab\\x09c\\x0Dd");
    expect_safe("\x1b[31mred\x1b]0;title\x07", 256, "\\x1B[31mred\\x1B]0;title\\x07");
    expect_safe("del\x7f", 256, "del\\x7F");
    expect_safe("\xc2\x9b" "2J", 256, "\\xC2\\x9B2J");       /* C1 control sequence introducer */
    expect_safe("23 \xb0" "C", 256, "23 \\xB0C");             /* a code page's degree sign */
    expect_safe("\xc0\xaf", 256, "\\xC0\\xAF");               /* overlong '/' */
    expect_safe("\xed\xa0\x80", 256, "\\xED\\xA0\\x80");      /* a surrogate */
    expect_safe("\xe2\x86", 256, "\\xE2\\x86");               /* cut short */
}

static void cuts_fall_between_pieces(void **state)
{
    (void)state;
    expect_safe("abcdefg", 8, "abcdefg"); /* fits exactly */
    expect_safe("abcdefghij", 8, "abcd...");
    expect_safe("\xc3\xa4\xc3\xa4\xc3\xa4\xc3\xa4", 8, "\xc3\xa4\xc3\xa4...");
    expect_safe("\x01\x02\x03", 10, "\\x01...");
    expect_safe("abcdef", 3, "ab"); /* too small for "...": cut only */
}

static void error_messages_are_safe(void **state)
{
    (void)state;
    cf_error err = {0};
    assert_int_equal(cf_error_set(&err, CF_E_NOINPUT, "%s: cannot open table: %s",
                                  "evil\n\x1b[2Jname.csv", "No such file or directory"),
                     CF_E_NOINPUT);
    assert_string_equal(err.msg,
                        "evil\\x0A\\x1B[2Jname.csv: cannot open table: No such file or directory");
    for (const char *p = err.msg; *p; p++)
        assert_true((unsigned char)*p >= 0x20 && *p != 0x7f);
    /* a long message ends in "..." within the buffer */
    char longname[2000];
    memset(longname, 'x', sizeof longname - 1);
    longname[sizeof longname - 1] = '\0';
    cf_error_set(&err, CF_E_DATA, "%s: bad", longname);
    assert_int_equal(strlen(err.msg), CF_ERROR_MSG_LEN - 1);
    assert_string_equal(err.msg + CF_ERROR_MSG_LEN - 4, "...");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(printable_text_and_utf8_stay),
        cmocka_unit_test(controls_and_stray_bytes_are_escaped),
        cmocka_unit_test(cuts_fall_between_pieces),
        cmocka_unit_test(error_messages_are_safe),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
