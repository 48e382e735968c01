/*
** Closed triangulated surfaces (surface.h): OBJ and STL read as data, the checks a solid's
** boundary passes, and the smoothing that removes a local self-crossing (a fold of a few
** triangles, as in scanned or smoothed organ surfaces) before a volume mesher sees it.
*/
#include "io/surface.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

void cf_surface_free(cf_surface *s)
{
    if (!s)
        return;
    free(s->X);
    free(s->tri);
    memset(s, 0, sizeof *s);
}

static int ends_with(const char *path, const char *ext)
{
    size_t n = strlen(path), e = strlen(ext);
    return n > e && strcasecmp(path + n - e, ext) == 0;
}

int cf_surface_name(const char *path)
{
    return ends_with(path, ".obj") || ends_with(path, ".stl");
}

/* Appends to a growing array (cap doubles); 0 when memory runs out. */
static int grow(void **p, size_t *cap, size_t need, size_t size)
{
    if (need <= *cap)
        return 1;
    size_t nc = *cap ? 2 * *cap : 1024;
    while (nc < need)
        nc *= 2;
    void *q = realloc(*p, nc * size);
    if (!q)
        return 0;
    *p = q;
    *cap = nc;
    return 1;
}

/* OBJ: "v x y z" and "f i j k ..." (i, i/t, i//n or i/t/n; negative counts from the end); every
** other line ignored. */
static cf_status read_obj(FILE *f, const char *path, cf_surface *s, cf_error *err)
{
    char *line = NULL;
    size_t lcap = 0, vcap = 0, tcap = 0;
    long lineno = 0;
    cf_status st = CF_OK;
    while (getline(&line, &lcap, f) >= 0 && st == CF_OK) {
        lineno++;
        char *p = line;
        while (*p == ' ' || *p == '\t')
            p++;
        if (p[0] == 'v' && (p[1] == ' ' || p[1] == '\t')) {
            double x[3];
            char *q = p + 1, *e;
            for (int a = 0; a < 3; a++, q = e) {
                x[a] = strtod(q, &e);
                if (e == q || !isfinite(x[a])) {
                    st = cf_error_set(err, CF_E_DATA, "%s:%ld: a vertex needs three finite "
                                      "numbers", path, lineno);
                    break;
                }
            }
            if (st)
                break;
            if (s->nv >= UINT32_MAX || !grow((void **)&s->X, &vcap, 3 * (s->nv + 1), sizeof *s->X))
                goto oom;
            memcpy(s->X + 3 * s->nv++, x, sizeof x);
        } else if (p[0] == 'f' && (p[1] == ' ' || p[1] == '\t')) {
            uint32_t first = 0, prev = 0;
            int n = 0;
            char *q = p + 1, *e;
            for (;;) {
                while (*q == ' ' || *q == '\t')
                    q++;
                if (!*q || *q == '\n' || *q == '\r' || *q == '#')
                    break;
                long i = strtol(q, &e, 10);
                if (e == q) {
                    st = cf_error_set(err, CF_E_DATA, "%s:%ld: a face's corners must be vertex "
                                      "numbers", path, lineno);
                    break;
                }
                while (*e && *e != ' ' && *e != '\t' && *e != '\n' && *e != '\r')
                    e++; /* texture and normal numbers */
                q = e;
                long idx = i > 0 ? i - 1 : (long)s->nv + i;
                if (i == 0 || idx < 0 || idx >= (long)s->nv) {
                    st = cf_error_set(err, CF_E_DATA, "%s:%ld: vertex %ld is not defined before "
                                      "its face", path, lineno, i);
                    break;
                }
                uint32_t v = (uint32_t)idx;
                if (n == 0)
                    first = v;
                else if (n >= 2) { /* a fan around the first corner */
                    if (!grow((void **)&s->tri, &tcap, 3 * (s->nf + 1), sizeof *s->tri))
                        goto oom;
                    uint32_t *t = s->tri + 3 * s->nf++;
                    t[0] = first;
                    t[1] = prev;
                    t[2] = v;
                }
                prev = v;
                n++;
            }
            if (st == CF_OK && n < 3)
                st = cf_error_set(err, CF_E_DATA, "%s:%ld: a face needs at least three corners",
                                  path, lineno);
        }
    }
    free(line);
    return st;
oom:
    free(line);
    return cf_error_set(err, CF_E_INTERNAL, "%s: out of memory for the surface", path);
}

/* STL vertices, three per triangle in order, into s->X (merged below). */
static cf_status read_stl(FILE *f, const char *path, cf_surface *s, cf_error *err)
{
    unsigned char head[84];
    size_t got = fread(head, 1, sizeof head, f);
    long size = -1;
    if (fseek(f, 0, SEEK_END) == 0)
        size = ftell(f);
    rewind(f);
    uint32_t n = got == 84 ? (uint32_t)head[80] | (uint32_t)head[81] << 8 |
                                 (uint32_t)head[82] << 16 | (uint32_t)head[83] << 24
                           : 0;
    size_t cap = 0;
    if (got == 84 && size == 84 + 50 * (long)n) { /* binary: 50 bytes a triangle */
        if (3 * (size_t)n >= UINT32_MAX)
            return cf_error_set(err, CF_E_DATA, "%s: %u triangles: too many", path, n);
        fseek(f, 84, SEEK_SET);
        if (!grow((void **)&s->X, &cap, 9 * (size_t)n + 1, sizeof *s->X))
            goto oom;
        for (uint32_t t = 0; t < n; t++) {
            unsigned char r[50];
            if (fread(r, 1, 50, f) != 50)
                return cf_error_set(err, CF_E_DATA, "%s: triangle %u: the file ends", path, t + 1);
            for (int k = 0; k < 9; k++) {
                float x;
                unsigned char b[4] = {r[12 + 4 * k], r[13 + 4 * k], r[14 + 4 * k], r[15 + 4 * k]};
                uint32_t u = (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 |
                             (uint32_t)b[3] << 24;
                memcpy(&x, &u, sizeof x);
                if (!isfinite(x))
                    return cf_error_set(err, CF_E_DATA, "%s: triangle %u has a coordinate that "
                                        "is not finite", path, t + 1);
                s->X[9 * (size_t)t + (size_t)k] = x;
            }
        }
        s->nv = 3 * (size_t)n;
        return CF_OK;
    }
    /* ASCII: every "vertex x y z" */
    char *line = NULL;
    size_t lcap = 0;
    long lineno = 0;
    while (getline(&line, &lcap, f) >= 0) {
        lineno++;
        char *p = line;
        while (*p == ' ' || *p == '\t')
            p++;
        if (strncmp(p, "vertex", 6) != 0)
            continue;
        char *q = p + 6, *e;
        if (!grow((void **)&s->X, &cap, 3 * (s->nv + 1), sizeof *s->X)) {
            free(line);
            goto oom;
        }
        for (int a = 0; a < 3; a++, q = e) {
            s->X[3 * s->nv + (size_t)a] = strtod(q, &e);
            if (e == q || !isfinite(s->X[3 * s->nv + (size_t)a])) {
                free(line);
                return cf_error_set(err, CF_E_DATA, "%s:%ld: a vertex needs three finite "
                                    "numbers", path, lineno);
            }
        }
        if (++s->nv >= UINT32_MAX) {
            free(line);
            return cf_error_set(err, CF_E_DATA, "%s: too many vertices", path);
        }
    }
    free(line);
    if (s->nv % 3)
        return cf_error_set(err, CF_E_DATA, "%s: %zu vertices: not three a facet", path, s->nv);
    return CF_OK;
oom:
    return cf_error_set(err, CF_E_INTERNAL, "%s: out of memory for the surface", path);
}

typedef struct stl_vertex {
    double x[3];
    uint32_t i; /* its place in the file's order */
} stl_vertex;

static int cmp_vertex(const void *pa, const void *pb)
{
    const double *x = ((const stl_vertex *)pa)->x, *y = ((const stl_vertex *)pb)->x;
    for (int k = 0; k < 3; k++)
        if (x[k] != y[k])
            return (x[k] > y[k]) - (x[k] < y[k]);
    return 0;
}

/* An STL's triangles: its 3 nf vertices merged where their coordinates are equal. */
static cf_status merge_stl(cf_surface *s, const char *path, cf_error *err)
{
    const size_t n = s->nv;
    stl_vertex *o = malloc((n ? n : 1) * sizeof *o);
    s->tri = malloc((n ? n : 1) * sizeof *s->tri);
    double *X = malloc((n ? 3 * n : 1) * sizeof *X);
    if (!o || !s->tri || !X) {
        free(o);
        free(X);
        return cf_error_set(err, CF_E_INTERNAL, "%s: out of memory for the surface", path);
    }
    for (size_t i = 0; i < n; i++) {
        memcpy(o[i].x, s->X + 3 * i, sizeof o[i].x);
        o[i].i = (uint32_t)i;
    }
    qsort(o, n, sizeof *o, cmp_vertex);
    size_t nv = 0;
    for (size_t k = 0; k < n; k++) {
        if (k == 0 || cmp_vertex(&o[k], &o[k - 1]) != 0) {
            memcpy(X + 3 * nv, o[k].x, 3 * sizeof *X);
            nv++;
        }
        s->tri[o[k].i] = (uint32_t)(nv - 1);
    }
    free(s->X);
    s->X = X;
    s->nf = n / 3;
    s->nv = nv;
    free(o);
    return CF_OK;
}

cf_status cf_surface_read(const char *path, cf_surface *s, cf_error *err)
{
    memset(s, 0, sizeof *s);
    FILE *f = fopen(path, "rb");
    if (!f)
        return cf_error_set(err, CF_E_NOINPUT, "%s: cannot open surface: %s", path,
                            strerror(errno));
    const int stl = ends_with(path, ".stl");
    cf_status st = stl ? read_stl(f, path, s, err) : read_obj(f, path, s, err);
    fclose(f);
    if (st == CF_OK && stl)
        st = merge_stl(s, path, err);
    if (st == CF_OK && (s->nf < 4 || s->nv < 4))
        st = cf_error_set(err, CF_E_DATA, "%s: %zu triangles on %zu vertices: not a closed "
                          "surface", path, s->nf, s->nv);
    if (st != CF_OK)
        cf_surface_free(s);
    return st;
}

static void sub3(const double *a, const double *b, double *c)
{
    for (int k = 0; k < 3; k++)
        c[k] = a[k] - b[k];
}

static void cross3(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Every edge in exactly two triangles, once in each direction. */
static cf_status closed(const cf_surface *s, const char *name, cf_error *err)
{
    uint64_t *d = malloc(3 * s->nf * sizeof *d);
    if (!d)
        return cf_error_set(err, CF_E_INTERNAL, "%s: out of memory for the surface", name);
    for (size_t t = 0; t < s->nf; t++)
        for (int k = 0; k < 3; k++)
            d[3 * t + (size_t)k] = (uint64_t)s->tri[3 * t + (size_t)k] << 32 |
                                   s->tri[3 * t + (size_t)(k + 1) % 3];
    qsort(d, 3 * s->nf, sizeof *d, cmp_u64);
    cf_status st = CF_OK;
    for (size_t i = 0; i < 3 * s->nf && st == CF_OK; i++) {
        uint32_t a = (uint32_t)(d[i] >> 32), b = (uint32_t)d[i];
        uint64_t back = (uint64_t)b << 32 | a;
        if (i + 1 < 3 * s->nf && d[i + 1] == d[i])
            st = cf_error_set(err, CF_E_DATA, "%s: the edge from vertex %u to vertex %u is in two "
                              "triangles the same way: not a closed, consistently oriented "
                              "surface", name, a + 1, b + 1);
        else if (!bsearch(&back, d, 3 * s->nf, sizeof *d, cmp_u64))
            st = cf_error_set(err, CF_E_DATA, "%s: the edge between vertices %u and %u is in one "
                              "triangle only (or two of opposite orientation): not a closed, "
                              "consistently oriented surface", name, a + 1, b + 1);
    }
    free(d);
    return st;
}

/* A bounding-volume tree over the triangles' boxes: the crossing test looks up, for each edge,
** only the triangles whose boxes meet the edge's box, in about log nf steps each, whatever the
** triangles' shapes (a sweep along one axis is quadratic when the triangles are long along it,
** as a cylinder's are). */
typedef struct bvh_node {
    double lo[3], hi[3];
    uint32_t first, count; /* a leaf's triangles: order[first .. first + count - 1] */
    uint32_t left;         /* an inner node's children: left and left + 1 */
    uint32_t common;       /* a corner every triangle under the node has, or UINT32_MAX: an edge
                           ** from it crosses none of them (a fan's centre: a cylinder's cap) */
} bvh_node;

typedef struct bvh {
    bvh_node *node;
    size_t nn;
    uint32_t *order;
    double *box; /* 6 nf: each triangle's lo[3], hi[3] */
    const uint32_t *tri;
} bvh;

typedef struct keyed {
    double key;
    uint32_t t;
} keyed;

static int cmp_keyed(const void *a, const void *b)
{
    double x = ((const keyed *)a)->key, y = ((const keyed *)b)->key;
    if (x != y)
        return (x > y) - (x < y);
    return (((const keyed *)a)->t > ((const keyed *)b)->t) -
           (((const keyed *)a)->t < ((const keyed *)b)->t);
}

/* Node k over order[first .. first + count - 1]: its box, split at the median of the centres
** along the longest side of their spread until four triangles or fewer are left. */
static void bvh_build(bvh *h, size_t k, uint32_t first, uint32_t count, keyed *tmp)
{
    bvh_node *n = &h->node[k];
    double clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int a = 0; a < 3; a++) {
        n->lo[a] = INFINITY;
        n->hi[a] = -INFINITY;
    }
    for (uint32_t i = first; i < first + count; i++) {
        const double *b = h->box + 6 * (size_t)h->order[i];
        for (int a = 0; a < 3; a++) {
            n->lo[a] = fmin(n->lo[a], b[a]);
            n->hi[a] = fmax(n->hi[a], b[3 + a]);
            clo[a] = fmin(clo[a], b[a] + b[3 + a]);
            chi[a] = fmax(chi[a], b[a] + b[3 + a]);
        }
    }
    n->first = first;
    n->count = count;
    n->common = UINT32_MAX;
    if (count <= 4) {
        const uint32_t *T0 = h->tri + 3 * (size_t)h->order[first];
        for (int c = 0; c < 3 && n->common == UINT32_MAX; c++) {
            uint32_t i = first + 1;
            for (; i < first + count; i++) {
                const uint32_t *T = h->tri + 3 * (size_t)h->order[i];
                if (T[0] != T0[c] && T[1] != T0[c] && T[2] != T0[c])
                    break;
            }
            if (i == first + count)
                n->common = T0[c];
        }
        return;
    }
    int ax = 0;
    for (int a = 1; a < 3; a++)
        if (chi[a] - clo[a] > chi[ax] - clo[ax])
            ax = a;
    for (uint32_t i = 0; i < count; i++) {
        const double *b = h->box + 6 * (size_t)h->order[first + i];
        tmp[i].key = b[ax] + b[3 + ax];
        tmp[i].t = h->order[first + i];
    }
    qsort(tmp, count, sizeof *tmp, cmp_keyed);
    for (uint32_t i = 0; i < count; i++)
        h->order[first + i] = tmp[i].t;
    const uint32_t half = count / 2;
    n->count = 0;
    n->left = (uint32_t)h->nn;
    h->nn += 2;
    bvh_build(h, n->left, first, half, tmp);
    bvh_build(h, h->node[k].left + 1, first + half, count - half, tmp);
    const uint32_t l = h->node[k].left;
    if (h->node[l].common == h->node[l + 1].common)
        h->node[k].common = h->node[l].common;
}

static void bvh_free(bvh *h)
{
    free(h->node);
    free(h->order);
    free(h->box);
}

/* The tree over s's triangles; 0 when memory runs out. */
static int bvh_make(const cf_surface *s, bvh *h)
{
    memset(h, 0, sizeof *h);
    h->node = malloc(2 * s->nf * sizeof *h->node);
    h->order = malloc(s->nf * sizeof *h->order);
    h->box = malloc(6 * s->nf * sizeof *h->box);
    keyed *tmp = malloc(s->nf * sizeof *tmp);
    if (!h->node || !h->order || !h->box || !tmp) {
        free(tmp);
        bvh_free(h);
        return 0;
    }
    for (size_t t = 0; t < s->nf; t++) {
        const uint32_t *v = s->tri + 3 * t;
        for (int a = 0; a < 3; a++) {
            const double x = s->X[3 * v[0] + a], y = s->X[3 * v[1] + a], z = s->X[3 * v[2] + a];
            h->box[6 * t + (size_t)a] = fmin(x, fmin(y, z));
            h->box[6 * t + 3 + (size_t)a] = fmax(x, fmax(y, z));
        }
        h->order[t] = (uint32_t)t;
    }
    h->nn = 1;
    h->tri = s->tri;
    bvh_build(h, 0, 0, (uint32_t)s->nf, tmp);
    free(tmp);
    return 1;
}

/* Moller and Trumbore's segment-triangle test (P + t D, t in [0, 1], against triangle T), ends
** and edges included. */
static int segment_hits(const cf_surface *s, const double *P, const double *D, const uint32_t *T)
{
    double e1[3], e2[3], h[3], q[3], r[3];
    sub3(s->X + 3 * (size_t)T[1], s->X + 3 * (size_t)T[0], e1);
    sub3(s->X + 3 * (size_t)T[2], s->X + 3 * (size_t)T[0], e2);
    cross3(D, e2, h);
    const double det = dot3(e1, h);
    if (fabs(det) < 1e-300)
        return 0;
    sub3(P, s->X + 3 * (size_t)T[0], r);
    const double u = dot3(r, h) / det;
    if (u < 0 || u > 1)
        return 0;
    cross3(r, e1, q);
    const double v = dot3(D, q) / det;
    if (v < 0 || u + v > 1)
        return 0;
    const double tt = dot3(e2, q) / det;
    return tt >= 0 && tt <= 1;
}

/* The crossings of edge a-b with the triangles of the tree (not its own): counted into *hits,
** their corners marked, the first recorded. */
static void edge_crossings(const cf_surface *s, const bvh *h, uint32_t a, uint32_t b,
                           uint8_t *mark, long *hits, uint32_t *fa, uint32_t *fb, uint32_t *ft,
                           size_t *tests)
{
    const double *P = s->X + 3 * (size_t)a;
    double D[3], lo[3], hi[3];
    sub3(s->X + 3 * (size_t)b, P, D);
    for (int k = 0; k < 3; k++) {
        lo[k] = fmin(P[k], P[k] + D[k]);
        hi[k] = fmax(P[k], P[k] + D[k]);
    }
    size_t stack[128], top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const bvh_node *n = &h->node[stack[--top]];
        if (n->common == a || n->common == b || n->lo[0] > hi[0] || n->hi[0] < lo[0] ||
            n->lo[1] > hi[1] || n->hi[1] < lo[1] || n->lo[2] > hi[2] || n->hi[2] < lo[2])
            continue;
        if (n->count == 0) {
            stack[top++] = n->left;
            stack[top++] = n->left + 1;
            continue;
        }
        for (uint32_t i = n->first; i < n->first + n->count; i++) {
            const uint32_t t = h->order[i];
            const uint32_t *T = s->tri + 3 * (size_t)t;
            if (T[0] == a || T[1] == a || T[2] == a || T[0] == b || T[1] == b || T[2] == b)
                continue;
            ++*tests;
            if (!segment_hits(s, P, D, T))
                continue;
            if (*hits == 0) {
                *fa = a;
                *fb = b;
                *ft = t;
            }
            ++*hits;
            mark[a] = mark[b] = mark[T[0]] = mark[T[1]] = mark[T[2]] = 1;
        }
    }
}

/* Marks (mark[v] = 1) the corners of every edge that crosses a triangle not its own, and that
** triangle's corners; returns the number of crossings, or -1 when memory runs out. *fa, *fb and
** *ft get the first crossing found; *tests counts the edge-triangle tests made. */
static long crossings(const cf_surface *s, uint8_t *mark, uint32_t *fa, uint32_t *fb, uint32_t *ft,
                      size_t *tests)
{
    bvh h;
    if (!bvh_make(s, &h))
        return -1;
    long hits = 0;
    for (size_t e = 0; e < s->nf; e++)
        for (int k = 0; k < 3; k++) {
            uint32_t a = s->tri[3 * e + (size_t)k], b = s->tri[3 * e + (size_t)(k + 1) % 3];
            if (a < b) /* each edge once (a closed surface has it both ways) */
                edge_crossings(s, &h, a, b, mark, &hits, fa, fb, ft, tests);
        }
    bvh_free(&h);
    return hits;
}

static double enclosed(const cf_surface *s)
{
    double V = 0;
    for (size_t t = 0; t < s->nf; t++) {
        const uint32_t *v = s->tri + 3 * t;
        double c[3];
        cross3(s->X + 3 * (size_t)v[1], s->X + 3 * (size_t)v[2], c);
        V += dot3(s->X + 3 * (size_t)v[0], c) / 6;
    }
    return V;
}

static uint32_t find_root(uint32_t *up, uint32_t v)
{
    while (up[v] != v)
        v = up[v] = up[up[v]];
    return v;
}

/* The closed shells of s (triangles joined by their corners): each vertex's shell into shell[]
** (0 .. count - 1), the count returned; 0 when memory runs out. */
static size_t find_shells(const cf_surface *s, uint32_t *shell)
{
    uint32_t *up = malloc(s->nv * sizeof *up);
    if (!up)
        return 0;
    for (size_t v = 0; v < s->nv; v++)
        up[v] = (uint32_t)v;
    for (size_t t = 0; t < s->nf; t++)
        for (int k = 1; k < 3; k++) {
            uint32_t x = find_root(up, s->tri[3 * t]), y = find_root(up, s->tri[3 * t + k]);
            if (x != y)
                up[x > y ? x : y] = x > y ? y : x;
        }
    size_t n = 0;
    for (size_t v = 0; v < s->nv; v++) /* a root comes before the vertices under it */
        shell[v] = find_root(up, (uint32_t)v) == v ? (uint32_t)n++ : shell[find_root(up, (uint32_t)v)];
    free(up);
    return n;
}

/* How many times the shells other than `self` wind around point p, counted from their
** orientation (an outward shell around p: +1, a cavity's inward one: -1), by a ray from p. */
static int winding(const cf_surface *s, const uint32_t *shell, uint32_t self, const double *p)
{
    static const double dir[3] = {0.8017837257372732, 0.5345224838248488, 0.2672612419124244};
    int w = 0;
    for (size_t t = 0; t < s->nf; t++) {
        const uint32_t *T = s->tri + 3 * t;
        if (shell[T[0]] == self)
            continue;
        double e1[3], e2[3], h[3], q[3], r[3], n[3];
        sub3(s->X + 3 * (size_t)T[1], s->X + 3 * (size_t)T[0], e1);
        sub3(s->X + 3 * (size_t)T[2], s->X + 3 * (size_t)T[0], e2);
        cross3(dir, e2, h);
        const double det = dot3(e1, h);
        if (fabs(det) < 1e-300)
            continue;
        sub3(p, s->X + 3 * (size_t)T[0], r);
        const double u = dot3(r, h) / det;
        cross3(r, e1, q);
        const double v = dot3(dir, q) / det, tt = dot3(e2, q) / det;
        if (u < 0 || v < 0 || u + v > 1 || tt <= 0)
            continue;
        cross3(e1, e2, n); /* outward normal: the ray leaves the shell's inside */
        w += dot3(n, dir) > 0 ? 1 : -1;
    }
    return w;
}

/* A shell that faces outward inside the solid of another (winding number at one of its
** vertices >= 1) is a solid within a solid: Gmsh would mesh the space between them only. */
static cf_status nested_shells(const cf_surface *s, const char *name, double unit_mm,
                               cf_mesh_surface_info *info, cf_error *err)
{
    uint32_t *shell = malloc(s->nv * sizeof *shell);
    double *vol = NULL;
    uint32_t *first = NULL;
    cf_status st = CF_OK;
    const size_t n = shell ? find_shells(s, shell) : 0;
    if (n > 1) {
        vol = calloc(n, sizeof *vol);
        first = malloc(n * sizeof *first);
    }
    if (n == 0 || (n > 1 && (!vol || !first))) {
        st = cf_error_set(err, CF_E_INTERNAL, "%s: out of memory for the surface", name);
    } else if (n > 1) {
        for (size_t t = 0; t < s->nf; t++) {
            const uint32_t *v = s->tri + 3 * t;
            double c[3];
            cross3(s->X + 3 * (size_t)v[1], s->X + 3 * (size_t)v[2], c);
            vol[shell[v[0]]] += dot3(s->X + 3 * (size_t)v[0], c) / 6;
        }
        for (size_t v = s->nv; v-- > 0;)
            first[shell[v]] = (uint32_t)v;
        for (size_t k = 0; k < n && st == CF_OK; k++) {
            const double *p = s->X + 3 * (size_t)first[k];
            if (vol[k] > 0 && winding(s, shell, (uint32_t)k, p) >= 1)
                st = cf_error_set(err, CF_E_DATA, "%s: the closed shell through vertex %u (%.4g "
                                  "mm^3) lies inside the solid of another shell and faces "
                                  "outward too: a solid within a solid, which would be meshed "
                                  "as a hollow body (a cavity's triangles must face into it; "
                                  "two bodies need two files)", name, first[k] + 1,
                                  vol[k] * unit_mm * unit_mm * unit_mm);
        }
    }
    info->shells = n;
    free(shell);
    free(vol);
    free(first);
    return st;
}

/* Each triangle into four at its edges' midpoints (the same shape, every edge halved); 0 when
** memory runs out (s unchanged). */
static int split_in_four(cf_surface *s)
{
    const size_t ne = 3 * s->nf / 2; /* a closed surface: every edge in two triangles */
    uint64_t *key = malloc(3 * s->nf * sizeof *key);
    double *X = malloc(3 * (s->nv + ne) * sizeof *X);
    uint32_t *tri = malloc(12 * s->nf * sizeof *tri);
    if (!key || !X || !tri) {
        free(key);
        free(X);
        free(tri);
        return 0;
    }
    for (size_t t = 0; t < s->nf; t++)
        for (int k = 0; k < 3; k++) {
            uint32_t a = s->tri[3 * t + (size_t)k], b = s->tri[3 * t + (size_t)(k + 1) % 3];
            key[3 * t + (size_t)k] = (uint64_t)(a < b ? a : b) << 32 | (a < b ? b : a);
        }
    qsort(key, 3 * s->nf, sizeof *key, cmp_u64);
    size_t nk = 0;
    for (size_t i = 0; i < 3 * s->nf; i++)
        if (i == 0 || key[i] != key[nk - 1])
            key[nk++] = key[i];
    memcpy(X, s->X, 3 * s->nv * sizeof *X);
    for (size_t e = 0; e < nk; e++)
        for (int c = 0; c < 3; c++)
            X[3 * (s->nv + e) + (size_t)c] = 0.5 * (s->X[3 * (size_t)(key[e] >> 32) + (size_t)c] +
                                                    s->X[3 * (size_t)(uint32_t)key[e] + (size_t)c]);
    for (size_t t = 0; t < s->nf; t++) {
        uint32_t v[3], m[3];
        for (int k = 0; k < 3; k++) {
            v[k] = s->tri[3 * t + (size_t)k];
            uint32_t a = v[k], b = s->tri[3 * t + (size_t)(k + 1) % 3];
            uint64_t q = (uint64_t)(a < b ? a : b) << 32 | (a < b ? b : a);
            m[k] = (uint32_t)(s->nv + (size_t)((uint64_t *)bsearch(&q, key, nk, sizeof *key,
                                                                    cmp_u64) - key));
        }
        const uint32_t four[4][3] = {{v[0], m[0], m[2]}, {m[0], v[1], m[1]}, {m[2], m[1], v[2]},
                                     {m[0], m[1], m[2]}};
        memcpy(tri + 12 * t, four, sizeof four);
    }
    free(key);
    free(s->X);
    free(s->tri);
    s->X = X;
    s->tri = tri;
    s->nv += nk;
    s->nf *= 4;
    return 1;
}

cf_status cf_surface_prepare(cf_surface *s, const char *name, double unit_mm, double size_mm,
                             cf_mesh_surface_info *info, cf_error *err)
{
    memset(info, 0, sizeof *info);
    info->vertices = s->nv;
    info->triangles = s->nf;
    double ext = 0;
    for (size_t i = 0; i < 3 * s->nv; i++)
        ext = fmax(ext, fabs(s->X[i]));
    for (size_t t = 0; t < s->nf; t++) {
        const uint32_t *v = s->tri + 3 * t;
        double e1[3], e2[3], c[3];
        sub3(s->X + 3 * (size_t)v[1], s->X + 3 * (size_t)v[0], e1);
        sub3(s->X + 3 * (size_t)v[2], s->X + 3 * (size_t)v[0], e2);
        cross3(e1, e2, c);
        if (!(sqrt(dot3(c, c)) > 1e-24 * ext * ext))
            return cf_error_set(err, CF_E_DATA, "%s: triangle %zu (vertices %u, %u, %u) has no "
                                "area", name, t + 1, v[0] + 1, v[1] + 1, v[2] + 1);
    }
    cf_status st = closed(s, name, err);
    if (st)
        return st;
    if (enclosed(s) < 0) {
        info->reversed = 1;
        for (size_t t = 0; t < s->nf; t++) {
            uint32_t x = s->tri[3 * t + 1];
            s->tri[3 * t + 1] = s->tri[3 * t + 2];
            s->tri[3 * t + 2] = x;
        }
    }
    /* the fill's size first (it is cheap, the search for crossings is not): a regular
    ** tetrahedron of edge h holds h^3 / (6 sqrt 2) */
    const double V = fabs(enclosed(s)) * unit_mm * unit_mm * unit_mm;
    info->estimated_tets = V / (size_mm * size_mm * size_mm / (6 * sqrt(2)));
    if (info->estimated_tets > CF_MESH_MAX_FILL_TETS) /* 5e6 */
        return cf_error_set(err, CF_E_DATA, "%s: element size %g mm would fill the %.4g mm^3 it "
                            "encloses with about %.3g tetrahedra, over 5e6", name, size_mm, V,
                            info->estimated_tets);
    if ((st = nested_shells(s, name, unit_mm, info, err)) != CF_OK)
        return st;
    uint8_t *mark = malloc(s->nv), *moved = calloc(s->nv, 1);
    double *sum = malloc(3 * s->nv * sizeof *sum);
    uint32_t *cnt = malloc(s->nv * sizeof *cnt);
    if (!mark || !moved || !sum || !cnt) {
        st = cf_error_set(err, CF_E_INTERNAL, "%s: out of memory for the surface", name);
        goto end;
    }
    for (int round = 0;; round++) {
        uint32_t a = 0, b = 0, t = 0;
        memset(mark, 0, s->nv);
        long n = crossings(s, mark, &a, &b, &t, &info->pair_tests);
        if (n < 0) {
            st = cf_error_set(err, CF_E_INTERNAL, "%s: out of memory for the surface", name);
            break;
        }
        if (round == 0)
            info->crossings = (size_t)n;
        if (n == 0)
            break;
        if (round == CF_SURFACE_SMOOTH_ROUNDS) {
            const uint32_t *T = s->tri + 3 * (size_t)t;
            st = cf_error_set(err, CF_E_DATA, "%s: the surface crosses itself (the edge between "
                              "vertices %u and %u passes through triangle %u, vertices %u, %u, "
                              "%u) and %d rounds of smoothing did not undo it",
                              name, a + 1, b + 1, t + 1, T[0] + 1, T[1] + 1, T[2] + 1,
                              CF_SURFACE_SMOOTH_ROUNDS);
            break;
        }
        /* each marked vertex to the mean of its neighbours (each met twice: the mean holds) */
        memset(sum, 0, 3 * s->nv * sizeof *sum);
        memset(cnt, 0, s->nv * sizeof *cnt);
        for (size_t f = 0; f < s->nf; f++)
            for (int k = 0; k < 3; k++) {
                uint32_t p = s->tri[3 * f + (size_t)k], q = s->tri[3 * f + (size_t)(k + 1) % 3];
                for (int c = 0; c < 3; c++) {
                    sum[3 * (size_t)p + (size_t)c] += s->X[3 * (size_t)q + (size_t)c];
                    sum[3 * (size_t)q + (size_t)c] += s->X[3 * (size_t)p + (size_t)c];
                }
                cnt[p]++;
                cnt[q]++;
            }
        for (size_t v = 0; v < s->nv; v++) {
            if (!mark[v] || !cnt[v])
                continue;
            double d2 = 0;
            for (int c = 0; c < 3; c++) {
                double x = sum[3 * v + (size_t)c] / cnt[v];
                d2 += (x - s->X[3 * v + (size_t)c]) * (x - s->X[3 * v + (size_t)c]);
                s->X[3 * v + (size_t)c] = x;
            }
            info->max_move_mm = fmax(info->max_move_mm, sqrt(d2) * unit_mm);
            info->smoothed += !moved[v];
            moved[v] = 1;
        }
    }
    info->enclosed_mm3 = enclosed(s) * unit_mm * unit_mm * unit_mm;
    while (st == CF_OK && s->nf < CF_SURFACE_MIN_TRIANGLES)
        if (!split_in_four(s))
            st = cf_error_set(err, CF_E_INTERNAL, "%s: out of memory for the surface", name);
end:
    free(mark);
    free(moved);
    free(sum);
    free(cnt);
    return st;
}
