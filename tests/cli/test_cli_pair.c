/*
** The command line of the double-acting element and the volume term (conifit fit --joint --law
** double-acting|auto, --volume fit, --volume-modulus K, --poisson NU): bad input exits 2 naming
** the option and its value, nothing written; a fit file of a pair is refused by export (65)
** rather than exported as its compression spring alone; on the brain cortex tables (when
** present) the fit file holds the pair and kappa.
*/
#include "testutil.h"

#include <sys/stat.h>

static char out[1 << 16], errb[1 << 12];

static int exists(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0;
}

#define TWO "data/telescoping.csv data/telescoping_compression.csv"

static void bad_input_exits_2_naming_the_option(void **state)
{
    (void)state;
    static const struct {
        const char *args, *says;
    } cases[] = {
        {"fit " TWO " --joint --poisson 0.2 -o /tmp/conifit-pair-no.json", "--poisson 0.2"},
        {"fit " TWO " --joint --poisson 0.5 -o /tmp/conifit-pair-no.json", "--poisson 0.5"},
        {"fit " TWO " --joint --poisson nan -o /tmp/conifit-pair-no.json", "--poisson"},
        {"fit " TWO " --joint --volume-modulus -1 -o /tmp/conifit-pair-no.json",
         "--volume-modulus -1"},
        {"fit " TWO " --joint --volume-modulus inf -o /tmp/conifit-pair-no.json",
         "--volume-modulus"},
        {"fit " TWO " --joint --volume guess -o /tmp/conifit-pair-no.json", "--volume 'guess'"},
        {"fit " TWO " --joint --volume fit --poisson 0.3 -o /tmp/conifit-pair-no.json",
         "--poisson 0.3"},
        {"fit data/telescoping.csv --volume fit -o /tmp/conifit-pair-no.json", "--volume fit"},
        {"fit data/telescoping.csv --poisson 0.3 -o /tmp/conifit-pair-no.json", "--poisson"},
        {"fit data/telescoping.csv --law double-acting -o /tmp/conifit-pair-no.json",
         "--law double-acting"},
        {"fit " TWO " --joint --law conical-tail --volume fit -o /tmp/conifit-pair-no.json",
         "conical-tail"},
        {"fit " TWO " --joint --law double-sided -o /tmp/conifit-pair-no.json", "double-sided"},
        {"fit " TWO " --joint --law double-acting --poisson 0.4 -o /tmp/conifit-pair-no.json",
         "--poisson 0.4"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const int rc = tu_run(out, sizeof out, errb, sizeof errb, "%s", cases[i].args);
        if (rc != 2 || !strstr(errb, cases[i].says))
            fail_msg("'%s': exit %d, message '%s' (expected 2 naming '%s')", cases[i].args, rc,
                     errb, cases[i].says);
        assert_false(exists("/tmp/conifit-pair-no.json"));
    }
}

/* The brain cortex, --joint --law auto --volume fit: the fit file holds the pair and kappa, and
** export refuses it with 65 naming the key, writing nothing. */
static void brain_pair_fit_file_and_export(void **state)
{
    (void)state;
    const char *d = tu_datasets();
    if (!d)
        skip();
    char dir[] = "/tmp/conifit-pair-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char json[256];
    snprintf(json, sizeof json, "%s/brain.json", dir);
    int rc = tu_run(out, sizeof out, errb, sizeof errb,
                    "fit %s/brain_cortex_tension.csv %s/brain_cortex_compression.csv "
                    "%s/brain_cortex_shear.csv --joint --law auto --volume fit -o %s",
                    d, d, d, json);
    if (rc != 0)
        fail_msg("exit %d: %s", rc, errb);
    assert_non_null(strstr(out, "double-acting element"));
    assert_non_null(strstr(out, "volume term"));
    char *file = tu_slurp(json);
    assert_non_null(file);
    assert_non_null(strstr(file, "\"params_extension\""));
    assert_non_null(strstr(file, "\"volume_modulus_MPa\""));
    free(file);
    rc = tu_run(out, sizeof out, errb, sizeof errb, "export %s --format csv -o %s/t.csv", json,
                dir);
    assert_int_equal(rc, 65);
    assert_non_null(strstr(errb, "params_extension"));
    char t[300];
    snprintf(t, sizeof t, "%s/t.csv", dir);
    assert_false(exists(t));
    remove(json);
    rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(bad_input_exits_2_naming_the_option),
        cmocka_unit_test(brain_pair_fit_file_and_export),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
