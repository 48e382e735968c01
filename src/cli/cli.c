/*
** Option parsing shared by the subcommands (see cli.h).
*/
#include "cli/cli.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

int cf_cli_fail(const cf_error *err)
{
    fprintf(stderr, "conifit: %s\n", err->msg[0] ? err->msg : cf_strerror(err->status));
    return cf_exit_code(err->status);
}

int cf_cli_usage_error(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "conifit %s: ", cmd);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, " (see 'conifit %s --help')\n", cmd);
    return CF_EXIT_USAGE;
}

int cf_cli_is_help(const char *arg)
{
    return strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0;
}

int cf_cli_match(int argc, char **argv, int *i, const char *name, const char **value,
                 cf_error *err)
{
    const char *arg = argv[*i];
    size_t len = strlen(name);
    if (strncmp(arg, name, len) != 0)
        return 0;
    if (arg[len] == '=') {
        *value = arg + len + 1;
        return 1;
    }
    if (arg[len] != '\0')
        return 0;
    if (*i + 1 >= argc) {
        cf_error_set(err, CF_E_USAGE, "option %s needs a value", name);
        return -1;
    }
    *i += 1;
    *value = argv[*i];
    return 1;
}

cf_status cf_cli_parse_double(const char *name, const char *text, double *out, cf_error *err)
{
    char *end = NULL;
    errno = 0;
    double v = strtod(text, &end);
    if (end == text || *end != '\0')
        return cf_error_set(err, CF_E_USAGE, "option %s: '%s' is not a number", name, text);
    if (!isfinite(v) || errno == ERANGE)
        return cf_error_set(err, CF_E_USAGE, "option %s: '%s' is not a finite number", name,
                            text);
    *out = v;
    return CF_OK;
}

cf_status cf_cli_parse_long(const char *name, const char *text, long lo, long hi, long *out,
                            cf_error *err)
{
    char *end = NULL;
    errno = 0;
    long v = strtol(text, &end, 10);
    if (end == text || *end != '\0' || errno == ERANGE)
        return cf_error_set(err, CF_E_USAGE, "option %s: '%s' is not a whole number", name, text);
    if (v < lo || v > hi)
        return cf_error_set(err, CF_E_USAGE, "option %s: %ld is outside [%ld, %ld]", name, v, lo,
                            hi);
    *out = v;
    return CF_OK;
}

static const char *const spring_flags[6] = {"--D1", "--D2", "--n", "--d", "--G", "--H"};

const char cf_cli_spring_help[] =
    "Spring (all six required):\n"
    "  --D1 MM    mean diameter of the smallest active coil, mm\n"
    "  --D2 MM    mean diameter of the largest active coil, mm (D2 >= D1)\n"
    "  --n N      number of active coils (>= 2, may be fractional)\n"
    "  --d MM     wire diameter, mm\n"
    "  --G MPA    shear modulus of the wire, MPa (N/mm^2)\n"
    "  --H MM     free length, mm\n";

int cf_cli_spring_option(cf_cli_spring *s, int argc, char **argv, int *i, cf_error *err)
{
    double *slot[6] = {&s->p.D1_mm, &s->p.D2_mm, &s->p.n, &s->p.d_mm, &s->p.G_MPa, &s->p.H_mm};
    for (int k = 0; k < 6; k++) {
        const char *val;
        int m = cf_cli_match(argc, argv, i, spring_flags[k], &val, err);
        if (m < 0)
            return -1;
        if (m == 0)
            continue;
        if (cf_cli_parse_double(spring_flags[k], val, slot[k], err) != CF_OK)
            return -1;
        s->have[k] = 1;
        return 1;
    }
    return 0;
}

cf_status cf_cli_spring_complete(const cf_cli_spring *s, cf_error *err)
{
    for (int k = 0; k < 6; k++)
        if (!s->have[k])
            return cf_error_set(err, CF_E_USAGE, "missing spring option %s", spring_flags[k]);
    return CF_OK;
}
