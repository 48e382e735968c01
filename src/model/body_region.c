/*
** Regions of a body (body.h): the nodes a selector picks (below or above a plane, inside a box or a
** sphere, on a physical group of the mesh's file), and a total force spread over a region as a
** traction on its part of the boundary.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/body_internal.h"

/* One row per selector kind: its name in a scene and whether a node at X is in it (tol: the
** slack of a comparison, mm). The group selector goes by the mesh's lists, not by position. */
typedef struct select_row {
    const char *name;
    int (*in)(const cf_select *s, const double *X, double tol);
} select_row;

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static int in_below(const cf_select *s, const double *X, double tol)
{
    return dot3(s->n, X) <= s->value_mm + tol;
}

static int in_above(const cf_select *s, const double *X, double tol)
{
    return dot3(s->n, X) >= s->value_mm - tol;
}

static int in_box(const cf_select *s, const double *X, double tol)
{
    for (int a = 0; a < 3; a++)
        if (!(X[a] >= s->lo_mm[a] - tol && X[a] <= s->hi_mm[a] + tol))
            return 0;
    return 1;
}

static int in_sphere(const cf_select *s, const double *X, double tol)
{
    double d[3] = {X[0] - s->center_mm[0], X[1] - s->center_mm[1], X[2] - s->center_mm[2]};
    return sqrt(dot3(d, d)) <= s->radius_mm + tol;
}

static const select_row rows[] = {
    [CF_SELECT_BELOW] = {"below", in_below},   [CF_SELECT_ABOVE] = {"above", in_above},
    [CF_SELECT_BOX] = {"box", in_box},         [CF_SELECT_SPHERE] = {"sphere", in_sphere},
    [CF_SELECT_GROUP] = {"group", NULL},
};

const char *cf_select_name(cf_select_kind kind)
{
    return (unsigned)kind < sizeof rows / sizeof rows[0] ? rows[kind].name : "?";
}

static int group_matches(const cf_select *s, const cf_mesh_group *g)
{
    if (s->group_dim >= 0 && g->dim != s->group_dim)
        return 0;
    return s->group_tag >= 0 ? g->tag == s->group_tag : strcmp(g->name, s->group_name) == 0;
}

size_t cf_mesh_select(const cf_mesh *m, const cf_select *s, uint8_t *mark)
{
    size_t count = 0;
    if (s->kind == CF_SELECT_GROUP) {
        for (size_t k = 0; k < m->ngroups; k++)
            if (group_matches(s, &m->groups[k]))
                for (size_t j = 0; j < m->groups[k].nnodes; j++)
                    mark[m->groups[k].nodes[j]] = 2; /* 2: this selector's, counted below */
        for (size_t i = 0; i < m->nn; i++)
            if (mark[i] == 2) {
                mark[i] = 1;
                count++;
            }
        return count;
    }
    if ((unsigned)s->kind >= sizeof rows / sizeof rows[0] || !rows[s->kind].in)
        return 0;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < m->nn; i++)
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(lo[a], m->X[3 * i + (size_t)a]);
            hi[a] = fmax(hi[a], m->X[3 * i + (size_t)a]);
        }
    const double tol = 1e-9 * fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
    for (size_t i = 0; i < m->nn; i++)
        if (rows[s->kind].in(s, m->X + 3 * i, tol)) {
            mark[i] = 1;
            count++;
        }
    return count;
}

/* A face of a tetrahedron: its corners sorted (for matching) and as the tetrahedron orders them. */
typedef struct face {
    uint32_t key[3];
    uint32_t v[3];
} face;

static int cmp_face(const void *pa, const void *pb)
{
    const face *a = pa, *b = pb;
    for (int k = 0; k < 3; k++)
        if (a->key[k] != b->key[k])
            return (a->key[k] > b->key[k]) - (a->key[k] < b->key[k]);
    return 0;
}

size_t cf_body_spread_force(const cf_body *b, const uint8_t *mark, const double F[3], double *f)
{
    static const int fv[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    double *w = calloc(b->nn, sizeof *w);
    face *fs = NULL;
    size_t nf = 0, cap = 0, got = 0;
    if (!w)
        return 0;
    /* the faces with all three corners marked; those met once are on the boundary */
    for (size_t t = 0; t < b->nt; t++)
        for (int k = 0; k < 4; k++) {
            face fc;
            for (int c = 0; c < 3; c++)
                fc.v[c] = fc.key[c] = b->tet[4 * t + (size_t)fv[k][c]];
            if (!mark[fc.v[0]] || !mark[fc.v[1]] || !mark[fc.v[2]])
                continue;
            for (int p = 0; p < 2; p++) /* sort the key's three corners */
                for (int c = 0; c < 2 - p; c++)
                    if (fc.key[c] > fc.key[c + 1]) {
                        uint32_t tmp = fc.key[c];
                        fc.key[c] = fc.key[c + 1];
                        fc.key[c + 1] = tmp;
                    }
            if (nf == cap) {
                size_t nc = cap ? 2 * cap : 256;
                face *n2 = realloc(fs, nc * sizeof *n2);
                if (!n2)
                    goto end;
                fs = n2;
                cap = nc;
            }
            fs[nf++] = fc;
        }
    if (nf)
        qsort(fs, nf, sizeof *fs, cmp_face);
    double wsum = 0;
    for (size_t i = 0; i < nf;) {
        size_t j = i + 1;
        while (j < nf && cmp_face(&fs[i], &fs[j]) == 0)
            j++;
        if (j == i + 1) { /* a boundary triangle: a third of its area to each corner */
            const double *p = b->X + 3 * fs[i].v[0], *q = b->X + 3 * fs[i].v[1],
                         *r = b->X + 3 * fs[i].v[2];
            double u[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
            double v[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
            double cr[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                            u[0] * v[1] - u[1] * v[0]};
            double A = 0.5 * sqrt(dot3(cr, cr));
            for (int c = 0; c < 3; c++)
                w[fs[i].v[c]] += A / 3;
            wsum += A;
        }
        i = j;
    }
    if (!(wsum > 0)) /* no boundary triangle: by nodal volume */
        for (size_t t = 0; t < b->nt; t++)
            for (int k = 0; k < 4; k++) {
                uint32_t a = b->tet[4 * t + (size_t)k];
                if (mark[a]) {
                    w[a] += b->V0[t] / 4;
                    wsum += b->V0[t] / 4;
                }
            }
    if (!(wsum > 0))
        goto end;
    for (size_t i = 0; i < b->nn; i++)
        if (w[i] > 0) {
            for (int a = 0; a < 3; a++)
                f[3 * i + (size_t)a] += F[a] * w[i] / wsum;
            got++;
        }
end:
    free(w);
    free(fs);
    return got;
}
