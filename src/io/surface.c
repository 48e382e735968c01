/*
** Closed triangulated surfaces (surface.h): OBJ and STL read as data, the checks a solid's
** boundary passes, and the smoothing that removes a local self-crossing (a fold of a few
** triangles, as in scanned or smoothed organ surfaces) before a volume mesher sees it.
*/
#include "io/surface.h"
#include "io/surface_geom.h"

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

/* info started; every triangle with an area (else refused, named). */
static cf_status has_area(const cf_surface *s, const char *name, cf_mesh_surface_info *info,
                          cf_error *err)
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
    return CF_OK;
}

/* Each marked vertex to the mean of its neighbours (each met twice: the mean holds); the moves
** into info. */
static void smooth_marked(cf_surface *s, const uint8_t *mark, uint8_t *moved, double *sum,
                          uint32_t *cnt, double unit_mm, cf_mesh_surface_info *info)
{
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

cf_status cf_surface_prepare(cf_surface *s, const char *name, double unit_mm, double size_mm,
                             cf_mesh_surface_info *info, cf_error *err)
{
    cf_status st = has_area(s, name, info, err);
    if (st == CF_OK)
        st = closed(s, name, err);
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
    double area = 0;
    for (size_t t = 0; t < s->nf; t++) {
        const uint32_t *v = s->tri + 3 * t;
        double e1[3], e2[3], c[3];
        sub3(s->X + 3 * (size_t)v[1], s->X + 3 * (size_t)v[0], e1);
        sub3(s->X + 3 * (size_t)v[2], s->X + 3 * (size_t)v[0], e2);
        cross3(e1, e2, c);
        area += 0.5 * sqrt(dot3(c, c)) * unit_mm * unit_mm;
    }
    info->estimated_nodes = info->estimated_tets / 8 + 1.15 * area / (size_mm * size_mm);
    if (info->estimated_tets > CF_MESH_MAX_FILL_TETS) /* 5e6 */
        return cf_error_set(err, CF_E_DATA, "%s: element size %g mm would fill the %.4g mm^3 it "
                            "encloses with about %.3g tetrahedra, over 5e6", name, size_mm, V,
                            info->estimated_tets);
    if ((st = cf_surface_nested_shells(s, name, unit_mm, info, err)) != CF_OK)
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
        long n = cf_surface_crossings(s, mark, &a, &b, &t, &info->pair_tests);
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
        smooth_marked(s, mark, moved, sum, cnt, unit_mm, info);
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
