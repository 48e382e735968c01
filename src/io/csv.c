/*
** The lexer of measurement tables (csv.h): lines, fields and their quoting, numbers, and the
** messages that point at a line and a column.
*/
#include "io/csv.h"

#include "base/safetext.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* ---- messages -------------------------------------------------------------------------------- */

void cf_csv_quote(char *out, size_t cap, const char *s, size_t n)
{
    /* at most the first 60 bytes, cut between characters, in the form every message uses */
    size_t keep = 0;
    while (keep < n) {
        size_t len = cf_text_char_length((const unsigned char *)s + keep, n - keep);
        len = len ? len : 1; /* a byte shown as \xNN */
        if (keep + len > 60)
            break;
        keep += len;
    }
    cf_safe_text(out, cap > 3 ? cap - 3 : cap, s, keep);
    if (keep < n && cap > 3)
        strcat(out, "...");
}

cf_status cf_csv_error(cf_error *err, const char *path, size_t line, size_t col, const char *fmt,
                       ...)
{
    char msg[CF_ERROR_MSG_LEN];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return cf_error_set(err, CF_E_DATA, "%s:%zu:%zu: %s", path, line, col, msg);
}

/* ---- lines and fields ------------------------------------------------------------------------ */

void cf_csv_fields_free(cf_csv_fields *f)
{
    free(f->buf);
    free(f->off);
    memset(f, 0, sizeof *f);
}

static int fields_reserve(cf_csv_fields *f, size_t text_len)
{
    if (f->buf_cap < text_len + 1) {
        char *b = realloc(f->buf, text_len + 1);
        if (!b)
            return -1;
        f->buf = b;
        f->buf_cap = text_len + 1;
    }
    return 0;
}

static int fields_push(cf_csv_fields *f, size_t off)
{
    if (f->count == f->cap) {
        size_t cap = f->cap ? 2 * f->cap : 16;
        size_t *o = realloc(f->off, cap * sizeof *o);
        if (!o)
            return -1;
        f->off = o;
        f->cap = cap;
    }
    f->off[f->count++] = off;
    return 0;
}

size_t cf_csv_content_length(const char *s, size_t n)
{
    int q = 0;
    size_t end = n;
    for (size_t i = 0; i < n; i++) {
        if (s[i] == '"')
            q = !q;
        else if (s[i] == '#' && !q) {
            end = i;
            break;
        }
    }
    while (end > 0 && (s[end - 1] == ' ' || s[end - 1] == '\t'))
        end--;
    return end;
}

int cf_csv_is_comment(const cf_csv_line *l)
{
    size_t i = 0;
    while (i < l->n && (l->s[i] == ' ' || l->s[i] == '\t'))
        i++;
    return i < l->n && l->s[i] == '#';
}

char cf_csv_delimiter(const char *s, size_t n)
{
    size_t comma = 0, semi = 0, tab = 0;
    int q = 0;
    for (size_t i = 0; i < n; i++) {
        if (s[i] == '"')
            q = !q;
        else if (!q && s[i] == ',')
            comma++;
        else if (!q && s[i] == ';')
            semi++;
        else if (!q && s[i] == '\t')
            tab++;
    }
    if (tab > comma && tab > semi)
        return '\t';
    if (semi > comma)
        return ';';
    if (comma > 0)
        return ',';
    /* none of them: columns separated by blanks (a .txt table), when there are two fields */
    size_t nf = 0;
    for (size_t i = 0; i < n; i++)
        if (s[i] != ' ' && (i == 0 || s[i - 1] == ' ') && s[i] != '[' && s[i] != '(')
            nf++;
    return nf >= 2 ? ' ' : 0;
}

static int is_blank(char c, char delim)
{
    return c == ' ' || (c == '\t' && delim != '\t');
}

/* Splits a whitespace-separated line (delimiter ' ': runs of blanks and TABs) into f. A field
** may be double-quoted (with "" for a quote inside); a field that starts with '[' or '(' belongs
** to the one before it, so that "stress [kPa]" stays one column name. Returns as cf_csv_split(). */
static int split_blanks(const char *s, size_t n, cf_csv_fields *f, size_t *bad_col,
                        const char **why)
{
    f->count = 0;
    if (fields_reserve(f, n) != 0)
        return -2;
    size_t i = 0, o = 0;
    for (;;) {
        while (i < n && (s[i] == ' ' || s[i] == '\t'))
            i++;
        if (i >= n)
            return 0;
        int joined = f->count > 0 && (s[i] == '[' || s[i] == '(');
        if (joined)
            f->buf[o - 1] = ' '; /* the previous field goes on: its NUL becomes a blank */
        else if (fields_push(f, o) != 0)
            return -2;
        if (s[i] == '"') {
            for (i++;; i++) {
                if (i >= n) {
                    *bad_col = f->count;
                    *why = "unterminated double quote";
                    return -1;
                }
                if (s[i] == '"' && i + 1 < n && s[i + 1] == '"')
                    f->buf[o++] = s[i++];
                else if (s[i] == '"')
                    break;
                else
                    f->buf[o++] = s[i];
            }
            i++;
        } else {
            while (i < n && s[i] != ' ' && s[i] != '\t') {
                if (s[i] == '"') {
                    *bad_col = f->count;
                    *why = "double quote inside an unquoted field";
                    return -1;
                }
                f->buf[o++] = s[i++];
            }
        }
        f->buf[o++] = '\0';
    }
}

int cf_csv_split(const char *s, size_t n, char delim, cf_csv_fields *f, size_t *bad_col,
                 const char **why)
{
    if (delim == ' ')
        return split_blanks(s, n, f, bad_col, why);
    f->count = 0;
    if (fields_reserve(f, n) != 0)
        return -2;
    size_t i = 0, o = 0;
    for (;;) {
        while (i < n && is_blank(s[i], delim))
            i++;
        if (fields_push(f, o) != 0)
            return -2;
        if (i < n && s[i] == '"') {
            i++;
            for (;;) {
                if (i >= n) {
                    *bad_col = f->count;
                    *why = "unterminated double quote";
                    return -1;
                }
                if (s[i] == '"') {
                    if (i + 1 < n && s[i + 1] == '"') {
                        f->buf[o++] = '"';
                        i += 2;
                        continue;
                    }
                    i++;
                    break;
                }
                f->buf[o++] = s[i++];
            }
            while (i < n && is_blank(s[i], delim))
                i++;
            if (i < n && s[i] != delim) {
                *bad_col = f->count;
                *why = "text after a closing double quote";
                return -1;
            }
        } else {
            size_t start = o;
            while (i < n && s[i] != delim) {
                if (s[i] == '"') {
                    *bad_col = f->count;
                    *why = "double quote inside an unquoted field";
                    return -1;
                }
                f->buf[o++] = s[i++];
            }
            while (o > start && is_blank(f->buf[o - 1], delim))
                o--;
        }
        f->buf[o++] = '\0';
        if (i >= n)
            return 0;
        i++; /* the delimiter: another field follows, possibly empty */
        if (fields_reserve(f, n + f->count + 1) != 0)
            return -2;
    }
}

void cf_csv_trim_copy(char *out, size_t cap, const char *s, size_t n)
{
    while (n > 0 && isspace((unsigned char)*s)) {
        s++;
        n--;
    }
    while (n > 0 && isspace((unsigned char)s[n - 1]))
        n--;
    if (n >= cap)
        n = cap - 1;
    memcpy(out, s, n);
    out[n] = '\0';
}

/* ---- bytes and characters -------------------------------------------------------------------- */

size_t cf_csv_bad_byte(const unsigned char *s, size_t n)
{
    size_t i = 0, len;
    while (i < n) {
        if (s[i] == '\t')
            len = 1;
        else if ((len = cf_text_char_length(s + i, n - i)) == 0)
            return i;
        i += len;
    }
    return n;
}

void cf_csv_utf8_copy(char *dst, size_t cap, const char *src)
{
    size_t o = 0, n = strlen(src), i = 0;
    while (i < n && o + 1 < cap) {
        const unsigned char *p = (const unsigned char *)src + i;
        size_t len = 1;
        if (*p >= 0x80) {
            len = *p >= 0xf0 ? 4 : *p >= 0xe0 ? 3 : 2;
            if (i + len > n || cf_csv_bad_byte(p, len) != len)
                len = 0; /* not a valid character here */
        } else if (*p < 0x20 || *p == 0x7f) {
            len = 0;
        }
        if (len == 0) {
            dst[o++] = '?';
            i++;
            continue;
        }
        if (o + len + 1 > cap)
            break;
        memcpy(dst + o, p, len);
        o += len;
        i += len;
    }
    dst[o] = '\0';
}

/* ---- numbers --------------------------------------------------------------------------------- */

cf_csv_num cf_csv_number(const char *text, char delim, double *out)
{
    char tmp[128];
    size_t n = strlen(text);
    if (n == 0)
        return CF_CSV_NUM_EMPTY;
    if (n >= sizeof tmp)
        return CF_CSV_NUM_NOT_NUMBER;
    memcpy(tmp, text, n + 1);
    const char *p = tmp;
    if (*p == '+' || *p == '-')
        p++;
    if (strncasecmp(p, "nan", 3) == 0 || strncasecmp(p, "inf", 3) == 0)
        return CF_CSV_NUM_NOT_FINITE;
    if (delim != ',') {
        char *comma = strchr(tmp, ',');
        if (comma && !strchr(tmp, '.') && !strchr(comma + 1, ','))
            *comma = '.';
    }
    for (const char *c = p; *c; c++)
        if (!isdigit((unsigned char)*c) && *c != '.' && *c != 'e' && *c != 'E' && *c != '+' &&
            *c != '-')
            return CF_CSV_NUM_NOT_NUMBER;
    char *end = NULL;
    errno = 0;
    double v = strtod(tmp, &end);
    if (end == tmp || *end != '\0')
        return CF_CSV_NUM_NOT_NUMBER;
    if (!isfinite(v) || (errno == ERANGE && fabs(v) > 1.0))
        return CF_CSV_NUM_NOT_FINITE;
    *out = v;
    return CF_CSV_NUM_OK;
}

