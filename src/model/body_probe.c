/*
** The probe's geometry (body_internal.h): how far a node is inside a sphere or a flat punch and
** the direction the probe pushes it, and whether a probe starts inside a body. Below the body's
** assembly and solvers, which call it.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/body_internal.h"

/* Penetration of the node at p into the probe whose reference point is at c, and the unit
** direction in which the probe pushes it. With signed = 0: 0 when the node is outside. With
** signed = 1 (a node of the active set): the signed depth along that direction, negative when the
** node has left the probe's surface. */
double cf_body_penetration(const cf_probe *pr, const double *c, const double *p, double nrm[3],
                           int sgn)
{
    double r[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
    if (pr->shape == CF_PROBE_SPHERE) {
        double d = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        if ((!sgn && !(d < pr->radius_mm)) || d == 0)
            return 0;
        for (int k = 0; k < 3; k++)
            nrm[k] = r[k] / d;
        return pr->radius_mm - d;
    }
    double s = r[0] * pr->dir[0] + r[1] * pr->dir[1] + r[2] * pr->dir[2];
    for (int k = 0; k < 3; k++)
        nrm[k] = pr->dir[k];
    if (sgn)
        return -s;
    if (!(s < 0))
        return 0;
    double rad2 = 0;
    for (int k = 0; k < 3; k++) {
        double q = r[k] - s * pr->dir[k];
        rad2 += q * q;
    }
    if (!(rad2 < pr->radius_mm * pr->radius_mm))
        return 0;
    return -s;
}


long cf_body_probe_inside(const cf_body *b, const cf_probe *probe)
{
    double nrm[3];
    for (size_t i = 0; i < b->nn; i++)
        if (cf_body_penetration(probe, probe->center_mm, b->X + 3 * i, nrm, 0) > 0)
            return (long)i;
    return -1;
}

size_t cf_body_contact_set(const cf_body *b, uint8_t *mark)
{
    const body_work *w = b->work;
    size_t n = 0;
    for (size_t i = 0; i < b->nn; i++) {
        mark[i] = w && w->active && w->active[i];
        n += mark[i];
    }
    return n;
}

double cf_body_penalty(const cf_body *b)
{
    return 1e4 * b->E_MPa * b->mean_edge_mm; /* the static solve's and the haptic step's default */
}

/* A face of a tetrahedron as its three nodes in increasing order. */
typedef struct tri_face {
    uint32_t v[3];
} tri_face;

static int cmp_face(const void *a, const void *b)
{
    const tri_face *p = a, *q = b;
    for (int k = 0; k < 3; k++)
        if (p->v[k] != q->v[k])
            return (p->v[k] > q->v[k]) - (p->v[k] < q->v[k]);
    return 0;
}

int cf_body_touchable(const cf_body *b, uint8_t *mark)
{
    static const int face[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
    tri_face *f = malloc(4 * b->nt * sizeof *f + 1);
    if (!f)
        return 0;
    for (size_t t = 0; t < b->nt; t++)
        for (int k = 0; k < 4; k++) {
            uint32_t *v = f[4 * t + (size_t)k].v;
            for (int a = 0; a < 3; a++)
                v[a] = b->tet[4 * t + (size_t)face[k][a]];
            for (int a = 0; a < 2; a++) /* three elements sorted */
                for (int q = 0; q < 2 - a; q++)
                    if (v[q] > v[q + 1]) {
                        const uint32_t s = v[q];
                        v[q] = v[q + 1];
                        v[q + 1] = s;
                    }
        }
    const size_t nf = 4 * b->nt;
    qsort(f, nf, sizeof *f, cmp_face);
    memset(mark, 0, b->nn);
    for (size_t k = 0; k < nf;) {
        size_t e = k + 1;
        while (e < nf && cmp_face(f + k, f + e) == 0)
            e++;
        if (e - k == 1) /* a face of one tetrahedron only: on the boundary */
            for (int a = 0; a < 3; a++)
                mark[f[k].v[a]] = 1;
        k = e;
    }
    free(f);
    return 1;
}
