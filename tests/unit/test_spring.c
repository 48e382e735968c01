/*
** Tests of the spring's field table (src/model/spring.c), the one description of the design
** parameters that every reader, writer, report, export and option works from:
**  - the table is whole: names, units, keys and meanings present and unique, bounds ordered,
**    lookup by name and by key, get and set touching their own field only;
**  - the documentation's lists of the JSON keys (the fit file's "params", the scene and the
**    exported spring; README.md and the notes, in src/notes/ and beside the code) are the table's
**    keys in its order, so that renaming a key in the table and not in the documentation fails here.
*/
#include <glob.h>

#include "testutil.h"

#include "conifit/spring.h"

static void the_field_table_is_whole_and_found_by_name_and_key(void **state)
{
    (void)state;
    for (int k = 0; k < CF_P_ALL; k++) {
        const cf_spring_param *sp = cf_spring_param_info(k);
        assert_non_null(sp);
        assert_true(sp->name[0] && sp->unit[0] && sp->key[0] && sp->meaning[0]);
        /* the tail's two may be 0 (no tail); the cone's six are positive */
        assert_true(isfinite(sp->lower) && isfinite(sp->upper) &&
                    (k < CF_P_COUNT ? sp->lower > 0 : sp->lower >= 0) && sp->lower < sp->upper);
        /* the name search finds the cone's six alone (a fit places the tail with its family) */
        assert_int_equal(cf_spring_param_find(sp->name), k < CF_P_COUNT ? k : -1);
        assert_int_equal(cf_spring_param_find(sp->key), k < CF_P_COUNT ? k : -1);
        for (int j = 0; j < k; j++) {
            assert_string_not_equal(cf_spring_param_info(j)->name, sp->name);
            assert_string_not_equal(cf_spring_param_info(j)->key, sp->key);
        }
        /* set and get reach field k alone */
        cf_spring p;
        memset(&p, 0, sizeof p);
        cf_spring_set(&p, k, 1.5 + k);
        for (int j = 0; j < CF_P_ALL; j++)
            assert_close(cf_spring_get(&p, j), j == k ? 1.5 + k : 0.0, 0.0);
    }
    assert_null(cf_spring_param_info(-1));
    assert_null(cf_spring_param_info(CF_P_ALL));
    assert_int_equal(cf_spring_param_find("D3"), -1);
    assert_int_equal(cf_spring_param_find(NULL), -1);
    /* the struct's fields are the table's, in its order */
    const cf_spring s = {1, 2, 3, 4, 5, 6, 7, 8};
    for (int k = 0; k < CF_P_ALL; k++)
        assert_close(cf_spring_get(&s, k), k + 1.0, 0.0);
    assert_true(cf_spring_has_tail(&s));
    const cf_spring plain = {1, 2, 3, 4, 5, 6};
    assert_false(cf_spring_has_tail(&plain));
}

/* Checks the keys of one list, from `from` to the closing brace: each key stands between two
** `quote` characters; in a JSON object (json = 1) only the names before a ':' count. */
static void check_list(const char *from, char quote, int json)
{
    const char *end = strchr(from, '}');
    assert_non_null(end);
    int k = 0;
    const char *p = from;
    while ((p = memchr(p, quote, (size_t)(end - p))) != NULL) {
        const char *q = memchr(p + 1, quote, (size_t)(end - p - 1));
        assert_non_null(q);
        const char *after = q + 1;
        while (*after == ' ')
            after++;
        if (!json || *after == ':') {
            if (k >= CF_P_COUNT)
                fail_msg("documentation: a params list has more than %d keys: '%.*s'", CF_P_COUNT,
                         (int)(end - from), from);
            const char *want = cf_spring_param_info(k)->key;
            if (strlen(want) != (size_t)(q - p - 1) || strncmp(p + 1, want, strlen(want)) != 0)
                fail_msg("documentation: key %d of a params list is '%.*s', the field table's is '%s' "
                         "(src/model/spring.c); list: '%.*s'",
                         k + 1, (int)(q - p - 1), p + 1, want, (int)(end - from), from);
            k++;
        }
        p = q + 1;
    }
    if (k != CF_P_COUNT)
        fail_msg("documentation: a params list has %d keys, the field table %d: '%.*s'", k, CF_P_COUNT,
                 (int)(end - from), from);
}

/* README.md and every notes file, one after another (caller frees). */
static char *documentation(void)
{
    char *all = tu_slurp("README.md");
    if (!all)
        fail_msg("README.md not found (the tests run from the repository's top level)");
    const char *patterns[] = {"src/notes/*.md", "src/*/*.md"};
    for (size_t k = 0; k < sizeof patterns / sizeof patterns[0]; k++) {
        glob_t g;
        if (glob(patterns[k], 0, NULL, &g) != 0)
            continue;
        for (size_t i = 0; i < g.gl_pathc; i++) {
            char *text = tu_slurp(g.gl_pathv[i]);
            assert_non_null(text);
            size_t n = strlen(all), m = strlen(text);
            char *both = realloc(all, n + m + 2);
            assert_non_null(both);
            both[n] = '\n';
            memcpy(both + n + 1, text, m + 1);
            all = both;
            free(text);
        }
        globfree(&g);
    }
    return all;
}

static void the_documentation_lists_the_keys_of_the_field_table(void **state)
{
    (void)state;
    char *readme = documentation();
    int lists = 0;
    /* JSON examples: "params": { "KEY": value, ... } */
    for (const char *p = strstr(readme, "\"params\""); p; p = strstr(p + 1, "\"params\"")) {
        const char *q = p + strlen("\"params\"");
        while (*q == ' ' || *q == ':')
            q++;
        if (*q != '{' || strncmp(q, "{...}", 5) == 0) /* "{...}": a placeholder, no list */
            continue;
        check_list(q, '"', 1);
        lists++;
    }
    /* prose: `params` {`KEY`, ...} */
    for (const char *p = strstr(readme, "`params` {"); p; p = strstr(p + 1, "`params` {")) {
        check_list(p + strlen("`params` "), '`', 0);
        lists++;
    }
    /* the fit file, the scene and the exported spring: at least these three lists */
    assert_true(lists >= 3);
    free(readme);
}

/* The parameters as text come from the table too, in both styles, and never overrun. */
static void the_spring_as_text_follows_the_table(void **state)
{
    (void)state;
    const cf_spring p = {10, 30, 4, 1, 80000, 40.5};
    char buf[160];
    assert_string_equal(cf_spring_text(&p, 6, 0, buf, sizeof buf),
                        "D1 10 mm, D2 30 mm, n 4, d 1 mm, G 80000 MPa, H 40.5 mm");
    assert_string_equal(cf_spring_text(&p, 2, 1, buf, sizeof buf),
                        "D1=10 D2=30 n=4 d=1 G=8e+04 H=40");
    char small[12];
    memset(small, 'x', sizeof small);
    assert_string_equal(cf_spring_text(&p, 6, 0, small, sizeof small), "D1 10 mm, D");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(the_field_table_is_whole_and_found_by_name_and_key),
        cmocka_unit_test(the_documentation_lists_the_keys_of_the_field_table),
        cmocka_unit_test(the_spring_as_text_follows_the_table),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
