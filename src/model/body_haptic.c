/*
** Tissue bodies (body.h): the probe loop at haptic rate, chord iterations on the factored
** contact-free tangent corrected for the nodes in contact by Woodbury's identity. The body is a
** mechanical system (mech.h) of its own hooks, iterated by the Newton driver in chord-only mode
** for a fixed count; the tangent is factored and solved through the linear solver (linsolve.h),
** the driver's, with the condensed pattern.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/body_internal.h"

/* The three columns of the inverse of the contact-free tangent at node i (held components zero),
** computed at its first contact and kept (*out). */
static cf_status haptic_columns(body_work *w, size_t nn, size_t i, const double **out,
                                cf_error *err)
{
    const size_t n = 3 * nn;
    cf_status st;
    if (w->slot[i]) {
        *out = w->Z + (size_t)(w->slot[i] - 1) * 3 * n;
        return CF_OK;
    }
    if (w->nslot == w->capslot) {
        size_t cap = w->capslot ? 2 * w->capslot : 16;
        double *Z = realloc(w->Z, cap * 3 * n * sizeof *Z);
        if (!Z)
            return cf_error_set(err, CF_E_INTERNAL, "out of memory for the haptic loop's columns");
        w->Z = Z;
        w->capslot = cap;
    }
    double *col = w->Z + w->nslot * 3 * n;
    for (int a = 0; a < 3; a++) {
        memset(w->hrhs, 0, n * sizeof *w->hrhs);
        w->hrhs[3 * i + (size_t)a] = 1;
        if ((st = cf_linsolve_solve(w->hmech.ls, w->hrhs, col + (size_t)a * n, err)) != CF_OK)
            return st;
    }
    w->slot[i] = (uint32_t)++w->nslot;
    *out = col;
    return CF_OK;
}

/* Solves (K0 + U U^T) dx = g by Woodbury's identity: K0 the factored contact-free tangent, U one
** column sqrt(kp) n_i (at node i's components, held ones zero) per node in contact. m nodes in
** list[], their normals in nv[3 m]; M is m x m work space, rhs m. */
static cf_status haptic_solve(cf_body *b, body_work *w, double kp, const size_t *list,
                              const double *nv, size_t m, double *M, double *rhs, const double *g,
                              double *dx, cf_error *err)
{
    const size_t n = 3 * b->nn;
    cf_status st = cf_linsolve_solve(w->hmech.ls, g, dx, err);
    if (st != CF_OK || m == 0)
        return st;
    const double sk = sqrt(kp);
    /* v_k = K0^-1 u_k is sqrt(kp) Z_k n_k; M = I + U^T K0^-1 U; rhs = U^T y */
    for (size_t k = 0; k < m; k++) {
        const double *Zk = NULL;
        if ((st = haptic_columns(w, b->nn, list[k], &Zk, err)) != CF_OK)
            return st;
        const size_t ik = list[k];
        rhs[k] = 0;
        for (int a = 0; a < 3; a++)
            rhs[k] += sk * nv[3 * k + a] * dx[3 * ik + (size_t)a];
        for (size_t q = 0; q < m; q++) {
            const size_t iq = list[q];
            double s = 0;
            for (int a = 0; a < 3; a++)     /* row of node iq, component a */
                for (int c = 0; c < 3; c++) /* column c of node ik */
                    s += nv[3 * q + a] * Zk[(size_t)c * n + 3 * iq + (size_t)a] * nv[3 * k + c];
            M[q * m + k] = kp * s + (q == k);
        }
    }
    /* M is symmetric positive definite: Cholesky in place, then rhs = M^-1 rhs */
    for (size_t j = 0; j < m; j++) {
        double d = M[j * m + j];
        for (size_t k = 0; k < j; k++)
            d -= M[j * m + k] * M[j * m + k];
        if (!(d > 0))
            return cf_error_set(err, CF_E_NOCONV, "body: the haptic loop's contact matrix is "
                                                  "not positive definite");
        d = sqrt(d);
        M[j * m + j] = d;
        for (size_t i = j + 1; i < m; i++) {
            double s = M[i * m + j];
            for (size_t k = 0; k < j; k++)
                s -= M[i * m + k] * M[j * m + k];
            M[i * m + j] = s / d;
        }
    }
    for (size_t i = 0; i < m; i++) {
        double s = rhs[i];
        for (size_t k = 0; k < i; k++)
            s -= M[i * m + k] * rhs[k];
        rhs[i] = s / M[i * m + i];
    }
    for (size_t i = m; i-- > 0;) {
        double s = rhs[i];
        for (size_t k = i + 1; k < m; k++)
            s -= M[k * m + i] * rhs[k];
        rhs[i] = s / M[i * m + i];
    }
    for (size_t k = 0; k < m; k++) {
        const double *Zk = w->Z + (size_t)(w->slot[list[k]] - 1) * 3 * n;
        for (int c = 0; c < 3; c++) {
            const double f = sk * nv[3 * k + c] * rhs[k];
            if (f == 0)
                continue;
            const double *z = Zk + (size_t)c * n;
            for (size_t r = 0; r < n; r++)
                dx[r] -= f * z[r];
        }
    }
    return CF_OK;
}

/* The contact-free tangent where the body is now into v (the haptic solver's values, the condensed
** pattern's order), its held components' rows and columns those of the identity. */
static void haptic_tangent(void *ctx, double *v)
{
    haptic_sys *h = ctx;
    body_work *w = h->w;
    cf_body *b = h->b;
    pattern *P = &w->P;
    double *keep = P->val;
    P->val = v;
    /* out of memory for the volume term's scratch: NaN values, which the factorisation refuses */
    if (isnan(cf_body_assemble(b, b->x, NULL, NULL, 0, NULL, w->gt, P, NULL)))
        for (size_t k = 0; k < (size_t)P->colptr[P->n]; k++)
            v[k] = NAN;
    cf_body_apply_fixed(b, P, w->gt);
    P->val = keep;
}

/* Doubles the contact set's room (list, normals, the Schur matrix and its right side); -1 when
** memory runs out (what was reallocated is kept for the caller to free). */
static int grow(size_t *cap, size_t **list, double **nv, double **M, double **rhs)
{
    *cap = *cap ? 2 * *cap : 16;
    size_t *l2 = realloc(*list, *cap * sizeof *l2);
    double *n2 = l2 ? realloc(*nv, 3 * *cap * sizeof *n2) : NULL;
    double *M2 = n2 ? realloc(*M, *cap * *cap * sizeof *M2) : NULL;
    double *r2 = M2 ? realloc(*rhs, *cap * sizeof *r2) : NULL;
    if (l2)
        *list = l2;
    if (n2)
        *nv = n2;
    if (M2)
        *M = M2;
    if (r2)
        *rhs = r2;
    return r2 ? 0 : -1;
}

/* Node i's contact normal (its held components zero) into nv[3]. */
static void contact_normal(const cf_body *b, const cf_probe *probe, const double *c, size_t i,
                           double *nv)
{
    cf_body_penetration(probe, c, b->x + 3 * i, nv, 1);
    for (int a = 0; a < 3; a++)
        if ((b->fix[i] >> a) & 1)
            nv[a] = 0;
}

/* The contact set where the body is at the update's start (into h->list[h->m], normals h->nv,
** flags w->hactive): nodes inside the probe, and nodes of the last set still pushed. */
static cf_status contact_set(cf_body *b, body_work *w, haptic_sys *h, cf_error *err)
{
    for (size_t i = 0; i < b->nn; i++) {
        double nrm[3];
        uint8_t in = w->touch[i] && b->fix[i] != CF_BODY_FIX_ALL &&
                     (cf_body_penetration(h->probe, h->c, b->x + 3 * i, nrm, 0) > 0 ||
                      (w->hactive[i] &&
                       cf_body_penetration(h->probe, h->c, b->x + 3 * i, nrm, 1) > 0));
        w->hactive[i] = in;
        if (!in)
            continue;
        if (h->m == h->cap && grow(&h->cap, &h->list, &h->nv, &h->M, &h->rhs) != 0)
            return cf_error_set(err, CF_E_INTERNAL, "out of memory for the haptic loop");
        h->list[h->m] = i;
        contact_normal(b, h->probe, h->c, i, h->nv + 3 * h->m);
        h->m++;
    }
    return CF_OK;
}

/* The residual g at the body's positions with the probe at c: the internal forces kept from the
** end of the last update when the body has not moved since (w->hxg), else assembled, then the
** contact of the nodes in w->hactive. Returns the contact force along the probe's direction (NAN
** when memory runs out). */
static double residual(cf_body *b, body_work *w, const cf_probe *probe, const double *c,
                       double kp, double *g, int *contacts)
{
    const size_t n = 3 * b->nn;
    if (memcmp(w->hxg, b->x, n * sizeof *b->x) != 0)
        return cf_body_assemble(b, b->x, probe, c, kp, w->hactive, g, NULL, contacts);
    memcpy(g, w->hgi, n * sizeof *g);
    double force = 0;
    int nc = 0;
    for (size_t i = 0; i < b->nn; i++) {
        if (!w->hactive[i])
            continue;
        double nrm[3], d = cf_body_penetration(probe, c, b->x + 3 * i, nrm, 1);
        nc++;
        for (int a = 0; a < 3; a++)
            g[3 * i + (size_t)a] -= kp * d * nrm[a];
        force += kp * d * (nrm[0] * probe->dir[0] + nrm[1] * probe->dir[1] + nrm[2] * probe->dir[2]);
    }
    *contacts = nc;
    return force;
}

/* After a step: the internal forces where the body now is (kept in w->hgi for the next iteration
** or update), and the probe's force from the body's side, their sum along the probe's direction
** over the m nodes of list[] (a held component takes the penalty's force instead). The body's
** stiffness, not the penalty's, turns a position not yet at equilibrium into a force error, so
** this estimate is far closer to the equilibrium force than penalty times depth. NAN when memory
** runs out. */
static double reaction(cf_body *b, body_work *w, const cf_probe *probe, const double *c, double kp,
                       const size_t *list, size_t m)
{
    const size_t n = 3 * b->nn;
    if (isnan(cf_body_assemble(b, b->x, NULL, NULL, 0, NULL, w->hgi, NULL, NULL)))
        return NAN;
    memcpy(w->hxg, b->x, n * sizeof *b->x);
    double force = 0;
    for (size_t k = 0; k < m; k++) {
        const size_t i = list[k];
        double nrm[3];
        const double d = cf_body_penetration(probe, c, b->x + 3 * i, nrm, 1);
        for (int a = 0; a < 3; a++)
            force += (((b->fix[i] >> a) & 1) ? kp * d * nrm[a] : w->hgi[3 * i + (size_t)a]) *
                     probe->dir[a];
    }
    return force;
}

/* The probe's force from the body's side where the last step left it (h->force), when a step was
** taken since the last residual. */
static cf_status read_reaction(haptic_sys *h, cf_error *err)
{
    if (!h->stepped)
        return CF_OK;
    h->stepped = 0;
    h->force = reaction(h->b, h->w, h->probe, h->c, h->kp, h->list, h->m);
    return isnan(h->force) ? cf_error_set(err, CF_E_INTERNAL, "out of memory for the body's forces")
                           : CF_OK;
}

/* The hooks of the haptic system (mech.h). The residual: first the force from the body's side
** where the last step left it (its internal forces then serve this residual), then the contact
** set's normals renewed (after the update's first residual), the residual with the contact's
** force (h->force), the supports' reactions kept and the held components zeroed. */
static cf_status h_residual(void *ctx, double *r, cf_error *err)
{
    haptic_sys *h = ctx;
    cf_status st = read_reaction(h, err);
    if (st != CF_OK)
        return st;
    for (size_t k = 0; h->evaluated && k < h->m; k++)
        contact_normal(h->b, h->probe, h->c, h->list[k], h->nv + 3 * k);
    h->evaluated = 1;
    h->force = residual(h->b, h->w, h->probe, h->c, h->kp, r, &h->contacts);
    if (isnan(h->force))
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the body's forces");
    cf_body_keep_reaction(h->b, r);
    cf_body_apply_fixed(h->b, NULL, r);
    return CF_OK;
}

/* A direction's held components zeroed, as a residual's are. */
static void h_project(void *ctx, double *dx)
{
    cf_body_apply_fixed(((haptic_sys *)ctx)->b, NULL, dx);
}

static void h_save(void *ctx)
{
    haptic_sys *h = ctx;
    memcpy(h->w->xt, h->b->x, 3 * h->b->nn * sizeof *h->w->xt);
}

/* The state origin - alpha dx; admissible when no tetrahedron inverts and no spring goes solid
** (the driver takes the first, halving alpha from 1). */
static int h_trial(void *ctx, const double *dx, double alpha)
{
    haptic_sys *h = ctx;
    cf_body *b = h->b;
    const size_t n = 3 * b->nn;
    if (alpha == 0) {
        memcpy(b->x, h->w->xt, n * sizeof *b->x);
        return 1;
    }
    for (size_t i = 0; i < n; i++)
        b->x[i] = h->w->xt[i] - alpha * dx[i];
    const int ok = cf_body_admissible(b, b->x);
    h->stepped |= ok;
    return ok;
}

/* The direction: the contact-free tangent's factors, corrected for the contact set. */
static cf_status h_chord(void *ctx, const double *r, double *dx, cf_error *err)
{
    haptic_sys *h = ctx;
    return haptic_solve(h->b, h->w, h->kp, h->list, h->nv, h->m, h->M, h->rhs, r, dx, err);
}

static const cf_mech_ops haptic_ops = {h_residual, haptic_tangent, h_project, h_save,
                                       h_trial,    NULL,           h_chord};

/* The loop's workspace and system on first use, and the contact-free tangent where the body is
** now, factored once (until the body moves on without the loop). */
static cf_status haptic_prepare(cf_body *b, body_work *w, cf_error *err)
{
    const size_t n = 3 * b->nn, nn = b->nn;
    cf_status st;
    if (!w->hactive) {
        w->hactive = calloc(nn, 1);
        w->slot = calloc(nn, sizeof *w->slot);
        w->hrhs = malloc(n * sizeof *w->hrhs);
        w->hgi = malloc(n * sizeof *w->hgi);
        w->hxg = malloc(n * sizeof *w->hxg);
        if (!w->hactive || !w->slot || !w->hrhs || !w->hgi || !w->hxg)
            return cf_error_set(err, CF_E_INTERNAL, "out of memory for the haptic loop");
        for (size_t i = 0; i < n; i++)
            w->hxg[i] = NAN; /* no internal forces kept yet */
    }
    if (!w->hmech.ls) {
        w->hsys.b = b;
        w->hsys.w = w;
        if ((st = cf_mech_create(&w->hmech, n, 0, &haptic_ops, &w->hsys, w->P.colptr,
                                 w->P.rowidx, 0, err)) != CF_OK)
            return st;
        /* a fixed count of chord steps on the factors taken here, each halved from full length
        ** until admissible (40 halvings), none judged, the last state read by the loop itself */
        w->hmech.chord_only = 1;
        w->hmech.last_unevaluated = 1;
        w->hmech.step_tol = 0;
        w->hmech.decrease = 0;
        w->hmech.reuse_halvings = 40;
        w->hmech.min_alpha = 0x1p-39;
    }
    if (!w->hfactored) {
        /* the contact-free tangent where the body is now, factored once */
        if ((st = cf_linsolve_factor(w->hmech.ls, err)) != CF_OK)
            return st;
        w->factored = 0; /* the Newton solver's factors were of the same values: refactor */
        w->hfactored = 1;
        w->nslot = 0;
        memset(w->slot, 0, nn * sizeof *w->slot);
    }
    return CF_OK;
}

cf_status cf_body_haptic_step(cf_body *b, const cf_probe *probe, double depth_mm,
                              double penalty_N_per_mm, int max_iters, cf_body_step *out,
                              cf_error *err)
{
    double c[3];
    for (int k = 0; k < 3; k++)
        c[k] = probe->center_mm[k] + depth_mm * probe->dir[k];
    body_work *w = NULL;
    cf_status st = cf_body_work_get(b, &w, err);
    if (st != CF_OK)
        return st;
    if ((st = haptic_prepare(b, w, err)) != CF_OK)
        return st;
    haptic_sys *h = &w->hsys;
    *h = (haptic_sys){b, w, probe, c, penalty_N_per_mm > 0 ? penalty_N_per_mm : cf_body_penalty(b),
                      h->list, h->nv, h->M, h->rhs, 0, h->cap, 0, 0, 0, 0};
    cf_mech_result res = {0};
    /* the contact set where the body is at the update's start, held through the update's
    ** iterations (a node the step leaves just outside a curved probe, by its slip along the
    ** surface, would otherwise drop out and spring back every other iteration), its normals
    ** renewed; then max_iters directions on the kept factors, ending early where the residual
    ** is below 1e-8 of the body's force scale */
    if ((st = contact_set(b, w, h, err)) == CF_OK && max_iters > 0) {
        const double fscale = b->E_MPa * b->mean_edge_mm * b->mean_edge_mm;
        w->hmech.max_iter = max_iters;
        w->hmech.tol = 1e-8 * fscale;
        st = cf_mech_newton(&w->hmech, w->g, w->dx, &res, err);
        if (st == CF_OK && res.inadmissible)
            st = cf_error_set(err, CF_E_NOCONV,
                              "body: at probe depth %g mm every haptic step would invert a "
                              "tetrahedron or take a spring to solid",
                              depth_mm);
        if (st == CF_OK) /* the force where the last step left the body, from its side */
            st = read_reaction(h, err);
    }
    h->probe = NULL; /* c is this call's */
    h->c = NULL;
    if (st != CF_OK)
        return st;
    out->depth_mm = depth_mm;
    out->force_N = h->force;
    out->contacts = h->contacts;
    out->newton_iters = res.iters;
    out->min_J = cf_body_measure(b, NULL, &out->max_u_over_travel);
    return CF_OK;
}
