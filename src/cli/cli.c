/*
** Option parsing shared by the subcommands (see cli.h).
*/
#include "cli/cli.h"

#include "base/safetext.h"

#include "io/scene.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* The library names a setting "option FIELD" (option stress_unit); the command line calls it
** --stress-unit. Copies msg to out with every such name in its flag spelling. */
static void flags_for_options(const char *msg, char *out, size_t cap)
{
    static const char key[] = "option ";
    size_t o = 0;
    while (*msg && o + 1 < cap) {
        if (strncmp(msg, key, sizeof key - 1) == 0 && islower((unsigned char)msg[sizeof key - 1])) {
            msg += sizeof key - 1;
            if (o + 2 < cap) {
                out[o++] = '-';
                out[o++] = '-';
            }
            while ((islower((unsigned char)*msg) || *msg == '_') && o + 1 < cap)
                out[o++] = *msg == '_' ? '-' : *msg, msg++;
            continue;
        }
        out[o++] = *msg++;
    }
    out[o] = '\0';
}

void cf_cli_write_safe(FILE *f, const char *text)
{
    char safe[4 * 1024 + 4];
    for (const char *line = text; *line;) {
        const char *nl = strchr(line, '\n');
        size_t n = nl ? (size_t)(nl - line) : strlen(line);
        /* in pieces that fit the buffer whatever they expand to (4 bytes per byte at most) */
        for (size_t done = 0; done < n;) {
            size_t take = n - done < 1024 ? n - done : 1024;
            /* a piece ends on a character boundary unless the line itself ends there */
            while (take < n - done && take > 0 && ((unsigned char)line[done + take] & 0xc0) == 0x80)
                take--;
            take = take ? take : 1;
            fputs(cf_safe_text(safe, sizeof safe, line + done, take), f);
            done += take;
        }
        if (!nl)
            break;
        fputc('\n', f);
        line = nl + 1;
    }
}

void cf_cli_printf_safe(FILE *f, const char *fmt, ...)
{
    char buf[8192];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    cf_cli_write_safe(f, buf);
}

int cf_cli_fail(const cf_error *err)
{
    char msg[2 * CF_ERROR_MSG_LEN];
    flags_for_options(err->msg[0] ? err->msg : cf_strerror(err->status), msg, sizeof msg);
    cf_cli_printf_safe(stderr, "conifit: %s\n", msg);
    return cf_exit_code(err->status);
}

void cf_cli_table_notes(const cf_table *m)
{
    for (const char *line = m->notes; *line;) {
        const char *nl = strchr(line, '\n');
        size_t n = nl ? (size_t)(nl - line) : strlen(line);
        char note[sizeof m->notes], msg[2 * sizeof m->notes];
        snprintf(note, sizeof note, "%.*s", (int)n, line);
        flags_for_options(note, msg, sizeof msg);
        cf_cli_printf_safe(stderr, "conifit: warning: %s: %s\n", m->path, msg);
        line += n + (nl != NULL);
    }
}

int cf_cli_usage_error(const char *cmd, const char *fmt, ...)
{
    char msg[2048];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    cf_cli_printf_safe(stderr, "conifit %s: %s (see 'conifit %s --help')\n", cmd, msg, cmd);
    return CF_EXIT_USAGE;
}

/* A size in bytes with an optional K, M or G (binary) suffix; 0 when it is not one. */
double cf_cli_parse_size(const char *text)
{
    char *end = NULL;
    double v = strtod(text, &end);
    double unit = 1;
    if (end == text || !(v > 0))
        return 0;
    if (*end)
        unit = end[1]        ? 0
               : *end == 'K' ? 1024.0
               : *end == 'M' ? 1048576.0
               : *end == 'G' ? 1073741824.0
                             : 0;
    return isfinite(v * unit) ? v * unit : 0;
}

cf_status cf_cli_parse_double(const char *name, const char *text, double *out, cf_error *err)
{
    char *end = NULL;
    errno = 0;
    double v = strtod(text, &end);
    if (end == text || *end != '\0')
        return cf_error_set(err, CF_E_USAGE, "option %s: '%s' is not a number", name, text);
    /* ERANGE is also an underflow: a subnormal such as 5e-324 is a finite number (it was
    ** refused as "not finite"); only a value that rounds to 0 from a nonzero one is refused */
    if (!isfinite(v) || (errno == ERANGE && fabs(v) > 1.0))
        return cf_error_set(err, CF_E_USAGE, "option %s: '%s' is not a finite number", name,
                            text);
    if (errno == ERANGE && v == 0)
        return cf_error_set(err, CF_E_USAGE,
                            "option %s: '%s' is below the smallest number a double holds "
                            "(about 4.9e-324)",
                            name, text);
    *out = v;
    return CF_OK;
}

int cf_cli_budget_option(const char *cmd, const char *flag, const char *value, cf_budget *b)
{
    cf_error err = {0};
    if (strcmp(flag, "--max-memory") == 0) {
        if (!(b->max_memory_bytes = cf_cli_parse_size(value)))
            return cf_cli_usage_error(cmd, "--max-memory '%s': expected a size in bytes, "
                                           "optionally with K, M or G", value);
        return 0;
    }
    double *v = strcmp(flag, "--max-steps") == 0 ? &b->max_steps : &b->max_work;
    if (cf_cli_parse_double(flag, value, v, &err) != CF_OK)
        return cf_cli_usage_error(cmd, "%s", err.msg);
    if (!(*v >= 1))
        return cf_cli_usage_error(cmd, "%s %g: must be at least 1", flag, *v);
    return 0;
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

/* ---- option parsing ------------------------------------------------------------------------- */

static const struct option common_opts[] = {
    {"help", no_argument, NULL, 'h'},
    {"output", required_argument, NULL, 'o'},
    {"quiet", no_argument, NULL, 'q'},
    {"progress", no_argument, NULL, CF_CLI_OPT_PROGRESS},
    {"no-progress", no_argument, NULL, CF_CLI_OPT_NO_PROGRESS},
};
#define NCOMMON (sizeof common_opts / sizeof common_opts[0])

int cf_cli_parser_init(cf_cli_parser *p, const char *cmd, const char *help, int spring,
                       int argc, char **argv, const char *shortopts,
                       const struct option *longopts)
{
    memset(p, 0, sizeof *p);
    p->cmd = cmd;
    p->help = help;
    p->spring = spring;
    p->argc = argc;
    p->argv = argv;
    p->progress = -1;
    /* ':' first: a missing value is told apart from an unknown option */
    snprintf(p->shortopts, sizeof p->shortopts, ":ho:q%s", shortopts ? shortopts : "");
    size_t own = 0;
    while (longopts && longopts[own].name)
        own++;
    size_t n = NCOMMON + (spring ? CF_P_ALL : 0) + own;
    p->longopts = calloc(n + 1, sizeof *p->longopts);
    if (!p->longopts) {
        fprintf(stderr, "conifit %s: out of memory\n", cmd);
        return CF_EXIT_SOFTWARE;
    }
    size_t k = 0;
    for (size_t i = 0; i < NCOMMON; i++)
        p->longopts[k++] = common_opts[i];
    for (int i = 0; spring && i < CF_P_ALL; i++)
        p->longopts[k++] = (struct option){cf_spring_param_info(i)->name, required_argument, NULL,
                                           CF_CLI_OPT_SPRING + i};
    for (size_t i = 0; i < own; i++)
        p->longopts[k++] = longopts[i];
    optind = 0; /* a fresh scan (glibc re-initialises on 0) */
    opterr = 0; /* messages are ours */
    return 0;
}

void cf_cli_parser_free(cf_cli_parser *p)
{
    free(p->longopts);
    p->longopts = NULL;
}

/* The option getopt_long just refused, as the user wrote it. */
static const char *offending(const cf_cli_parser *p, char *buf, size_t cap)
{
    if (optopt > 0 && optopt < 256) {
        snprintf(buf, cap, "-%c", optopt);
        return buf;
    }
    const char *a = (optind > 0 && optind <= p->argc) ? p->argv[optind - 1] : "?";
    const char *eq = strchr(a, '=');
    snprintf(buf, cap, "%.*s", eq ? (int)(eq - a) : (int)strlen(a), a);
    return buf;
}

int cf_cli_next(cf_cli_parser *p)
{
    for (;;) {
        int c = getopt_long(p->argc, p->argv, p->shortopts, p->longopts, NULL);
        char buf[128];
        switch (c) {
        case -1:
            return 0;
        case 'h':
            fputs(p->help, stdout);
            if (p->help_more)
                fputs(p->help_more, stdout);
            if (p->help_extra)
                p->help_extra(stdout);
            if (p->spring)
                cf_cli_spring_help(stdout);
            cf_cli_common_help(stdout);
            p->status = CF_EXIT_OK;
            return -1;
        case 'o':
            p->output = optarg;
            break;
        case 'q':
            p->quiet = 1;
            break;
        case CF_CLI_OPT_PROGRESS:
            p->progress = 1;
            break;
        case CF_CLI_OPT_NO_PROGRESS:
            p->progress = 0;
            break;
        case ':':
            p->status = cf_cli_usage_error(p->cmd, "option %s needs a value",
                                           offending(p, buf, sizeof buf));
            return -1;
        case '?':
            p->status = cf_cli_usage_error(p->cmd, "unknown option '%s'",
                                           offending(p, buf, sizeof buf));
            return -1;
        default:
            return c;
        }
    }
}

int cf_cli_parse(cf_cli_parser *p, int (*take)(void *ctx, int c, const char *value), void *ctx)
{
    int c, rc = 0;
    while ((c = cf_cli_next(p)) > 0 && (rc = take(ctx, c, optarg)) == 0)
        ;
    cf_cli_parser_free(p);
    if (c < 0)
        return p->status;
    return rc ? rc : -1;
}

int cf_cli_progress(const cf_cli_parser *p)
{
    return p->progress < 0 ? isatty(STDERR_FILENO) : p->progress;
}

void cf_cli_common_help(FILE *out)
{
    fputs("  -q, --quiet             nothing but the result and errors (no report, notes or\n"
          "                          summaries)\n"
          "  --progress, --no-progress  progress lines on stderr (default: only when stderr is\n"
          "                          a terminal)\n"
          "  -h, --help              this help\n",
          out);
}

/* ---- output ---------------------------------------------------------------------------------- */

int cf_cli_is_stdio(const char *path)
{
    return path && strcmp(path, "-") == 0;
}

int cf_cli_is_dir_target(const char *p)
{
    struct stat s;
    size_t n = strlen(p);
    return (n > 0 && p[n - 1] == '/') || (stat(p, &s) == 0 && S_ISDIR(s.st_mode));
}

cf_status cf_cli_out_open(cf_cli_out *o, const char *path, const char *const *inputs,
                          cf_error *err)
{
    memset(o, 0, sizeof *o);
    if (!path || cf_cli_is_stdio(path)) {
        o->fp = stdout;
        o->to_stdout = 1;
        return CF_OK;
    }
    cf_status st = cf_atomic_open(&o->a, path, inputs, err);
    o->fp = o->a.fp;
    return st;
}

cf_status cf_cli_out_close(cf_cli_out *o, cf_error *err)
{
    if (o->to_stdout) {
        o->fp = NULL;
        if (fflush(stdout) != 0 || ferror(stdout))
            return cf_error_set(err, CF_E_CANTWRITE, "cannot write to standard output");
        return CF_OK;
    }
    o->fp = NULL;
    return cf_atomic_commit(&o->a, err);
}

void cf_cli_out_abort(cf_cli_out *o)
{
    if (!o->to_stdout)
        cf_atomic_abort(&o->a);
    o->fp = NULL;
}

/* ---- spring options -------------------------------------------------------------------------- */

int cf_cli_spring_take(cf_cli_spring *s, int c, const char *text, cf_error *err)
{
    int k = c - CF_CLI_OPT_SPRING;
    if (k < 0 || k >= CF_P_ALL)
        return 0;
    char flag[16];
    double v;
    snprintf(flag, sizeof flag, "--%s", cf_spring_param_info(k)->name);
    if (cf_cli_parse_double(flag, text, &v, err) != CF_OK)
        return -1;
    cf_spring_set(&s->p, k, v);
    s->have[k] = 1;
    return 1;
}

cf_status cf_cli_spring_complete(const cf_cli_spring *s, cf_error *err)
{
    for (int k = 0; k < CF_P_COUNT; k++)
        if (!s->have[k])
            return cf_error_set(err, CF_E_USAGE, "missing spring option --%s",
                                cf_spring_param_info(k)->name);
    return CF_OK;
}

void cf_cli_spring_help(FILE *out)
{
    fputs("Spring (the first six required; the cylindrical tail's two optional):\n", out);
    for (int k = 0; k < CF_P_ALL; k++) {
        const cf_spring_param *sp = cf_spring_param_info(k);
        char flag[32];
        snprintf(flag, sizeof flag, "--%s %s", sp->name,
                 strcmp(sp->unit, "-") == 0 ? "N" : strcmp(sp->unit, "mm") == 0 ? "MM" : "MPA");
        fprintf(out, "  %-12s %s%s%s\n", flag, sp->meaning, strcmp(sp->unit, "-") ? ", " : "",
                strcmp(sp->unit, "-") ? sp->unit : "");
    }
}

void cf_cli_scene_fit(const char *scene_path, char *out, size_t cap)
{
    cf_scene sc;
    out[0] = '\0';
    if (cf_scene_load(scene_path, &sc, NULL) != CF_OK)
        return; /* the run's own reading of the scene reports why */
    snprintf(out, cap, "%s", sc.fit_path);
    cf_scene_free(&sc);
}
