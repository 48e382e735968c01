/*
** libFuzzer harness: the command-line parser (cli/cli.c: getopt_long with the shared options, the
** spring options and a command's own) and the number parsers, on argument vectors made of the
** input split at NUL bytes.
*/
#include "fuzz.h"

#include <string.h>

#include "cli/cli.h"

#define MAX_ARGS 32

static int take(void *ctx, int c, const char *value)
{
    (void)ctx;
    cf_error err = {0};
    double d;
    long l;
    if (value && c % 2)
        cf_cli_parse_double("--x", value, &d, &err);
    else if (value)
        cf_cli_parse_long("--n", value, -5, 1000000, &l, &err);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static int quiet;
    /* usage errors go to stderr: a replay sets CONIFIT_FUZZ_QUIET to keep its output readable
    ** (libFuzzer itself is run with -close_fd_mask=3, which keeps its own reports) */
    if (!quiet && getenv("CONIFIT_FUZZ_QUIET")) {
        quiet = 1;
        if (!freopen("/dev/null", "w", stderr) || !freopen("/dev/null", "w", stdout))
            return 0;
    }
    char *buf = malloc(size + 1);
    if (!buf)
        return 0;
    memcpy(buf, data, size);
    buf[size] = '\0';
    char *argv[MAX_ARGS + 2];
    int argc = 0;
    argv[argc++] = "fuzz";
    for (size_t i = 0; i < size && argc <= MAX_ARGS; i += strlen(buf + i) + 1)
        argv[argc++] = buf + i;
    argv[argc] = NULL;
    static const struct option own[] = {{"type", required_argument, NULL, CF_CLI_OPT_OWN},
                                        {"fix", required_argument, NULL, CF_CLI_OPT_OWN + 1},
                                        {"relative", no_argument, NULL, CF_CLI_OPT_OWN + 2},
                                        {"validate", optional_argument, NULL, CF_CLI_OPT_OWN + 3},
                                        {NULL, 0, NULL, 0}};
    for (int spring = 0; spring < 2; spring++) {
        cf_cli_parser p;
        optind = 0; /* getopt starts over */
        if (cf_cli_parser_init(&p, "fuzz", "help\n", spring, argc, argv, "j:", own) == 0)
            cf_cli_parse(&p, take, NULL);
    }
    free(buf);
    return 0;
}
