/*
** Tetrahedral meshes of bodies (body.h): the block generator and the checks every mesh passes
** before it becomes a body.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/body_internal.h"

void cf_mesh_free(cf_mesh *m)
{
    if (!m)
        return;
    free(m->X);
    free(m->tet);
    free(m->id);
    free(m->eid);
    for (size_t k = 0; k < m->ngroups; k++)
        free(m->groups[k].nodes);
    free(m->groups);
    memset(m, 0, sizeof *m);
}

static cf_status grid_ok(const double *g, int n, const char *axis, cf_error *err)
{
    if (n < 1 || n > 4096)
        return cf_error_set(err, CF_E_DATA, "block: %d cells along %s: must be 1 to 4096", n, axis);
    for (int i = 0; i <= n; i++)
        if (!isfinite(g[i]) || (i > 0 && !(g[i] > g[i - 1])))
            return cf_error_set(err, CF_E_DATA,
                                "block: coordinate %d along %s (%g) is not finite and increasing",
                                i, axis, g[i]);
    return CF_OK;
}

cf_status cf_mesh_block(cf_mesh *m, const double *xs, int nx, const double *ys, int ny,
                        const double *zs, int nz, cf_error *err)
{
    memset(m, 0, sizeof *m);
    cf_status st;
    if ((st = grid_ok(xs, nx, "x", err)) || (st = grid_ok(ys, ny, "y", err)) ||
        (st = grid_ok(zs, nz, "z", err)))
        return st;
    const size_t px = (size_t)nx + 1, py = (size_t)ny + 1, pz = (size_t)nz + 1;
    m->nn = px * py * pz;
    m->nt = 6 * (size_t)nx * (size_t)ny * (size_t)nz;
    if (m->nn > UINT32_MAX)
        return cf_error_set(err, CF_E_DATA, "block: %zu nodes: too many", m->nn);
    m->X = malloc(3 * m->nn * sizeof *m->X);
    m->tet = malloc(4 * m->nt * sizeof *m->tet);
    m->id = malloc(m->nn * sizeof *m->id);
    m->eid = malloc(m->nt * sizeof *m->eid);
    if (!m->X || !m->tet || !m->id || !m->eid) {
        cf_mesh_free(m);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for a block of %zu nodes", px * py * pz);
    }
    for (size_t k = 0; k < pz; k++)
        for (size_t j = 0; j < py; j++)
            for (size_t i = 0; i < px; i++) {
                size_t n = i + px * (j + py * k);
                m->X[3 * n] = xs[i];
                m->X[3 * n + 1] = ys[j];
                m->X[3 * n + 2] = zs[k];
                m->id[n] = (uint32_t)(n + 1);
            }
    /* the six paths from corner 000 to corner 111, one axis at a time */
    static const int perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    size_t t = 0, cell = 0;
    for (size_t k = 0; k < (size_t)nz; k++)
        for (size_t j = 0; j < (size_t)ny; j++)
            for (size_t i = 0; i < (size_t)nx; i++, cell++)
                for (int p = 0; p < 6; p++, t++) {
                    /* the cell mirrored along each axis where its index is odd: neighbours
                    ** share their faces' diagonals, and the block holds every face and body
                    ** diagonal direction (the cubic lattice's) */
                    const size_t base[3] = {i, j, k};
                    size_t c[3] = {i % 2, j % 2, k % 2};
                    uint32_t v[4];
                    for (int s = 0; s < 4; s++) {
                        if (s > 0)
                            c[perm[p][s - 1]] ^= 1;
                        size_t q[3];
                        for (int a = 0; a < 3; a++)
                            q[a] = base[a] + (c[a] ^ (base[a] % 2));
                        v[s] = (uint32_t)(q[0] + px * (q[1] + py * q[2]));
                    }
                    if (body_vol6(m->X + 3 * v[0], m->X + 3 * v[1], m->X + 3 * v[2], m->X + 3 * v[3]) < 0) {
                        uint32_t tmp = v[2];
                        v[2] = v[3];
                        v[3] = tmp;
                    }
                    memcpy(m->tet + 4 * t, v, sizeof v);
                    m->eid[t] = cell + 1;
                }
    return CF_OK;
}

cf_status cf_mesh_check(cf_mesh *m, const char *name, cf_error *err)
{
    if (m->nt == 0)
        return cf_error_set(err, CF_E_DATA,
                            "%s: no tetrahedra or hexahedra: not a volume mesh", name);
    for (size_t n = 0; n < 3 * m->nn; n++)
        if (!isfinite(m->X[n]))
            return cf_error_set(err, CF_E_DATA, "%s: node %lu has a coordinate that is not finite",
                                name, (unsigned long)(m->id ? m->id[n / 3] : n / 3 + 1));
    size_t neg = 0;
    for (size_t t = 0; t < m->nt; t++) {
        const uint32_t *v = m->tet + 4 * t;
        unsigned long eid = (unsigned long)(m->eid ? m->eid[t] : t + 1);
        for (int a = 0; a < 4; a++) {
            if (v[a] >= m->nn)
                return cf_error_set(err, CF_E_DATA, "%s: element %lu names a node that is not in "
                                                    "the mesh", name, eid);
            for (int b = 0; b < a; b++)
                if (v[a] == v[b])
                    return cf_error_set(err, CF_E_DATA,
                                        "%s: element %lu is degenerate (node %lu twice)", name, eid,
                                        (unsigned long)(m->id ? m->id[v[a]] : v[a] + 1));
        }
        double lmax = 0;
        for (int a = 0; a < 4; a++)
            for (int b = 0; b < a; b++) {
                double d2 = 0;
                for (int k = 0; k < 3; k++) {
                    double d = m->X[3 * v[a] + k] - m->X[3 * v[b] + k];
                    d2 += d * d;
                }
                lmax = fmax(lmax, sqrt(d2));
            }
        double v6 = body_vol6(m->X + 3 * v[0], m->X + 3 * v[1], m->X + 3 * v[2], m->X + 3 * v[3]);
        if (!(fabs(v6) > 6e-12 * lmax * lmax * lmax))
            return cf_error_set(err, CF_E_DATA,
                                "%s: element %lu is degenerate (volume %.3g mm^3, longest edge "
                                "%.3g mm)",
                                name, eid, v6 / 6, lmax);
        neg += v6 < 0;
    }
    const int flip = 2 * neg > m->nt; /* the majority's orientation is the mesh's */
    for (size_t t = 0; t < m->nt; t++) {
        uint32_t *v = m->tet + 4 * t;
        double v6 = body_vol6(m->X + 3 * v[0], m->X + 3 * v[1], m->X + 3 * v[2], m->X + 3 * v[3]);
        if ((v6 < 0) != flip)
            return cf_error_set(err, CF_E_DATA,
                                "%s: element %lu is inverted (its orientation is the opposite of "
                                "%zu of the %zu elements)",
                                name, (unsigned long)(m->eid ? m->eid[t] : t + 1),
                                flip ? neg : m->nt - neg, m->nt);
        if (flip) {
            uint32_t tmp = v[2];
            v[2] = v[3];
            v[3] = tmp;
        }
    }
    return CF_OK;
}
