/*
** Building gnuplot scripts under one rule and running gnuplot (see gnuplot.h).
*/
#include "report/gnuplot.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <spawn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

extern char **environ;

static int ends_with_ci(const char *s, const char *suffix)
{
    size_t a = strlen(s), b = strlen(suffix);
    return a >= b && strcasecmp(s + a - b, suffix) == 0;
}

cf_status cf_gp_check_name(const char *path, cf_error *err)
{
    if (path && (ends_with_ci(path, ".png") || ends_with_ci(path, ".svg") ||
                 ends_with_ci(path, ".pdf")))
        return CF_OK;
    return cf_error_set(err, CF_E_DATA, "plot %s: the file must end in .png, .svg or .pdf",
                        path ? path : "(none)");
}

void cf_gp_init(cf_gp *g)
{
    memset(g, 0, sizeof *g);
}

void cf_gp_free(cf_gp *g)
{
    free(g->buf);
    memset(g, 0, sizeof *g);
}

static void invalid(cf_gp *g, cf_status st, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static void invalid(cf_gp *g, cf_status st, const char *fmt, ...)
{
    if (g->st != CF_OK)
        return;
    g->st = st;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(g->msg, sizeof g->msg, fmt, ap);
    va_end(ap);
}

static void put(cf_gp *g, const char *s, size_t n)
{
    if (g->st != CF_OK)
        return;
    if (g->len + n + 1 > g->cap) {
        size_t cap = g->cap ? g->cap : 4096;
        while (cap < g->len + n + 1)
            cap *= 2;
        char *b = realloc(g->buf, cap);
        if (!b) {
            invalid(g, CF_E_INTERNAL, "out of memory building a plot script");
            return;
        }
        g->buf = b;
        g->cap = cap;
    }
    memcpy(g->buf + g->len, s, n);
    g->len += n;
    g->buf[g->len] = '\0';
}

static void puts_(cf_gp *g, const char *s)
{
    put(g, s, strlen(s));
}

/* The bytes that may stand for themselves inside a string literal; all others are escaped. */
static int plain(unsigned char c)
{
    return isalnum(c) || (c != 0 && strchr(" .,_+-/:=()[]#", c) != NULL);
}

/* Text as a gnuplot double-quoted literal made only of plain bytes and octal escapes. */
static void put_literal(cf_gp *g, const char *text)
{
    put(g, "\"", 1);
    for (const unsigned char *p = (const unsigned char *)(text ? text : ""); *p; p++) {
        if (plain(*p) && isascii(*p)) {
            put(g, (const char *)p, 1);
        } else {
            char esc[5];
            snprintf(esc, sizeof esc, "\\%03o", (unsigned)*p);
            put(g, esc, 4);
        }
    }
    put(g, "\"", 1);
}

static void put_number(cf_gp *g, const char *spec, double v)
{
    if (!isfinite(v)) {
        invalid(g, CF_E_INTERNAL, "a non-finite number in a plot script");
        return;
    }
    char s[64];
    int n = snprintf(s, sizeof s, spec, v);
    if (n < 0 || (size_t)n >= sizeof s) {
        invalid(g, CF_E_INTERNAL, "a number too wide for a plot script");
        return;
    }
    put(g, s, (size_t)n);
}

void cf_gp_cmd(cf_gp *g, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    for (const char *p = fmt; *p && g->st == CF_OK; p++) {
        if (*p == '\n') {
            invalid(g, CF_E_INTERNAL, "a plot script line with a newline in its format");
            break;
        }
        if (*p != '%') {
            put(g, p, 1);
            continue;
        }
        /* one conversion: %[flags][width][.precision]conv */
        const char *start = p++;
        while (*p && strchr("-+ #0", *p))
            p++;
        while (isdigit((unsigned char)*p))
            p++;
        if (*p == '.') {
            p++;
            while (isdigit((unsigned char)*p))
                p++;
        }
        char spec[16];
        size_t sl = (size_t)(p - start);
        if (*p == '%' && sl == 1) {
            put(g, "%", 1);
        } else if (*p == 'q' && sl == 1) {
            put_literal(g, va_arg(ap, const char *));
        } else if (*p == 'd' && sl + 2 < sizeof spec) {
            char s[32];
            memcpy(spec, start, sl);
            spec[sl] = 'd';
            spec[sl + 1] = '\0';
            snprintf(s, sizeof s, spec, va_arg(ap, int));
            puts_(g, s);
        } else if (*p == 'z' && p[1] == 'u' && sl == 1) {
            char s[32];
            snprintf(s, sizeof s, "%zu", va_arg(ap, size_t));
            puts_(g, s);
            p++;
        } else if (*p && strchr("gef", *p) && sl + 2 < sizeof spec) {
            memcpy(spec, start, sl);
            spec[sl] = *p;
            spec[sl + 1] = '\0';
            put_number(g, spec, va_arg(ap, double));
        } else {
            invalid(g, CF_E_INTERNAL, "plot script format '%.40s': conversion not allowed", fmt);
        }
        if (!*p)
            break;
    }
    va_end(ap);
    put(g, "\n", 1);
}

void cf_gp_terminal(cf_gp *g, const char *path, int width, int height)
{
    if (path && ends_with_ci(path, ".svg"))
        cf_gp_cmd(g, "set terminal svg size %d,%d dynamic enhanced font %q", width, height,
                  "sans,12");
    else if (path && ends_with_ci(path, ".png"))
        cf_gp_cmd(g, "set terminal pngcairo size %d,%d enhanced font %q", width, height,
                  "sans,11");
    else if (path && ends_with_ci(path, ".pdf")) /* vector, for papers: 140 pixels to the inch */
        cf_gp_cmd(g, "set terminal pdfcairo size %gin,%gin enhanced font %q", width / 140.0,
                  height / 140.0, "sans,8");
    else
        invalid(g, CF_E_DATA, "the file must end in .png, .svg or .pdf");
}

void cf_gp_block_begin(cf_gp *g, const char *name)
{
    if (g->in_block) {
        invalid(g, CF_E_INTERNAL, "plot script: a data block inside another");
        return;
    }
    for (const char *p = name; *p; p++)
        if (!isalnum((unsigned char)*p) && *p != '_') {
            invalid(g, CF_E_INTERNAL, "plot script: data block name '%.40s' not allowed", name);
            return;
        }
    if (!*name) {
        invalid(g, CF_E_INTERNAL, "plot script: a data block without a name");
        return;
    }
    puts_(g, "$");
    puts_(g, name);
    puts_(g, " << EOD\n");
    g->in_block = 1;
}

void cf_gp_block_row(cf_gp *g, size_t n, const double *values)
{
    if (!g->in_block) {
        invalid(g, CF_E_INTERNAL, "plot script: a data row outside a data block");
        return;
    }
    for (size_t i = 0; i < n; i++) {
        if (i)
            put(g, " ", 1);
        put_number(g, "%.17g", values[i]);
    }
    put(g, "\n", 1);
}

void cf_gp_block_end(cf_gp *g)
{
    if (!g->in_block)
        invalid(g, CF_E_INTERNAL, "plot script: the end of a data block that was not begun");
    g->in_block = 0;
    puts_(g, "EOD\n");
}

/* The first line of gnuplot's error output that says something, as printable ASCII. */
static void first_error_line(FILE *f, char *out, size_t cap)
{
    char line[512];
    out[0] = '\0';
    rewind(f);
    while (fgets(line, sizeof line, f)) {
        size_t o = 0;
        for (const char *p = line; *p && o + 1 < cap; p++)
            if (*p >= 0x20 && *p < 0x7f)
                out[o++] = *p;
        out[o] = '\0';
        while (o > 0 && out[o - 1] == ' ')
            out[--o] = '\0';
        const char *s = out;
        while (*s == ' ' || *s == '^')
            s++;
        if (*s && strstr(out, "error") != NULL)
            return;
    }
    /* no line mentions an error: keep the last non-empty one */
    rewind(f);
    char last[512] = "";
    while (fgets(line, sizeof line, f)) {
        size_t o = 0;
        for (const char *p = line; *p && o + 1 < sizeof last; p++)
            if (*p >= 0x20 && *p < 0x7f)
                last[o++] = *p;
        if (o > 0) {
            last[o] = '\0';
            if (o >= cap)
                o = cap - 1;   /* cap > 0: the caller's buffer holds at least the terminator */
            memcpy(out, last, o);
            out[o] = '\0';
        }
    }
}

/* Runs gnuplot on the finished script: store it in a temporary file, start gnuplot by
** posix_spawnp with a fixed argument vector (no shell; the script on its standard input, its
** output into the atomic target), wait, read its error stream. Kept as one function because every
** step owns a resource that each later failure must release. */
cf_status cf_gp_render(cf_gp *g, const char *path, const char *const *inputs, cf_atomic *out,
                       cf_error *err)
{
    memset(out, 0, sizeof *out);
    if (g->in_block)
        invalid(g, CF_E_INTERNAL, "plot script: a data block was not ended");
    if (g->st != CF_OK)
        return cf_error_set(err, g->st, "%s: %s", path, g->msg);
    cf_status st = cf_atomic_open(out, path, inputs, err);
    if (st != CF_OK)
        return st;
    FILE *script = tmpfile(), *errors = tmpfile();
    if (!script || !errors || fwrite(g->buf, 1, g->len, script) != g->len ||
        fflush(script) != 0) {
        int e = errno;
        if (script)
            fclose(script);
        if (errors)
            fclose(errors);
        cf_atomic_abort(out);
        return cf_error_set(err, CF_E_INTERNAL, "%s: cannot store the plot script: %s", path,
                            strerror(e ? e : EIO));
    }
    rewind(script);
    /* neither file may leak into a gnuplot that another thread starts meanwhile */
    fcntl(fileno(script), F_SETFD, FD_CLOEXEC);
    fcntl(fileno(errors), F_SETFD, FD_CLOEXEC);
    const char *prog = getenv("CONIFIT_GNUPLOT");
    if (!prog || !*prog)
        prog = "gnuplot";
    posix_spawn_file_actions_t fa;
    char *argv[] = {(char *)prog, "-d", NULL}; /* -d: no initialisation file (~/.gnuplot) */
    pid_t pid;
    fflush(out->fp);
    int rc = posix_spawn_file_actions_init(&fa);
    if (rc == 0) {
        rc = posix_spawn_file_actions_adddup2(&fa, fileno(script), 0);
        if (rc == 0)
            rc = posix_spawn_file_actions_adddup2(&fa, fileno(out->fp), 1);
        if (rc == 0)
            rc = posix_spawn_file_actions_adddup2(&fa, fileno(errors), 2);
        if (rc == 0)
            rc = posix_spawnp(&pid, prog, &fa, NULL, argv, environ);
        posix_spawn_file_actions_destroy(&fa);
    }
    fclose(script);
    if (rc != 0) {
        fclose(errors);
        cf_atomic_abort(out);
        if (rc == ENOENT)
            return cf_error_set(err, CF_E_INTERNAL,
                                "cannot run '%s' to draw %s: install gnuplot (Debian package "
                                "gnuplot-nox)", prog, path);
        return cf_error_set(err, CF_E_INTERNAL, "cannot run '%s' to draw %s: %s", prog, path,
                            strerror(rc));
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0) {
        if (errno != EINTR) {
            status = -1;
            break;
        }
    }
    int code = status >= 0 && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    char why[200];
    first_error_line(errors, why, sizeof why);
    fclose(errors);
    if (code == 127) {
        cf_atomic_abort(out);
        return cf_error_set(err, CF_E_INTERNAL,
                            "cannot run '%s' to draw %s: install gnuplot (Debian package "
                            "gnuplot-nox)", prog, path);
    }
    struct stat sb;
    if (code == 0 && (fstat(fileno(out->fp), &sb) != 0 || sb.st_size == 0)) {
        code = -2;
        snprintf(why, sizeof why, "it drew nothing");
    }
    if (code != 0) {
        cf_atomic_abort(out);
        if (code == -1 && status >= 0 && WIFSIGNALED(status))
            return cf_error_set(err, CF_E_INTERNAL, "'%s' was killed by signal %d drawing %s",
                                prog, WTERMSIG(status), path);
        return cf_error_set(err, CF_E_INTERNAL, "'%s' failed drawing %s%s%s", prog, path,
                            why[0] ? ": " : "", why);
    }
    return CF_OK;
}
