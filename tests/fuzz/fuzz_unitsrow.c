/*
** libFuzzer harness: the units row of a testing machine's export (io/unitsrow.c) and the rows
** after it. The first byte picks a header (comma, semicolon, tab or blank separated, with and
** without units of its own); the rest of the input follows it as the table's second line on.
*/
#include "fuzz.h"

#include <string.h>

#include "io/measure.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const char *const headers[] = {
        "Time,Extension,Load\n",          "Time;Extension;Load\n",
        "Time\tExtension\tLoad\n",        "Time Extension Load\n",
        "time_s,strain,stress\n",         "Zeit;Weg;Kraft;Gewicht\n",
        "strain,stress_kPa\n",            "# mode: shear\nExtension,Load\n",
    };
    if (size < 1)
        return 0;
    const char *h = headers[data[0] % (sizeof headers / sizeof headers[0])];
    size_t hl = strlen(h);
    uint8_t *buf = malloc(hl + size - 1);
    if (!buf)
        return 0;
    memcpy(buf, h, hl);
    memcpy(buf + hl, data + 1, size - 1);
    const char *path = fuzz_file(buf, hl + size - 1, ".csv");
    free(buf);
    if (!path)
        return 0;
    cf_table t;
    cf_error err = {0};
    if (cf_measure_load(path, NULL, &t, &err) == CF_OK)
        cf_table_free(&t);
    cf_measure_options o = cf_measure_default_options();
    o.force_unit = "N";
    o.length_unit = "mm";
    if (cf_measure_load(path, &o, &t, &err) == CF_OK)
        cf_table_free(&t);
    return 0;
}
