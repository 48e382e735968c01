/*
** libFuzzer harness: the fit-file reader (io/fitfile.c) on arbitrary bytes, for the better type
** and for each type by name, as a spring and as a model (cf_fitfile_load_model, conifit predict).
*/
#include "fuzz.h"

#include "io/fitfile.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_file(data, size, ".json");
    if (!path)
        return 0;
    static const char *const types[] = {NULL, "telescoping", "non-telescoping"};
    for (int k = 0; k < 3; k++) {
        cf_fitted_spring fs;
        cf_error err = {0};
        cf_fitfile_load(path, types[k], &fs, &err);
        static cf_fitted_model fm;
        cf_error merr = {0};
        cf_fitfile_load_model(path, types[k], &fm, &merr);
    }
    return 0;
}
