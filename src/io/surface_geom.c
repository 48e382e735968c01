/*
** Crossings and shells of closed surfaces (surface_geom.h).
*/
#include "io/surface_geom.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

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
long cf_surface_crossings(const cf_surface *s, uint8_t *mark, uint32_t *fa, uint32_t *fb,
                          uint32_t *ft, size_t *tests)
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
cf_status cf_surface_nested_shells(const cf_surface *s, const char *name, double unit_mm,
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

