/*
** The fused explicit step of the lattice (see lattice_step.h).
**
** Multiply-adds are contracted here (fused multiply-add in the clones whose processors have it:
** about 10 % off the closed-form step), so the step's last bits depend on the clone the
** processor runs; on one machine they are always the same. The law's batch evaluation
** (law_simd.c) keeps separate roundings: its bits are those of every clone.
*/
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("fp-contract=fast")
#endif
#include "model/lattice_step.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

cf_status cf_lattice_stepper_init(cf_lattice_stepper *st, cf_lattice *lat, const long *eq,
                                  cf_error *err)
{
    memset(st, 0, sizeof *st);
    st->lat = lat;
    cf_law_lanes_init(lat->law, &st->lanes);
    if (lat->method == CF_LAW_CLOSED)
        st->form = CF_LANE_CLOSED;
    else if (lat->method == CF_LAW_TABLE && st->lanes.coef)
        st->form = CF_LANE_TABLE;
    else
        st->form = -1;
    const size_t layer = (size_t)(lat->cfg.nx + 1) * (size_t)(lat->cfg.ny + 1);
    const size_t nlayers = (size_t)lat->cfg.nz + 1;
    st->slab = malloc((nlayers + 1) * sizeof *st->slab);
    for (int a = 0; a < 3; a++)
        st->inv_mass[a] = malloc((lat->nn ? lat->nn : 1) * sizeof(double));
    if (!st->slab || !st->inv_mass[0] || !st->inv_mass[1] || !st->inv_mass[2]) {
        cf_lattice_stepper_free(st);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the explicit step");
    }
    /* slab k: the springs whose first node lies in layer k (springs are sorted by first node) */
    size_t q = 0;
    for (size_t k = 0; k < nlayers; k++) {
        st->slab[k] = q;
        while (q < lat->ns && lat->si[q] / layer == k)
            q++;
    }
    st->slab[nlayers] = lat->ns;
    st->nslab = nlayers;
    for (size_t p = 0; p < lat->nn; p++)
        for (int a = 0; a < 3; a++) {
            int prescribed = eq ? eq[3 * p + a] < 0 : (lat->fix[p] >> a) & 1;
            st->inv_mass[a][p] = prescribed ? 0.0 : 1.0 / lat->mass_t[p];
        }
    st->threads = lat->ns >= CF_STEP_THREADS_MIN;
    return CF_OK;
}

void cf_lattice_stepper_free(cf_lattice_stepper *st)
{
    if (!st)
        return;
    free(st->slab);
    for (int a = 0; a < 3; a++)
        free(st->inv_mass[a]);
    memset(st, 0, sizeof *st);
}

/* Springs [q0, q1) in blocks: gather and geometry, the law, tensions (each a vectorised loop over
** the block, so no lane's work hides behind a branch), then the scatter. form is a constant in every
** call site, so each copy is specialised. */
static inline __attribute__((always_inline)) double
springs_range(const cf_lattice *lat, const cf_law_lanes *lanes, int form, size_t q0, size_t q1)
{
    const uint32_t *restrict si = lat->si, *restrict sj = lat->sj;
    const double *restrict x = lat->x, *restrict y = lat->y, *restrict z = lat->z;
    const double *restrict L0 = lat->L0_mm, *restrict A = lat->a, *restrict W = lat->w;
    double *restrict fx = lat->fx, *restrict fy = lat->fy, *restrict fz = lat->fz;
    const cf_law_lanes c = *lanes;
    double dx[CF_STEP_BLOCK], dy[CF_STEP_BLOCK], dz[CF_STEP_BLOCK], L[CF_STEP_BLOCK],
        u[CF_STEP_BLOCK], F[CF_STEP_BLOCK];
    double umax = 0;
    for (size_t b = q0; b < q1; b += CF_STEP_BLOCK) {
        const size_t m = q1 - b < CF_STEP_BLOCK ? q1 - b : CF_STEP_BLOCK;
        const uint32_t *restrict bi = si + b, *restrict bj = sj + b;
        const double *restrict bL0 = L0 + b, *restrict bA = A + b, *restrict bW = W + b;
#pragma omp simd
        for (size_t k = 0; k < m; k++) {
            const double ex = x[bj[k]] - x[bi[k]], ey = y[bj[k]] - y[bi[k]],
                         ez = z[bj[k]] - z[bi[k]];
            dx[k] = ex, dy[k] = ey, dz[k] = ez;
            const double d2 = ex * ex + ey * ey + ez * ez;
            L[k] = sqrt(d2);
            u[k] = (bL0[k] - L[k]) * bA[k];
        }
#pragma omp simd reduction(max : umax)
        for (size_t k = 0; k < m; k++) {
            const double au = fabs(u[k]);
            umax = au > umax ? au : umax;
        }
        if (form == CF_LANE_TABLE)
            cf_lanes_table(&c, m, u, F);
        else if (form == CF_LANE_CLOSED)
            cf_lanes_closed(&c, m, u, F);
        else /* the scalar law */
            cf_law_force_many(lat->law, lat->method, m, u, F, NULL);
#pragma omp simd
        for (size_t k = 0; k < m; k++) {
            const double gk = -bW[k] * F[k] / L[k];
            dx[k] *= gk, dy[k] *= gk, dz[k] *= gk;
        }
        /* the scatter: a node's run of springs (they are sorted by first node) is summed in
        ** registers and stored once, not read back from the store it just made */
        uint32_t ci = bi[0];
        double ax = 0, ay = 0, az = 0;
        for (size_t k = 0; k < m; k++) {
            const uint32_t i = bi[k], j = bj[k];
            if (i != ci) {
                fx[ci] += ax, fy[ci] += ay, fz[ci] += az;
                ax = ay = az = 0;
                ci = i;
            }
            ax += dx[k], ay += dy[k], az += dz[k];
            fx[j] -= dx[k], fy[j] -= dy[k], fz[j] -= dz[k];
        }
        fx[ci] += ax, fy[ci] += ay, fz[ci] += az;
    }
    return umax;
}

CF_DISPATCH
static double slabs_closed(const cf_lattice_stepper *st, size_t parity)
{
    double umax = 0;
#pragma omp parallel for schedule(static) reduction(max : umax) if (st->threads)
    for (size_t k = parity; k < st->nslab; k += 2) {
        double um = springs_range(st->lat, &st->lanes, CF_LANE_CLOSED, st->slab[k], st->slab[k + 1]);
        umax = um > umax ? um : umax;
    }
    return umax;
}

CF_DISPATCH
static double slabs_table(const cf_lattice_stepper *st, size_t parity)
{
    double umax = 0;
#pragma omp parallel for schedule(static) reduction(max : umax) if (st->threads)
    for (size_t k = parity; k < st->nslab; k += 2) {
        double um = springs_range(st->lat, &st->lanes, CF_LANE_TABLE, st->slab[k], st->slab[k + 1]);
        umax = um > umax ? um : umax;
    }
    return umax;
}

static double slabs_scalar(const cf_lattice_stepper *st, size_t parity)
{
    double umax = 0;
#pragma omp parallel for schedule(static) reduction(max : umax) if (st->threads)
    for (size_t k = parity; k < st->nslab; k += 2) {
        double um = springs_range(st->lat, &st->lanes, -1, st->slab[k], st->slab[k + 1]);
        umax = um > umax ? um : umax;
    }
    return umax;
}

double cf_lattice_stepper_forces(cf_lattice_stepper *st)
{
    double umax = 0;
    for (size_t parity = 0; parity < 2; parity++) { /* even slabs, then odd: no shared node */
        double um = st->form == CF_LANE_CLOSED  ? slabs_closed(st, parity)
                    : st->form == CF_LANE_TABLE ? slabs_table(st, parity)
                                                : slabs_scalar(st, parity);
        umax = um > umax ? um : umax;
    }
    return umax / st->lat->travel_mm;
}

CF_DISPATCH
void cf_lattice_stepper_advance(cf_lattice_stepper *st, double h, double *vx, double *vy,
                                double *vz)
{
    cf_lattice *lat = st->lat;
    double *const xs[3] = {lat->x, lat->y, lat->z};
    double *const fs[3] = {lat->fx, lat->fy, lat->fz};
    double *const vs[3] = {vx, vy, vz};
    const long nn = (long)lat->nn;
    for (int a = 0; a < 3; a++) {
        double *restrict x = xs[a], *restrict f = fs[a], *restrict v = vs[a];
        const double *restrict im = st->inv_mass[a];
#pragma omp parallel for simd schedule(static) if (st->threads)
        for (long p = 0; p < nn; p++) {
            v[p] += h * f[p] * im[p];
            x[p] += h * v[p];
            f[p] = 0.0;
        }
    }
}
