/*
** The lattice solvers' workspace and static equilibria (see msm_internal.h): free DOFs, loads and
** the residual; the lattice as a mechanical system (mech.h) and its Newton solves on the one
** driver (mech_newton.c): steps accepted only where the residual drops and every spring stays
** short of solid, the tolerance of the force scale, chord and Krylov steps on kept factors for the
** uniaxial curve, a fresh tangent at every step otherwise (each state's inertia is reported); the
** static load steps with a secant predictor of the uniaxial curve's steps, and load increments
** halved when a solve fails.
*/
#include "model/msm_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A spring may come this close to solid (fraction of the travel) in a Newton step; beyond it the
** step is shortened. Past it the law's stiffness grows like (s - u)^(-1/2) and Newton stalls. */
#define SOLID_MARGIN (1.0 - 1e-9)
/* Steps from reused factors (the uniaxial curve): a chord step (a direction from the last factored
** tangent) is kept while each cuts the residual at least by CHORD_RATE without shortening;
** otherwise the next directions are Krylov steps (the current tangent solved by GMRES with those
** factors as preconditioner, linsolve_krylov.c), held to the same rate; otherwise the next
** direction refactors. */
#define CHORD_RATE 0.25
/* Halvings of a step from reused factors (chord or Krylov) before it counts as failed: a direction
** that needs more is not worth the residual evaluations, the next one does better (Krylov steps,
** then a fresh tangent). A fresh tangent's step gets FRESH_HALVINGS; after ACCEPT_AFTER of them
** it is taken wherever no spring passes the margin, whatever its residual. */
#define REUSE_HALVINGS 4
#define FRESH_HALVINGS 40
#define ACCEPT_AFTER 30
/* A step is accepted where the residual's largest component is below (1 - DECREASE alpha) of
** its origin's. */
#define DECREASE 1e-4

/* ---- workspace, loads and residual ----------------------------------------------------------- */

void cf_msm_solver_free(solver *s)
{
    free(s->eq);
    free(s->R);
    free(s->dx);
    free(s->xsave);
    free(s->Tx0);
    free(s->kx);
    free(s->Lprev);
    free(s->sigm);
    free(s->hq);
    free(s->Fprev);
    free(s->tmp);
    free(s->map);
    free(s->vmap);
    free(s->xprev);
    free(s->xcur);
    cf_mech_free(&s->mech);
}

static int is_prescribed(const solver *s, size_t node, int axis)
{
    const cf_lattice *lat = s->lat;
    if (lat->fix[node] & (1 << axis))
        return 1;
    if (axis == 2 && s->drive == CF_DRIVE_DISPLACEMENT && lat->Z[node] >= lat->height_mm * 0.9999999)
        return 1;
    return 0;
}

cf_status cf_msm_solver_init(solver *s, cf_lattice *lat, const cf_msm_effects *fx,
                             const cf_msm_config *cfg, cf_msm_drive drive,
                             cf_msm_stats *st, cf_error *err)
{
    memset(s, 0, sizeof *s);
    s->lat = lat;
    s->fx = fx;
    s->cfg = cfg;
    s->drive = drive;
    s->st = st;
    s->neg_pivots = -1;
    if (st)
        st->neg_pivots_max = -1;
    s->eq = malloc(3 * lat->nn * sizeof(long));
    s->xsave = malloc(3 * lat->nn * sizeof(double));
    s->tmp = calloc(lat->ns ? lat->ns : 1, sizeof(double));
    if (!s->eq || !s->xsave || !s->tmp)
        goto oom;
    size_t n = 0;
    for (size_t p = 0; p < lat->nn; p++)
        for (int a = 0; a < 3; a++)
            s->eq[3 * p + a] = is_prescribed(s, p, a) ? -1 : (long)n++;
    s->ndof = n;
    s->R = calloc(n ? n : 1, sizeof(double));
    s->dx = calloc(n ? n : 1, sizeof(double));
    if (!s->R || !s->dx)
        goto oom;
    if (fx && (fx->eta_MPa_s > 0 || fx->maxwell_E_MPa > 0 || fx->prony_count > 0)) {
        s->Tx0 = calloc(lat->ns, sizeof(double));
        s->kx = calloc(lat->ns, sizeof(double));
        s->Lprev = calloc(lat->ns, sizeof(double));
        if (!s->Tx0 || !s->kx || !s->Lprev)
            goto oom;
    }
    if (fx && fx->maxwell_E_MPa > 0 && !(s->sigm = calloc(lat->ns, sizeof(double))))
        goto oom;
    if (fx && fx->prony_count > 0 &&
        (!(s->hq = calloc(lat->ns * (size_t)fx->prony_count, sizeof(double))) ||
         !(s->Fprev = calloc(lat->ns, sizeof(double)))))
        goto oom;
    return CF_OK;
oom:
    cf_msm_solver_free(s);
    return cf_error_set(err, CF_E_INTERNAL, "out of memory for the lattice solver");
}

cf_status cf_msm_solver_secant(solver *s, cf_error *err)
{
    const size_t nn = s->lat->nn;
    s->xprev = malloc(3 * nn * sizeof(double));
    s->xcur = malloc(3 * nn * sizeof(double));
    if (!s->xprev || !s->xcur)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the lattice solver");
    s->secant = 1;
    s->prev_ok = 0;
    return CF_OK;
}

/* Places the top face for a displacement drive at compressive strain e. */
void cf_msm_place_top(cf_lattice *lat, double e)
{
    for (size_t t = 0; t < lat->ntop; t++) {
        uint32_t p = lat->top[t];
        lat->z[p] = lat->Z[p] - e * lat->height_mm;
    }
}

/* External loads: force drive on the top face, gravity on every node. */
void cf_msm_add_external(solver *s)
{
    cf_lattice *lat = s->lat;
    if (s->drive == CF_DRIVE_FORCE) {
        double per = s->load * lat->H_mm * lat->H_mm; /* N per unit share */
        for (size_t t = 0; t < lat->ntop; t++)
            lat->fz[lat->top[t]] -= per * lat->top_share[t];
    }
    if (s->fx && s->fx->gravity_mm_per_s2 != 0)
        for (size_t p = 0; p < lat->nn; p++)
            lat->fz[p] -= lat->mass_t[p] * s->fx->gravity_mm_per_s2;
}

/* Forces at the current positions (kernel + quasi-static extras + loads) and the residual on the
** free DOFs. Returns max |u|/travel; *rnorm the infinity norm, *fscale the force scale. */
double cf_msm_residual(solver *s, double *rnorm, double *fscale)
{
    cf_lattice *lat = s->lat;
    double um = cf_lattice_forces(lat);
    if (s->extras) {
        for (size_t q = 0; q < lat->ns; q++)
            s->tmp[q] = s->Tx0[q] + s->kx[q] * (lat->L_mm[q] - s->Lprev[q]) -
                        qlv_factor(s, q, NULL) * lat->w[q] * lat->F_N[q];
        cf_lattice_add_tensions(lat, s->tmp);
    }
    cf_msm_add_external(s);
    double rn = 0, fs = 0;
    for (size_t q = 0; q < lat->ns; q++)
        fs = fmax(fs, fabs(lat->T_N[q]));
    for (size_t p = 0; p < lat->nn; p++)
        for (int a = 0; a < 3; a++) {
            long e = s->eq[3 * p + a];
            if (e < 0)
                continue;
            s->R[e] = force(lat, a)[p];
            rn = fmax(rn, fabs(s->R[e]));
        }
    *rnorm = s->rn = rn;
    *fscale = s->fs = fs;
    s->um = um;
    s->r_ready = 0; /* a residual the driver did not ask for */
    return um;
}

void cf_msm_positions_get(const cf_lattice *lat, double *buf)
{
    memcpy(buf, lat->x, lat->nn * sizeof(double));
    memcpy(buf + lat->nn, lat->y, lat->nn * sizeof(double));
    memcpy(buf + 2 * lat->nn, lat->z, lat->nn * sizeof(double));
}

void cf_msm_positions_set(cf_lattice *lat, const double *buf)
{
    memcpy(lat->x, buf, lat->nn * sizeof(double));
    memcpy(lat->y, buf + lat->nn, lat->nn * sizeof(double));
    memcpy(lat->z, buf + 2 * lat->nn, lat->nn * sizeof(double));
}

/* The force below which Newton's residual counts as converged, whatever the force scale. */
static double force_floor(const solver *s)
{
    const cf_lattice *lat = s->lat;
    /* Floor of the force scale: a small fraction of the solid load times the largest spring
    ** weight (forces scale with it, and so does their rounding), so that an unloaded lattice is
    ** converged at once whatever its weights (a diagonal weight of 1e4 left 7e-13 N of rounding
    ** against a floor of 1e-12 F_C). */
    double wmax = 1, dash = 0;
    for (size_t q = 0; q < lat->ns; q++)
        wmax = fmax(wmax, lat->w[q]);
    /* ... and, in an implicit step with dashpots or Maxwell branches, above the rounding of their
    ** forces kx (L - Lprev) (kx grows as 1/dt: 1000 substeps of a 1 s ramp left 1.9e-8 N of it).
    ** A length is known only to the rounding of the coordinates it is formed from, eps times the
    ** largest |coordinate| of the lattice, not of the length: so the scale of those terms is kx
    ** times that coordinate (a row of 1000 cells stalled at 1.9 times a floor taken from kx L). */
    if (s->extras && s->kx) {
        double xmax = 0;
        for (size_t p = 0; p < lat->nn; p++)
            xmax = fmax(xmax, fmax(fabs(lat->x[p]), fmax(fabs(lat->y[p]), fabs(lat->z[p]))));
        for (size_t q = 0; q < lat->ns; q++)
            dash = fmax(dash, s->kx[q] * fmax(lat->L_mm[q], xmax));
    }
    /* with spring groups the scale is the largest weighted F_C over the springs (each its group's) */
    double FC = lat->law->extension ? fmax(lat->law->F_C_N, lat->law->extension->F_C_N)
                                    : lat->law->F_C_N;
    if (lat->grouped) {
        double wF = 0;
        for (size_t q = 0; q < lat->ns; q++) {
            const cf_law *g = cf_lattice_spring_law(lat, q);
            wF = fmax(wF, lat->w[q] * (g->extension ? fmax(g->F_C_N, g->extension->F_C_N)
                                                     : g->F_C_N));
        }
        FC = fmax(wF / wmax, FC / wmax);
    }
    /* the volume term's forces scale with kappa H^2 as the springs' with F_C, the hourglass
    ** control's with k_h H */
    const double vol =
        lat->cfg.volume_modulus_MPa * lat->H_mm * lat->H_mm + lat->hg_k_N_per_mm * lat->H_mm;
    return 1e-12 * FC * wmax + 1e-13 * dash + (vol != 0 ? 1e-12 * vol : 0.0);
}

/* ---- the lattice as a mechanical system ------------------------------------------------------ */

/* The residual (the out-of-balance forces on the free DOFs) at the current positions: the one a
** trial evaluated there, else evaluated now. */
static cf_status lat_residual(void *ctx, double *r, cf_error *err)
{
    (void)err;
    solver *s = ctx;
    if (!s->r_ready) {
        double rn, fs;
        cf_msm_residual(s, &rn, &fs);
    }
    s->r_ready = 0;
    if (r != s->R)
        memcpy(r, s->R, s->ndof * sizeof *r);
    return CF_OK;
}

static void lat_save(void *ctx)
{
    solver *s = ctx;
    cf_msm_positions_get(s->lat, s->xsave);
}

/* The free DOFs at the origin plus alpha dx (dx solves K dx = R with K = -dR/dx), admissible
** when every spring stays short of the margin to solid: known from the forces, so the residual
** is evaluated here. alpha 0 puts the origin back. */
static int lat_trial(void *ctx, const double *dx, double alpha)
{
    solver *s = ctx;
    cf_lattice *lat = s->lat;
    if (alpha == 0) {
        cf_msm_positions_set(lat, s->xsave);
        s->r_ready = 0;
        return 1;
    }
    for (size_t p = 0; p < lat->nn; p++)
        for (int a = 0; a < 3; a++) {
            long e = s->eq[3 * p + a];
            if (e >= 0)
                coord(lat, a)[p] = s->xsave[a * lat->nn + p] + alpha * dx[e];
        }
    double rn, fs;
    const double um = cf_msm_residual(s, &rn, &fs);
    s->r_ready = 1;
    return um < SOLID_MARGIN;
}

/* Converged when the residual is below newton_rtol of the largest spring tension plus the force
** floor, and no spring passes the margin. */
static double lat_tolerance(void *ctx, int *may_end)
{
    const solver *s = ctx;
    *may_end = s->um < SOLID_MARGIN;
    return s->cfg->newton_rtol * s->fs + s->floor_f;
}

static const cf_mech_ops lattice_ops = {lat_residual, cf_msm_tangent_fill, NULL, lat_save,
                                        lat_trial,    lat_tolerance,       NULL};

/* The driver on the lattice's tangent, with the lattice's iteration, made at the first solve. */
static cf_status lattice_mech(solver *s, cf_error *err)
{
    if (s->mech.ls)
        return CF_OK;
    cf_status st = cf_msm_tangent_build(s, &lattice_ops, err);
    if (st != CF_OK)
        return st;
    cf_mech *m = &s->mech;
    m->use_krylov = 1;
    m->judge_fresh = 0;
    m->decrease = DECREASE;
    m->accept_after = ACCEPT_AFTER;
    m->max_halvings = FRESH_HALVINGS;
    m->reuse_halvings = REUSE_HALVINGS;
    m->min_alpha = 0;
    m->step_tol = 0;
    return CF_OK;
}

/* Adds what the driver did to the statistics. */
static void note(solver *s, const cf_mech_result *res)
{
    if (res->tangents > 0)
        s->neg_pivots = res->neg_pivots;
    cf_msm_stats *st = s->st;
    if (!st)
        return;
    st->newton_iters += (size_t)res->iters;
    st->chord_iters += (size_t)res->reused;
    st->linear_iters += res->linear_solves;
    st->indefinite_tangents += (size_t)res->indefinite;
    if (res->neg_pivots_max > st->neg_pivots_max)
        st->neg_pivots_max = res->neg_pivots_max;
}

/* ---- Newton on the driver -------------------------------------------------------------------- */

cf_status cf_msm_newton(solver *s, cf_error *err)
{
    cf_lattice *lat = s->lat;
    double *start = malloc(3 * lat->nn * sizeof(double));
    if (!start)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory");
    cf_msm_positions_get(lat, start);
    if (s->st)
        s->st->solves++;
    cf_error lerr = {0};
    cf_status st = lattice_mech(s, &lerr);
    cf_mech_result res = {0};
    if (st == CF_OK) {
        double rn, fs;
        cf_msm_residual(s, &rn, &fs);
        s->floor_f = force_floor(s); /* the rounding of the forces at the start */
        s->r_ready = 1;
        cf_mech *m = &s->mech;
        m->chord_rate = s->chord ? CHORD_RATE : 0;
        m->max_iter = s->cfg->newton_max_iter;
        m->fresh |= s->refactor;
        s->refactor = 0;
        st = cf_mech_newton(m, s->R, s->dx, &res, &lerr);
        note(s, &res);
    }
    if (st == CF_E_INTERNAL || lerr.status == CF_E_INTERNAL) { /* not a matter of step size */
        cf_msm_positions_set(lat, start);
        free(start);
        return cf_error_set(err, CF_E_INTERNAL, "%s", lerr.msg);
    }
    if (st == CF_OK && res.conv) {
        if (s->st && s->um > s->st->max_u_over_travel)
            s->st->max_u_over_travel = s->um;
        free(start);
        return CF_OK;
    }
    cf_msm_positions_set(lat, start);
    free(start);
    return cf_error_set(err, CF_E_NOCONV,
                        "lattice equilibrium not found at %s %.6g (residual %.3g N, max spring "
                        "compression %.6g of travel)",
                        s->drive == CF_DRIVE_DISPLACEMENT ? "strain" : "stress_MPa", s->load,
                        s->rn, s->um);
}

cf_status cf_msm_direction(solver *s, cf_error *err)
{
    if (lattice_mech(s, err) != CF_OK)
        return CF_E_INTERNAL;
    cf_mech_result res;
    cf_status st = cf_mech_inertia(&s->mech, s->R, s->dx, &res, err);
    note(s, &res);
    return st;
}

/* ---- static load steps ----------------------------------------------------------------------- */

/* Moves the free z of every node by the affine part of a strain increment de (a predictor that
** puts the interior where a uniform lattice would be). */
static void predict(solver *s, double de)
{
    cf_lattice *lat = s->lat;
    for (size_t p = 0; p < lat->nn; p++)
        if (s->eq[3 * p + 2] >= 0)
            lat->z[p] -= de * lat->Z[p];
}

/* Moves the free DOFs to the secant prediction for drive value v1 from the converged states at
** v0 (s->xcur) and s->vprev (s->xprev): the last increment of every free coordinate, scaled to the
** new one. Along the uniaxial curve of an 8^3 lattice it starts Newton with a residual 250 times
** smaller than predict() (2e-6 N against 6e-4 N). */
static void predict_secant(solver *s, double v0, double v1)
{
    cf_lattice *lat = s->lat;
    const double r = (v1 - v0) / (v0 - s->vprev);
    for (size_t p = 0; p < lat->nn; p++)
        for (int a = 0; a < 3; a++)
            if (s->eq[3 * p + a] >= 0) {
                const size_t k = (size_t)a * lat->nn + p;
                coord(lat, a)[p] = s->xcur[k] + r * (s->xcur[k] - s->xprev[k]);
            }
}

/* Static equilibrium from drive value v0 (the current state) to v1; splits the increment in two
** when a direct solve fails. */
static cf_status static_seg(solver *s, double v0, double v1, int depth, cf_error *err)
{
    s->load = v1;
    int disp = s->drive == CF_DRIVE_DISPLACEMENT;
    const int secant = s->secant && disp;
    if (secant)
        cf_msm_positions_get(s->lat, s->xcur);
    if (disp) {
        cf_msm_place_top(s->lat, v1);
        if (secant && s->prev_ok && s->vprev != v0)
            predict_secant(s, v0, v1);
        else
            predict(s, v1 - v0);
    }
    cf_status st = cf_msm_newton(s, err);
    if (st == CF_OK) {
        if (secant && v1 != v0) { /* the state at v0 becomes the previous one */
            double *t = s->xprev;
            s->xprev = s->xcur;
            s->xcur = t;
            s->vprev = v0;
            s->prev_ok = 1;
        }
        return st;
    }
    s->load = v0;
    if (secant)
        cf_msm_positions_set(s->lat, s->xcur);
    else if (disp) {
        cf_msm_place_top(s->lat, v0);
        predict(s, v0 - v1);
    }
    if (st != CF_E_NOCONV || depth >= MAX_BISECT)
        return st;
    double mid = 0.5 * (v0 + v1);
    st = static_seg(s, v0, mid, depth + 1, err);
    if (st != CF_OK)
        return st;
    return static_seg(s, mid, v1, depth + 1, err);
}

cf_status cf_msm_static_to(solver *s, double v, cf_error *err)
{
    return static_seg(s, s->load, v, 0, err);
}

/* Compressive nominal stress (MPa) at the current state from the node forces of the last
** residual/kernel call: the reaction the top platen provides. */
double cf_msm_top_stress(const cf_lattice *lat)
{
    double r = 0;
    for (size_t t = 0; t < lat->ntop; t++)
        r += lat->fz[lat->top[t]];
    return r / lat->area_mm2;
}

/* Node force evaluation for reporting the reaction of a displacement drive. */
double cf_msm_reported_stress(solver *s)
{
    if (s->drive == CF_DRIVE_FORCE)
        return s->load;
    double rn, fs;
    cf_msm_residual(s, &rn, &fs);
    return cf_msm_top_stress(s->lat);
}
