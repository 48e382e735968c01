/*
** A biaxial table's ratio and a table's plane in the fibre frame (biaxial.h).
*/
#include "io/biaxial.h"

#include "io/columns.h"
#include "io/measures.h"
#include "model/mode.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


/* The comment whose first word is key (followed by ':'), its text after the colon and blanks in
** *v (up to end), its column (1-based, in the line after '#'); NULL when none. */
static const cf_csv_line *keyed_comment(const cf_csv_line *c, size_t n, const char *key,
                                        const char **v, const char **end)
{
    const size_t kl = strlen(key);
    for (size_t i = 0; i < n; i++) {
        const char *s = c[i].s, *e = s + c[i].n;
        while (s < e && isspace((unsigned char)*s))
            s++;
        if ((size_t)(e - s) <= kl || strncmp(s, key, kl) != 0 || s[kl] != ':')
            continue;
        s += kl + 1;
        while (s < e && isspace((unsigned char)*s))
            s++;
        *v = s;
        *end = e;
        return &c[i];
    }
    return NULL;
}

/* A positive finite number at *s (before end), *s moved past it; -1 when there is none. */
static double positive_at(const char **s, const char *end)
{
    char buf[64];
    size_t n = 0;
    while (*s + n < end && n + 1 < sizeof buf && strchr("0123456789.eE+-", (*s)[n]))
        n++;
    memcpy(buf, *s, n);
    buf[n] = '\0';
    char *stop = NULL;
    const double v = n ? strtod(buf, &stop) : -1;
    if (n == 0 || *stop != '\0' || !isfinite(v) || !(v > 0))
        return -1;
    *s += n;
    return v;
}

cf_status cf_comment_ratio(const cf_csv_line *comments, size_t ncomments, const char *path,
                           cf_table *m, cf_error *err)
{
    const char *v = NULL, *end = NULL;
    const cf_csv_line *c = keyed_comment(comments, ncomments, "ratio", &v, &end);
    if (!c)
        return cf_error_set(err, CF_E_DATA,
                            "%s: a biaxial table states the ratio of its strains (first:second "
                            "direction) in a comment '# ratio: A:B' (e.g. '# ratio: 1:0.75'); "
                            "none found", path);
    const char *s = v;
    double a = positive_at(&s, end), b = -1;
    while (s < end && isspace((unsigned char)*s))
        s++;
    if (a > 0 && s < end && *s == ':') {
        s++;
        while (s < end && isspace((unsigned char)*s))
            s++;
        b = positive_at(&s, end);
    }
    if (!(a > 0) || !(b > 0)) {
        size_t n = (size_t)(end - v);
        return cf_csv_error(err, path, c->line, (size_t)(v - c->s) + 2,
                            "comment 'ratio: %.*s': expected two positive numbers A:B, the "
                            "strain of the first direction to the second's ('%.*s')",
                            (int)(n > 40 ? 40 : n), v, (int)(n > 40 ? 40 : n), v);
    }
    m->ratio[0] = a;
    m->ratio[1] = b;
    m->ratio_line = c->line;
    return CF_OK;
}

int cf_plane_parse(const char *text, size_t n, char plane[3])
{
    while (n > 0 && isspace((unsigned char)text[n - 1]))
        n--;
    if (n != 2 || !strchr("fsn", text[0]) || !strchr("fsn", text[1]) || text[0] == text[1] ||
        !text[0] || !text[1])
        return -1;
    plane[0] = text[0];
    plane[1] = text[1];
    plane[2] = '\0';
    return 0;
}

/* The entry of the option plane for a table named name: *v, *n its plane text; 0 when none. */
static int plane_entry(const char *planes, const char *name, const char **v, size_t *n)
{
    if (!strchr(planes, '=')) {
        *v = planes;
        *n = strlen(planes);
        return 1;
    }
    for (const char *s = planes; *s;) {
        const char *comma = strchr(s, ','), *e = comma ? comma : s + strlen(s);
        const char *eq = memchr(s, '=', (size_t)(e - s));
        if (eq && (size_t)(eq - s) == strlen(name) && strncmp(s, name, (size_t)(eq - s)) == 0) {
            *v = eq + 1;
            *n = (size_t)(e - eq - 1);
            return 1;
        }
        s = comma ? comma + 1 : e;
    }
    return 0;
}

cf_status cf_table_plane(const cf_csv_line *comments, size_t ncomments, const char *planes,
                         cf_table *m, cf_error *err)
{
    char name[256];
    cf_table_name(m, name, sizeof name);
    const char *v = NULL, *end = NULL;
    size_t n = 0;
    const cf_csv_line *c = NULL;
    if (planes && plane_entry(planes, name, &v, &n)) {
        if (cf_plane_parse(v, n, m->plane) != 0)
            return cf_error_set(err, CF_E_DATA,
                                "%s: option plane: '%.*s' is not a plane: expected two "
                                "different letters of f (fibre), s (sheet), n (normal), as fs",
                                m->path, (int)(n > 40 ? 40 : n), v);
    } else if ((c = keyed_comment(comments, ncomments, "plane", &v, &end)) != NULL) {
        n = (size_t)(end - v);
        if (cf_plane_parse(v, n, m->plane) != 0)
            return cf_csv_error(err, m->path, c->line, (size_t)(v - c->s) + 2,
                                "comment 'plane: %.*s': expected two different letters of f "
                                "(fibre), s (sheet), n (normal), as fs ('%.*s')",
                                (int)(n > 40 ? 40 : n), v, (int)(n > 40 ? 40 : n), v);
        m->plane_line = c->line;
    } else
        return CF_OK;
    if (m->mode != CF_MODE_SHEAR && m->mode != CF_MODE_BIAXIAL && !c && !strchr(planes, '=')) {
        m->plane[0] = '\0'; /* one plane for every table: the shear and biaxial ones */
        return CF_OK;
    }
    if (m->mode != CF_MODE_SHEAR && m->mode != CF_MODE_BIAXIAL) {
        char where[48] = "";
        if (c)
            snprintf(where, sizeof where, ":%zu:1", c->line);
        return cf_error_set(err, CF_E_DATA,
                            "%s%s: plane '%s' given for a %s table: only shear and biaxial "
                            "tables lie in a plane of the fibre frame",
                            m->path, where, m->plane, cf_mode_name(m->mode));
    }
    return CF_OK;
}

/* ---- the reader's biaxial passes ------------------------------------------------------------ */

/* The second direction's strain and stress columns of a biaxial table, as "X,Y" (1-based numbers)
** into pair: the first strain and the first stress column after the first direction's. */
static cf_status second_pair(const reader *r, const layout *h, char *pair, size_t cap,
                             cf_error *err)
{
    long xi = -1, yi = -1;
    for (size_t i = 0; i < h->ncols; i++) {
        const long k = (long)i;
        if (k == h->xi || k == h->yi || k == h->wi || k == h->ti)
            continue;
        if (xi < 0 && k > h->xi && cf_column_is_x(r->cols[i].base))
            xi = k;
        else if (yi < 0 && k > h->yi && cf_column_is_y(r->cols[i].base))
            yi = k;
    }
    if (xi < 0 || yi < 0)
        return cf_csv_error(err, r->path, h->header_line, 1,
                            "a biaxial table holds a strain and a stress column for each of its "
                            "two directions (strain_f,strain_c,stress_f,stress_c): no second %s "
                            "column after '%s' ('%s')", xi < 0 ? "strain" : "stress",
                            r->cols[xi < 0 ? h->xi : h->yi].name, h->hq);
    snprintf(pair, cap, "%ld,%ld", xi + 1, yi + 1);
    return CF_OK;
}

/* What a first reading adds to the table from the comments: the plane, and a biaxial table's
** ratio and second pair of columns (pair, "" for any other table). */
cf_status cf_biaxial_frame(const reader *r, const layout *h, const cf_measure_options *opt,
                           cf_table *m, char *pair, size_t cap, cf_error *err)
{
    cf_status st = cf_table_plane(r->comments, r->ncomments, opt->plane, m, err);
    if (st != CF_OK || m->mode != CF_MODE_BIAXIAL)
        return st;
    if (strcmp(r->path, "(standard input)") == 0)
        return cf_error_set(err, CF_E_DATA, "(standard input): a biaxial table is read in two "
                            "passes, one per direction: give it as a file");
    if ((st = cf_comment_ratio(r->comments, r->ncomments, r->path, m, err)) != CF_OK)
        return st;
    return second_pair(r, h, pair, cap, err);
}

/* Appends b's rows (the second direction, read with pair's columns; its rows' lines in lines)
** to m's, after checking that they are the same load steps at m's ratio, in the same units and
** measures. */
cf_status cf_biaxial_stack(cf_table *m, const cf_table *b, const size_t *lines, const char *pair,
                           cf_error *err)
{
    const size_t n = m->count, col = (size_t)strtoul(pair, NULL, 10);
    if (b->count != n || b->y_to_file != m->y_to_file ||
        b->measures.stress != m->measures.stress || b->measures.strain != m->measures.strain)
        return cf_error_set(err, CF_E_DATA,
                            "%s: the biaxial table's second direction ('%s', '%s': %zu rows, "
                            "%s, %s stress) differs from its first ('%s', '%s': %zu rows, %s, %s "
                            "stress): both are read in one unit and measure, row by row",
                            m->path, b->x_column, b->y_column, b->count, b->y_unit,
                            cf_stress_measure_name(b->measures.stress), m->x_column, m->y_column,
                            n, m->y_unit, cf_stress_measure_name(m->measures.stress));
    const double a0 = m->ratio[0], a1 = m->ratio[1];
    for (size_t i = 0; i < n; i++) {
        const double u = b->x[i] * a0, v = m->x[i] * a1;
        if (!(fabs(u - v) <= 1e-9 * fmax(fabs(u), fabs(v))))
            return cf_csv_error(err, m->path, lines[i], col,
                                "%s %.9g against %s %.9g is not the ratio %.9g:%.9g of the "
                                "comment on line %zu (%s would be %.9g) ('%.9g')",
                                b->x_column, b->x[i], m->x_column, m->x[i], a0, a1, m->ratio_line,
                                b->x_column, m->x[i] * a1 / a0, b->x[i]);
    }
    double *p[4] = {m->x, m->y, m->w, m->t};
    const double *q[4] = {b->x, b->y, b->w, b->t};
    for (int k = 0; k < 4; k++) {
        if (!p[k] || !q[k])
            continue;
        double *g = realloc(p[k], 2 * n * sizeof *g);
        if (!g)
            return cf_error_set(err, CF_E_INTERNAL, "%s: out of memory", m->path);
        memcpy(g + n, q[k], n * sizeof *g);
        *(k == 0 ? &m->x : k == 1 ? &m->y : k == 2 ? &m->w : &m->t) = g;
    }
    m->second = n;
    m->count = 2 * n;
    snprintf(m->x2_column, sizeof m->x2_column, "%s", b->x_column);
    snprintf(m->y2_column, sizeof m->y2_column, "%s", b->y_column);
    return CF_OK;
}

