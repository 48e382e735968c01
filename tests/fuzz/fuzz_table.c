/*
** libFuzzer harness: the measurement-table reader (io/measure.c) on arbitrary bytes, with the
** default options and with explicit columns and units.
*/
#include "fuzz.h"

#include "io/measure.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_file(data, size, ".csv");
    if (!path)
        return 0;
    cf_table t;
    cf_error err = {0};
    if (cf_measure_load(path, NULL, &t, &err) == CF_OK)
        cf_table_free(&t);
    cf_measure_options o = cf_measure_default_options();
    o.x_col = "strain";
    o.y_col = "force";
    o.force_unit = "mN";
    o.length_unit = "mm";
    if (cf_measure_load(path, &o, &t, &err) == CF_OK)
        cf_table_free(&t);
    return 0;
}
