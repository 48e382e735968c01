/*
** The Python module: runs tests/python/test_conifit.py with python3 against this build's
** libconifit.so and binary, and requires every case to pass. Skipped, with a message, where no
** python3 exists, and in the sanitizer build (its library cannot be loaded into python3 without
** preloading the sanitizer runtime).
*/
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "testutil.h"

#if defined(__SANITIZE_ADDRESS__)
#define TP_SANITIZED 1
#else
#define TP_SANITIZED 0
#endif

static void test_module(void **state)
{
    (void)state;
    if (TP_SANITIZED) {
        print_message("test_python: the sanitizer build's library is not loaded into python3: skipped\n");
        skip();
    }
    if (system("command -v python3 >/dev/null 2>&1") != 0) {
        print_message("test_python: no python3 on this machine: the Python module is not tested\n");
        skip();
    }
    /* the library beside the binary under test: build/conifit -> build/libconifit.so */
    char lib[4096];
    snprintf(lib, sizeof lib, "%s", tu_conifit());
    char *slash = strrchr(lib, '/');
    snprintf(slash ? slash + 1 : lib, sizeof lib - (size_t)(slash ? slash + 1 - lib : 0),
             "libconifit.so");
    FILE *f = fopen(lib, "rb");
    assert_non_null(f);
    fclose(f);
    char cmd[9000];
    snprintf(cmd, sizeof cmd,
             "CONIFIT_LIBRARY='%s' CONIFIT='%s' python3 tests/python/test_conifit.py "
             ">/tmp/conifit-python-$$.log 2>&1; s=$?; [ $s = 0 ] || cat /tmp/conifit-python-$$.log >&2; "
             "rm -f /tmp/conifit-python-$$.log; exit $s",
             lib, tu_conifit());
    assert_int_equal(system(cmd), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_module)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
