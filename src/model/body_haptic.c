/*
** Tissue bodies (body.h): the probe loop at haptic rate, chord iterations on the factored
** contact-free tangent corrected for the nodes in contact by Woodbury's identity. The tangent is
** factored and solved through the linear solver (linsolve.h), on its own solver object with the
** condensed pattern.
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
        if ((st = cf_linsolve_solve(w->hls, w->hrhs, col + (size_t)a * n, err)) != CF_OK)
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
                              const double *nv, size_t m, double *M, double *rhs, double *dx,
                              cf_error *err)
{
    const size_t n = 3 * b->nn;
    cf_status st = cf_linsolve_solve(w->hls, w->g, dx, err);
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
    body_work *w = ctx;
    cf_body *b = w->sys.b;
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

/* The loop's workspace on first use, and the contact-free tangent where the body is now,
** factored once (until the body moves on without the loop). */
static cf_status haptic_prepare(cf_body *b, body_work *w, cf_error *err)
{
    const size_t n = 3 * b->nn, nn = b->nn;
    cf_status st;
    if (!w->hls) {
        w->hactive = calloc(nn, 1);
        w->slot = calloc(nn, sizeof *w->slot);
        w->hy = malloc(n * sizeof *w->hy);
        w->hrhs = malloc(n * sizeof *w->hrhs);
        w->hgi = malloc(n * sizeof *w->hgi);
        w->hxg = malloc(n * sizeof *w->hxg);
        if (!w->hactive || !w->slot || !w->hy || !w->hrhs || !w->hgi || !w->hxg)
            return cf_error_set(err, CF_E_INTERNAL, "out of memory for the haptic loop");
        for (size_t i = 0; i < n; i++)
            w->hxg[i] = NAN; /* no internal forces kept yet */
        if ((st = cf_linsolve_create(&w->hls, n, w->P.colptr, w->P.rowidx, haptic_tangent, w,
                                     0, err)) != CF_OK)
            return st;
    }
    if (!w->hfactored) {
        /* the contact-free tangent where the body is now, factored once */
        if ((st = cf_linsolve_factor(w->hls, err)) != CF_OK)
            return st;
        w->factored = 0; /* the Newton solver's factors were of the same values: refactor */
        w->hfactored = 1;
        w->nslot = 0;
        memset(w->slot, 0, nn * sizeof *w->slot);
    }
    return CF_OK;
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

/* The contact set where the body is at the update's start (into list[*m], normals nv, flags
** w->hactive): nodes inside the probe, and nodes of the last set still pushed. */
static cf_status contact_set(cf_body *b, body_work *w, const cf_probe *probe, const double *c,
                             size_t *cap, size_t **list, double **nv, double **M, double **rhs,
                             size_t *m, cf_error *err)
{
    for (size_t i = 0; i < b->nn; i++) {
        double nrm[3];
        uint8_t in = w->touch[i] && b->fix[i] != CF_BODY_FIX_ALL &&
                     (cf_body_penetration(probe, c, b->x + 3 * i, nrm, 0) > 0 ||
                      (w->hactive[i] && cf_body_penetration(probe, c, b->x + 3 * i, nrm, 1) > 0));
        w->hactive[i] = in;
        if (!in)
            continue;
        if (*m == *cap && grow(cap, list, nv, M, rhs) != 0)
            return cf_error_set(err, CF_E_INTERNAL, "out of memory for the haptic loop");
        (*list)[*m] = i;
        contact_normal(b, probe, c, i, *nv + 3 * *m);
        (*m)++;
    }
    return CF_OK;
}

/* The residual w->g at the body's positions with the probe at c: the internal forces kept from the
** end of the last update when the body has not moved since (w->hxg), else assembled, then the
** contact of the nodes in w->hactive. Returns the contact force along the probe's direction (NAN
** when memory runs out). */
static double residual(cf_body *b, body_work *w, const cf_probe *probe, const double *c,
                       double kp, int *contacts)
{
    const size_t n = 3 * b->nn;
    if (memcmp(w->hxg, b->x, n * sizeof *b->x) != 0)
        return cf_body_assemble(b, b->x, probe, c, kp, w->hactive, w->g, NULL, contacts);
    memcpy(w->g, w->hgi, n * sizeof *w->g);
    double force = 0;
    int nc = 0;
    for (size_t i = 0; i < b->nn; i++) {
        if (!w->hactive[i])
            continue;
        double nrm[3], d = cf_body_penetration(probe, c, b->x + 3 * i, nrm, 1);
        nc++;
        for (int a = 0; a < 3; a++)
            w->g[3 * i + (size_t)a] -= kp * d * nrm[a];
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

/* A step -alpha dx from the body's positions, alpha halved from 1 until no tetrahedron inverts
** and no spring goes solid; 0 when none of 40 does. */
static int admissible_step(cf_body *b, body_work *w)
{
    const size_t n = 3 * b->nn;
    for (size_t i = 0; i < b->nn; i++)
        for (int a = 0; a < 3; a++)
            if ((b->fix[i] >> a) & 1)
                w->dx[3 * i + (size_t)a] = 0;
    double alpha = 2;
    for (int bt = 0; bt < 40; bt++) {
        alpha *= 0.5;
        for (size_t i = 0; i < n; i++)
            w->xt[i] = b->x[i] - alpha * w->dx[i];
        if (cf_body_admissible(b, w->xt)) {
            memcpy(b->x, w->xt, n * sizeof *w->xt);
            return 1;
        }
    }
    return 0;
}

cf_status cf_body_haptic_step(cf_body *b, const cf_probe *probe, double depth_mm,
                              double penalty_N_per_mm, int max_iters, cf_body_step *out,
                              cf_error *err)
{
    const size_t n = 3 * b->nn;
    const double kp = penalty_N_per_mm > 0 ? penalty_N_per_mm : cf_body_penalty(b);
    double c[3];
    for (int k = 0; k < 3; k++)
        c[k] = probe->center_mm[k] + depth_mm * probe->dir[k];
    body_work *w = NULL;
    cf_status st = cf_body_work_get(b, &w, err);
    if (st != CF_OK)
        return st;
    if ((st = haptic_prepare(b, w, err)) != CF_OK)
        return st;
    size_t *list = NULL, cap = 0;
    double *nv = NULL, *M = NULL, *rhs = NULL;
    const double fscale = b->E_MPa * b->mean_edge_mm * b->mean_edge_mm;
    int it = 0, contacts = 0;
    double force = 0;
    size_t m = 0;
    /* the contact set where the body is at the update's start, held through the update's
    ** iterations (a node the step leaves just outside a curved probe, by its slip along the
    ** surface, would otherwise drop out and spring back every other iteration), its normals
    ** renewed */
    if ((st = contact_set(b, w, probe, c, &cap, &list, &nv, &M, &rhs, &m, err)) != CF_OK)
        goto end;
    for (it = 0; it < max_iters; it++) {
        for (size_t k = 0; it > 0 && k < m; k++)
            contact_normal(b, probe, c, list[k], nv + 3 * k);
        force = residual(b, w, probe, c, kp, &contacts);
        if (isnan(force)) {
            st = cf_error_set(err, CF_E_INTERNAL, "out of memory for the body's forces");
            goto end;
        }
        cf_body_keep_reaction(b, w->g);
        cf_body_apply_fixed(b, NULL, w->g);
        if (body_norm_inf(w->g, n) <= 1e-8 * fscale)
            break;
        if ((st = haptic_solve(b, w, kp, list, nv, m, M, rhs, w->dx, err)) != CF_OK)
            goto end;
        if (!admissible_step(b, w)) {
            st = cf_error_set(err, CF_E_NOCONV,
                              "body: at probe depth %g mm every haptic step would invert a "
                              "tetrahedron or take a spring to solid",
                              depth_mm);
            goto end;
        }
        /* the force where the step left the body, from the body's side; its internal forces
        ** serve the next iteration's residual */
        if (isnan(force = reaction(b, w, probe, c, kp, list, m))) {
            st = cf_error_set(err, CF_E_INTERNAL, "out of memory for the body's forces");
            goto end;
        }
    }
    out->depth_mm = depth_mm;
    out->force_N = force;
    out->contacts = contacts;
    out->newton_iters = it;
    out->min_J = cf_body_measure(b, NULL, &out->max_u_over_travel);
end:
    free(list);
    free(nv);
    free(M);
    free(rhs);
    return st;
}
