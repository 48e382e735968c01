/*
** No empty reason anywhere: the fit files of several fits (shipped and published tables, one
** the design limits make infeasible, a force-displacement table the lattice cannot run, a time
** series) are scanned for every "skipped", "note" and "*_reason" key, which must hold a non-empty
** string; the text reports hold no "skipped: " or "not checked" without a reason after it.
*/
#include <string.h>

#include <jansson.h>

#include "testutil.h"

static char out[1 << 16], errb[1 << 14];

TU_SCRATCH_GROUP("reasons")

/* 1 when key names a reason: skipped, note, or *_reason. */
static int is_reason_key(const char *key)
{
    size_t n = strlen(key);
    return strcmp(key, "skipped") == 0 || strcmp(key, "note") == 0 ||
           (n >= 7 && strcmp(key + n - 7, "_reason") == 0);
}

/* Counts the reason keys under j, failing on any whose value is not a non-empty string. */
static int scan(const json_t *j, const char *where)
{
    int found = 0;
    if (json_is_object(j)) {
        const char *key;
        json_t *v;
        json_object_foreach((json_t *)j, key, v) {
            if (is_reason_key(key)) {
                if (!json_is_string(v) || json_string_length(v) == 0)
                    fail_msg("%s: key '%s' holds no reason", where, key);
                found++;
            }
            found += scan(v, where);
        }
    } else if (json_is_array(j)) {
        size_t i;
        json_t *v;
        json_array_foreach(j, i, v) found += scan(v, where);
    }
    return found;
}

/* The text report states a reason after every "skipped" and "not checked". */
static void text_has_reasons(const char *text, const char *where)
{
    for (const char *p = text; (p = strstr(p, "skipped: ")); p += 9)
        if (p[9] == '\n' || p[9] == '\0' || p[9] == ')')
            fail_msg("%s: 'skipped: ' without a reason", where);
    for (const char *p = text; (p = strstr(p, "not checked")); p += 11)
        if (p[11] != ' ' || p[12] != '(')
            fail_msg("%s: 'not checked' without a reason", where);
}

static int run_and_scan(const char *args, const char *name)
{
    char json[512];
    snprintf(json, sizeof json, "%s/%s.json", dir, name);
    int st = tu_run(out, sizeof out, errb, sizeof errb, "fit %s -o %s", args, json);
    if (st != 0)
        fail_msg("%s: exit %d: %s", args, st, errb);
    json_error_t e;
    json_t *root = json_load_file(json, 0, &e);
    if (!root)
        fail_msg("%s: %s", json, e.text);
    int n = scan(root, args);
    json_decref(root);
    text_has_reasons(out, args);
    return n;
}

static void shipped_fits_state_every_reason(void **state)
{
    (void)state;
    run_and_scan("data/telescoping.csv --validate", "tension");
    run_and_scan("data/telescoping_compression.csv --target lattice", "compression");
    /* the design limits leave no feasible telescoping spring: the lattice fit cannot run */
    int n = run_and_scan("data/telescoping.csv --target lattice --index-max 3 --n-max 2 "
                         "--rho-min 0.9",
                         "infeasible");
    assert_true(n > 0);
    assert_non_null(strstr(out, "validation skipped: "));
    run_and_scan("data/series/synthetic_relaxation.csv --branches 1", "series");
}

static void published_fits_state_every_reason(void **state)
{
    (void)state;
    const char *d = tu_datasets();
    if (!d)
        skip();
    char args[512];
    snprintf(args, sizeof args, "%s/thrombus_pureshear_force_displacement.csv --validate", d);
    assert_true(run_and_scan(args, "clot") > 0); /* the lattice skipped, and why */
    snprintf(args, sizeof args, "%s/brain_cortex_shear.csv --validate", d);
    run_and_scan(args, "shear");
    snprintf(args, sizeof args, "%s/heart_myocardium_biaxial_1to1_fiber.csv", d);
    run_and_scan(args, "biaxial");
    snprintf(args, sizeof args, "%s/chicken_breast_compression.csv --target lattice", d);
    run_and_scan(args, "softening");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(shipped_fits_state_every_reason),
        cmocka_unit_test(published_fits_state_every_reason),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
