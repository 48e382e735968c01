/*
** The explicit step of the lattice as a stencil over its regular grid (see lattice_step.h).
**
** Multiply-adds are contracted here (fused multiply-add in the clones whose processors have it),
** so the step's last bits depend on the clone the processor runs; on one machine they are always
** the same. The law's batch evaluation (law_simd.c) keeps separate roundings: its bits are those
** of every clone.
*/
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("fp-contract=fast")
#endif
#include "model/lattice_step.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The form of a lattice with spring groups, every group's lanes in st->glanes: the polynomial
** when each group's law has one within CF_POLY_TOL (st->poly_error the largest), else the closed
** form or the table (every group's built); -1 (the scalar law of each group) for a kind, a pair
** or a tailed spring among them. */
static int group_form(cf_lattice_stepper *st, const cf_lattice *lat)
{
    const cf_law_method m = lat->method;
    int poly = 1, table = 1;
    st->poly_error = NAN;
    for (int f = 0; f < CF_FAMILY_COUNT; f++) {
        const cf_law *g = lat->glaw[f];
        if (!(lat->cfg.weight[f] > 0))
            continue;
        if (g->mech || g->extension || g->tail || (m != CF_LAW_CLOSED && m != CF_LAW_TABLE))
            return -1;
        cf_law_lanes_init(g, &st->glanes[f]);
        table = table && st->glanes[f].coef;
    }
    double worst = 0;
    for (int f = 0; f < CF_FAMILY_COUNT && poly; f++) {
        double pe;
        if (lat->cfg.weight[f] > 0 && !cf_law_lanes_fit_poly(lat->glaw[f], &st->glanes[f], &pe))
            poly = 0;
        else if (lat->cfg.weight[f] > 0)
            worst = fmax(worst, pe);
    }
    if (poly) {
        st->poly_error = worst;
        return CF_LANE_POLY;
    }
    return m == CF_LAW_CLOSED ? CF_LANE_CLOSED : table ? CF_LANE_TABLE : -1;
}

cf_status cf_lattice_stepper_init(cf_lattice_stepper *st, cf_lattice *lat, const long *eq,
                                  cf_error *err)
{
    memset(st, 0, sizeof *st);
    st->lat = lat;
    cf_law_lanes_init(lat->law, &st->lanes);
    if (lat->grouped) /* a law per group: each group's lanes in one form */
        st->form = group_form(st, lat);
    else if (lat->law->mech) /* a law kind's row: the scalar law (its batch, law_kind.c) */
        st->form = -1;
    else if (lat->law->extension) { /* a double-acting element: both springs' lanes, side by side */
        const cf_law *e = lat->law->extension;
        cf_law_lanes_init(e, &st->ext_lanes);
        st->poly_error = NAN;
        cf_law plain = *lat->law; /* the compression spring alone (its fit checks both signs) */
        plain.extension = NULL;
        double pe1, pe2;
        if (lat->law->tail || e->tail) /* tailed sides: not in the pair's lanes yet */
            st->form = -1;
        else if (lat->method != CF_LAW_CLOSED && lat->method != CF_LAW_TABLE)
            st->form = -1;
        else if (cf_law_lanes_fit_poly(&plain, &st->lanes, &pe1) &&
                 cf_law_lanes_fit_poly(e, &st->ext_lanes, &pe2)) {
            st->form = CF_STEP_PAIR_POLY; /* both within CF_POLY_TOL of their closed forms */
            st->poly_error = fmax(pe1, pe2);
        } else if (lat->method == CF_LAW_CLOSED)
            st->form = CF_STEP_PAIR_CLOSED;
        else if (st->lanes.coef && st->ext_lanes.coef)
            st->form = CF_STEP_PAIR_TABLE;
        else
            st->form = -1;
    } else if (lat->law->tail) /* its lanes hold the polynomial only: without it, the scalar law */
        st->form = lat->method == CF_LAW_CLOSED || lat->method == CF_LAW_TABLE ? CF_LANE_POLY : -1;
    else if (lat->method == CF_LAW_CLOSED)
        st->form = CF_LANE_CLOSED;
    else if (lat->method == CF_LAW_TABLE && st->lanes.coef)
        st->form = CF_LANE_TABLE;
    else
        st->form = -1;
    /* closed form and table: the spring's polynomial when it is within CF_POLY_TOL of the closed
    ** form (more accurate than the table, cheaper than both) */
    if (lat->grouped)
        ; /* group_form chose */
    else if (st->form >= 0 && !lat->law->extension && cf_law_lanes_fit_poly(lat->law, &st->lanes, &st->poly_error))
        st->form = CF_LANE_POLY;
    else if (st->form == CF_LANE_POLY)
        st->form = -1;
    const cf_lattice_config *cfg = &lat->cfg;
    const int nx = cfg->nx, ny = cfg->ny, nz = cfg->nz;
    st->layer = (size_t)(nx + 1) * (size_t)(ny + 1);
    st->nslab = (size_t)nz + 1;
    for (int a = 0; a < 3; a++)
        st->inv_mass[a] = malloc((lat->nn ? lat->nn : 1) * sizeof(double));
    if (!st->inv_mass[0] || !st->inv_mass[1] || !st->inv_mass[2])
        goto oom;
    for (int d = 0; d < CF_CELL_DIRS; d++) {
        int off[3], fam;
        cf_cell_direction(d, off, &fam);
        if (cfg->weight[fam] == 0)
            continue; /* a family of weight 0 has no springs (lattice.c) */
        cf_step_dir *sd = &st->dir[st->ndir++];
        sd->di = off[0], sd->dj = off[1], sd->dk = off[2];
        sd->D = (size_t)((long)off[0] + (long)(nx + 1) * ((long)off[1] + (long)(ny + 1) * off[2]));
        const int nzc = (off[0] != 0) + (off[1] != 0) + (off[2] != 0);
        sd->L0 = lat->H_mm * sqrt((double)nzc); /* as lattice.c forms them */
        sd->a = lat->H_mm / sd->L0;
        sd->law = lat->glaw[fam];
        sd->lanes = lat->grouped && st->form >= 0 ? &st->glanes[fam] : NULL;
        sd->wk[0] = 1.0;
        sd->wk[1] = cf_lattice_axis_share(0, off[2], nz); /* bottom and top layers */
        if (!(sd->wl = malloc(st->layer * sizeof(double))))
            goto oom;
        for (int j = 0; j <= ny; j++)
            for (int i = 0; i <= nx; i++)
                sd->wl[(size_t)i + (size_t)(nx + 1) * (size_t)j] =
                    cfg->weight[fam] * cf_lattice_axis_share(i, off[0], nx) *
                    cf_lattice_axis_share(j, off[1], ny);
    }
    for (size_t p = 0; p < lat->nn; p++)
        for (int a = 0; a < 3; a++) {
            int prescribed = eq ? eq[3 * p + a] < 0 : (lat->fix[p] >> a) & 1;
            st->inv_mass[a][p] = prescribed ? 0.0 : 1.0 / lat->mass_t[p];
        }
    st->threads = lat->ns >= CF_STEP_THREADS_MIN;
    return CF_OK;
oom:
    cf_lattice_stepper_free(st);
    return cf_error_set(err, CF_E_INTERNAL, "out of memory for the explicit step");
}

void cf_lattice_stepper_free(cf_lattice_stepper *st)
{
    if (!st)
        return;
    for (int d = 0; d < CF_CELL_DIRS; d++)
        free(st->dir[d].wl);
    for (int a = 0; a < 3; a++)
        free(st->inv_mass[a]);
    memset(st, 0, sizeof *st);
}

/* The springs of direction sd from the first nodes [p0, p0 + n) of one layer (n <= CF_STEP_BLOCK;
** W: their weights): geometry, the law, tensions added at p and subtracted at p + D, each a
** vectorised loop over contiguous nodes. form is a constant in every call site, so each copy is
** specialised. Returns the largest |u| of the real springs. */
static inline __attribute__((always_inline)) double
run_dir(const cf_lattice *lat, const cf_law_lanes *c, const cf_law_lanes *e, int form,
        const cf_step_dir *sd, double wk, size_t p0, size_t n, const double *restrict W)
{
    const size_t D = sd->D;
    const double L0 = sd->L0, A = sd->a;
    const double *restrict xa = lat->x + p0, *restrict ya = lat->y + p0, *restrict za = lat->z + p0;
    const double *restrict xb = xa + D, *restrict yb = ya + D, *restrict zb = za + D;
    double dx[CF_STEP_BLOCK], dy[CF_STEP_BLOCK], dz[CF_STEP_BLOCK], iL[CF_STEP_BLOCK],
        u[CF_STEP_BLOCK], F[CF_STEP_BLOCK];
    double umax = 0;
#pragma omp simd reduction(max : umax)
    for (size_t k = 0; k < n; k++) {
        const double ex = xb[k] - xa[k], ey = yb[k] - ya[k], ez = zb[k] - za[k];
        dx[k] = ex, dy[k] = ey, dz[k] = ez;
        const double d2 = ex * ex + ey * ey + ez * ez;
        const double il = cf_lane_rsqrt(d2); /* the length and its inverse, no division */
        iL[k] = il;
        const double uk = (L0 - d2 * il) * A;
        u[k] = uk;
        const double au = W[k] != 0.0 ? fabs(uk) : 0.0; /* a wrapped pair is no spring */
        umax = au > umax ? au : umax;
    }
    /* the vector lanes' law over a whole number of 8 lanes: a short run (a small lattice's
    ** layer) would otherwise spend most of its time in the scalar remainder of the loop */
    const size_t n8 = (n + 7) & ~(size_t)7;
    for (size_t k = n; k < n8; k++)
        u[k] = 0.0;
    if (form == CF_STEP_PAIR_CLOSED || form == CF_STEP_PAIR_TABLE || form == CF_STEP_PAIR_POLY) {
        /* the pair: every lane through both springs, the side by the sign of u (the lanes are
        ** odd, so the extension spring's value at u < 0 is -F_e(|u|)) */
        double Fe[CF_STEP_BLOCK];
        if (form == CF_STEP_PAIR_POLY)
            cf_lanes_poly(c, n8, u, F), cf_lanes_poly(e, n8, u, Fe);
        else if (form == CF_STEP_PAIR_TABLE)
            cf_lanes_table(c, n8, u, F), cf_lanes_table(e, n8, u, Fe);
        else
            cf_lanes_closed(c, n8, u, F), cf_lanes_closed(e, n8, u, Fe);
#pragma omp simd
        for (size_t k = 0; k < n8; k++)
            F[k] = u[k] < 0.0 ? Fe[k] : F[k];
    } else if (form == CF_LANE_POLY)
        cf_lanes_poly(c, n8, u, F);
    else if (form == CF_LANE_TABLE)
        cf_lanes_table(c, n8, u, F);
    else if (form == CF_LANE_CLOSED)
        cf_lanes_closed(c, n8, u, F);
    else /* the scalar law */
        cf_law_force_many(sd->law, lat->method, n, u, F, NULL);
    /* the forces at p, then at p + D: two loops, since the runs overlap when D < n (each pointer
    ** is restrict in its own loop only) */
    {
        double *restrict fx = lat->fx + p0, *restrict fy = lat->fy + p0, *restrict fz = lat->fz + p0;
#pragma omp simd
        for (size_t k = 0; k < n; k++) {
            const double gk = W[k] != 0.0 ? -(wk * W[k]) * F[k] * iL[k] : 0.0;
            const double tx = dx[k] * gk, ty = dy[k] * gk, tz = dz[k] * gk;
            dx[k] = tx, dy[k] = ty, dz[k] = tz;
            fx[k] += tx, fy[k] += ty, fz[k] += tz;
        }
    }
    {
        double *restrict fx = lat->fx + p0 + D, *restrict fy = lat->fy + p0 + D,
                         *restrict fz = lat->fz + p0 + D;
#pragma omp simd
        for (size_t k = 0; k < n; k++)
            fx[k] -= dx[k], fy[k] -= dy[k], fz[k] -= dz[k];
    }
    return umax;
}

/* Every spring whose first node lies in layer k, in chunks of CF_STEP_BLOCK nodes; per chunk every
** direction, so the chunk's nodes stay in cache across the directions. */
static inline __attribute__((always_inline)) double
layer_springs(const cf_lattice_stepper *st, int form, size_t k)
{
    const cf_lattice *lat = st->lat;
    const cf_law_lanes c = st->lanes, e = st->ext_lanes;
    const int nx = lat->cfg.nx, ny = lat->cfg.ny, nz = lat->cfg.nz;
    const size_t row = (size_t)nx + 1, base = k * st->layer;
    const int edge = k == 0 || k == (size_t)nz;
    double umax = 0;
    for (size_t c0 = 0; c0 < st->layer; c0 += CF_STEP_BLOCK) {
        const size_t c1 = st->layer - c0 < CF_STEP_BLOCK ? st->layer : c0 + CF_STEP_BLOCK;
        for (int d = 0; d < st->ndir; d++) {
            const cf_step_dir *sd = &st->dir[d];
            if (sd->dk > 0 && k == (size_t)nz)
                continue;
            /* the first nodes of this direction's springs in the layer: one flat run */
            const size_t f0 = (size_t)(sd->di < 0) + row * (size_t)(sd->dj < 0);
            const size_t f1 = (size_t)(nx - (sd->di > 0)) + row * (size_t)(ny - (sd->dj > 0)) + 1;
            const size_t a = c0 > f0 ? c0 : f0, b = c1 < f1 ? c1 : f1;
            if (a >= b)
                continue;
            const double um =
                run_dir(lat, sd->lanes ? sd->lanes : &c, &e, form, sd, sd->wk[edge], base + a,
                        b - a, sd->wl + a);
            umax = um > umax ? um : umax;
        }
    }
    return umax;
}

/* The slabs of one parity with the law's form fixed at compile time, one copy per form and
** instruction set (law_simd.h). */
#define CF_SLABS(attr, sfx, name, form_)                                                           \
    attr static double name##sfx(const cf_lattice_stepper *st, size_t parity)                      \
    {                                                                                              \
        double umax = 0;                                                                           \
        _Pragma("omp parallel for schedule(static) reduction(max : umax) if (st->threads)")       \
        for (size_t k = parity; k < st->nslab; k += 2) {                                           \
            double um = layer_springs(st, form_, k);                                               \
            umax = um > umax ? um : umax;                                                          \
        }                                                                                          \
        return umax;                                                                               \
    }
CF_SIMD_COPIES(CF_SLABS, slabs_closed, CF_LANE_CLOSED)
CF_SIMD_COPIES(CF_SLABS, slabs_table, CF_LANE_TABLE)
CF_SIMD_COPIES(CF_SLABS, slabs_poly, CF_LANE_POLY)
CF_SIMD_COPIES(CF_SLABS, slabs_pair_closed, CF_STEP_PAIR_CLOSED)
CF_SIMD_COPIES(CF_SLABS, slabs_pair_table, CF_STEP_PAIR_TABLE)
CF_SIMD_COPIES(CF_SLABS, slabs_pair_poly, CF_STEP_PAIR_POLY)
CF_SLABS(, , slabs_scalar, -1)

double cf_lattice_stepper_forces(cf_lattice_stepper *st)
{
    double umax = 0;
    for (size_t parity = 0; parity < 2; parity++) { /* even slabs, then odd: no shared node */
        double um = st->form == CF_LANE_POLY     ? CF_SIMD_CALL(slabs_poly, (st, parity))
                    : st->form == CF_LANE_CLOSED ? CF_SIMD_CALL(slabs_closed, (st, parity))
                    : st->form == CF_LANE_TABLE  ? CF_SIMD_CALL(slabs_table, (st, parity))
                    : st->form == CF_STEP_PAIR_CLOSED
                        ? CF_SIMD_CALL(slabs_pair_closed, (st, parity))
                    : st->form == CF_STEP_PAIR_TABLE ? CF_SIMD_CALL(slabs_pair_table, (st, parity))
                    : st->form == CF_STEP_PAIR_POLY  ? CF_SIMD_CALL(slabs_pair_poly, (st, parity))
                                                     : slabs_scalar(st, parity);
        umax = um > umax ? um : umax;
    }
    return umax / st->lat->travel_mm;
}

#define STEPPER_ADVANCE(attr, sfx, unused)                                                         \
    attr static void advance##sfx(cf_lattice_stepper *st, double h, double *vx, double *vy,         \
                                  double *vz)                                                      \
    {                                                                                              \
        cf_lattice *lat = st->lat;                                                                 \
        double *const xs[3] = {lat->x, lat->y, lat->z};                                            \
        double *const fs[3] = {lat->fx, lat->fy, lat->fz};                                         \
        double *const vs[3] = {vx, vy, vz};                                                        \
        const long nn = (long)lat->nn;                                                             \
        for (int a = 0; a < 3; a++) {                                                              \
            double *restrict x = xs[a], *restrict f = fs[a], *restrict v = vs[a];                  \
            const double *restrict im = st->inv_mass[a];                                           \
            _Pragma("omp parallel for simd schedule(static) if (st->threads)")                    \
            for (long p = 0; p < nn; p++) {                                                        \
                v[p] += h * f[p] * im[p];                                                          \
                x[p] += h * v[p];                                                                  \
                f[p] = 0.0;                                                                        \
            }                                                                                      \
        }                                                                                          \
    }
CF_SIMD_COPIES(STEPPER_ADVANCE, 0)

void cf_lattice_stepper_advance(cf_lattice_stepper *st, double h, double *vx, double *vy,
                                double *vz)
{
    CF_SIMD_CALL(advance, (st, h, vx, vy, vz));
}
