/*
** Tissue bodies (body.h): the static probe solve, Newton's method on the sparse tangent with an
** active set of the nodes in contact.
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/body_internal.h"

/* Newton's method (the driver of mech.h over the body as a mechanical system, body_work.c) with
** the contact set w->active held (each node of it pushed back by the penalty kp in proportion to
** its signed depth), probe reference point at c: at most 200 steps, chord steps on the last
** factors while each cuts the residual to a quarter, the tangent taken afresh otherwise (*fresh 1
** asks for it at the first step). *conv 1 when the residual or the step fell below rounding; *it
** counts the iterations, *force and *contacts are the last assembly's. */
static cf_status newton_in_set(body_work *w, const cf_probe *probe, const double c[3],
                               double kp, double depth_mm, int *fresh, int *it, int *contacts,
                               double *force, int *conv, cf_error *err)
{
    body_sys *s = &w->sys;
    s->probe = probe;
    s->c = c;
    s->kp = kp;
    w->mech.fresh = *fresh || !w->factored;
    w->factored = 0;
    cf_mech_result res;
    cf_status st = cf_mech_newton(&w->mech, w->g, w->dx, &res, err);
    w->factored = cf_linsolve_factored(w->mech.ls);
    if (res.factorizations > 0)
        w->neg_last = res.neg_pivots;
    *fresh = w->mech.fresh;
    *it += res.iters;
    *force = s->force;
    *contacts = s->contacts;
    *conv = res.conv;
    if (st != CF_OK)
        return st;
    if (res.inadmissible)
        return cf_error_set(err, CF_E_NOCONV,
                            "body: at probe depth %g mm every Newton step would invert a "
                            "tetrahedron or take a spring to solid",
                            depth_mm);
    return CF_OK;
}

/* The static solve with the probe's reference point at c (depth_mm names it in messages), from
** the body where it is. */
static cf_status solve_at(cf_body *b, body_work *w, const cf_probe *probe, const double c[3],
                          double depth_mm, double kp, cf_body_step *out, cf_error *err)
{
    cf_status st;
    double *g = w->g;
    uint8_t *active = w->active;
    /* Active set: Newton's method with the set of nodes in contact held (each held node pushed
    ** back by the penalty in proportion to its signed depth), then the set replaced by the nodes
    ** inside the probe, until it no longer changes (penalty contact with a set that changes
    ** inside Newton's iteration cycles between states). Within a set, the factors of an earlier
    ** tangent serve as long as each step reduces the residual to a quarter (chord steps: the
    ** next update of a probe moving slowly reuses the last factors); otherwise, and whenever the
    ** set changes, the tangent is assembled and factored afresh. */
    int it = 0, contacts = 0, rounds, fresh = 0;
    double force = 0;
    for (size_t i = 0; i < b->nn; i++) {
        double nrm[3];
        uint8_t in = w->touch[i] && b->fix[i] != CF_BODY_FIX_ALL &&
                         cf_body_penetration(probe, c, b->x + 3 * i, nrm, 0) > 0;
        fresh |= in != active[i];
        active[i] = in;
    }
    fresh |= !w->factored;
    for (rounds = 0; rounds < 100; rounds++) {
        int conv = 0;
        if ((st = newton_in_set(w, probe, c, kp, depth_mm, &fresh, &it, &contacts, &force,
                                &conv, err)) != CF_OK)
            goto end;
        if (!conv) {
            st = cf_error_set(err, CF_E_NOCONV,
                              "body: Newton's method did not converge at probe depth %g mm",
                              depth_mm);
            goto end;
        }
        int changed = 0;
        for (size_t i = 0; i < b->nn; i++) {
            double nrm[3];
            uint8_t in = w->touch[i] && b->fix[i] != CF_BODY_FIX_ALL &&
                         cf_body_penetration(probe, c, b->x + 3 * i, nrm, 0) > 0;
            /* a node at a punch's rim can slide out past the radius and back in as the set
            ** changes; after ten rounds a node in the set stays while it is still pushed */
            if (rounds >= 10 && active[i] && cf_body_penetration(probe, c, b->x + 3 * i, nrm, 1) > 0)
                in = 1;
            changed += in != active[i];
            active[i] = in;
        }
        if (!changed)
            break;
        fresh = 1;
    }
    if (rounds == 100) {
        st = cf_error_set(err, CF_E_NOCONV,
                          "body: the contact set did not settle at probe depth %g mm", depth_mm);
        goto end;
    }
    force = cf_body_assemble(b, b->x, probe, c, kp, active, g, NULL, &contacts);
    cf_body_add_inertia(b, w, b->x, g, NULL);
    cf_body_keep_reaction(b, g);
    cf_body_keep_contact(b, probe, c, kp, active);
    out->depth_mm = depth_mm;
    out->force_N = force;
    out->contacts = contacts;
    out->newton_iters = it;
    out->neg_pivots = w->neg_last;
    out->min_J = cf_body_measure(b, NULL, &out->max_u_over_travel);
end:
    return st;
}

/* Load-step control: the probe's reference point moves from where the body was last solved
** (w->c_last; at depth 0 before the first solve) to c. When the solve of the whole move fails to
** converge, the body goes back to where it was and the move is taken in parts, each half the
** last that failed and twice the last that converged, down to a millionth of the move (at most
** 200 parts tried). */
static cf_status solve_cut(cf_body *b, body_work *w, const cf_probe *probe, const double c[3],
                           double depth_mm, double kp, cf_body_step *out, cf_error *err)
{
    const size_t n = 3 * b->nn;
    const double *c0 = w->has_last ? w->c_last : probe->center_mm;
    const double d0 = w->has_last ? w->depth_last : 0;
    cf_error first = {0};
    if (!w->xs && !(w->xs = malloc(n * sizeof *w->xs)))
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the body's load steps");
    memcpy(w->xs, b->x, n * sizeof *w->xs);
    cf_status st = solve_at(b, w, probe, c, depth_mm, kp, out, &first);
    if (st != CF_E_NOCONV || (c[0] == c0[0] && c[1] == c0[1] && c[2] == c0[2])) {
        if (err && st != CF_OK)
            *err = first;
        return st;
    }
    int iters = out->newton_iters, cuts = 0;
    double t = 0, h = 0.5;
    for (int tries = 0; t < 1; tries++) {
        const double tn = fmin(1, t + h);
        double ci[3];
        for (int k = 0; k < 3; k++)
            ci[k] = tn < 1 ? c0[k] + tn * (c[k] - c0[k]) : c[k];
        memcpy(b->x, w->xs, n * sizeof *w->xs);
        cf_error e = {0};
        st = solve_at(b, w, probe, ci, d0 + tn * (depth_mm - d0), kp, out, &e);
        iters += out->newton_iters;
        if (st == CF_OK) {
            t = tn;
            memcpy(w->xs, b->x, n * sizeof *w->xs);
            h *= 2;
        } else if (st == CF_E_NOCONV && h > 1e-6 && tries < 200) {
            h *= 0.5;
            cuts++;
        } else {
            memcpy(b->x, w->xs, n * sizeof *w->xs);
            if (err)
                *err = st == CF_E_NOCONV ? first : e;
            if (err && st == CF_E_NOCONV)
                snprintf(err->msg + strlen(err->msg), sizeof err->msg - strlen(err->msg),
                         " (also in steps cut %d times, to %g of the move from depth %g mm)",
                         cuts, h, d0);
            return st;
        }
    }
    out->newton_iters = iters;
    return CF_OK;
}

cf_status cf_body_solve(cf_body *b, const cf_probe *probe, double depth_mm,
                        double penalty_N_per_mm, cf_body_step *out, cf_error *err)
{
    const double kp = penalty_N_per_mm > 0 ? penalty_N_per_mm : cf_body_penalty(b);
    double c[3];
    for (int k = 0; k < 3; k++)
        c[k] = probe->center_mm[k] + depth_mm * probe->dir[k];
    body_work *w = NULL;
    cf_status st = cf_body_work_static(b, &w, err);
    if (st != CF_OK)
        return st;
    if ((st = solve_cut(b, w, probe, c, depth_mm, kp, out, err)) == CF_OK) {
        memcpy(w->c_last, c, sizeof w->c_last);
        w->depth_last = depth_mm;
        w->has_last = 1;
    }
    return st;
}

/* The depth, from `now` on, at which the probe first touches a node at its current position
** (INFINITY: never). */
static double touch_depth(const cf_body *b, const cf_probe *pr, double now)
{
    double dmin = INFINITY;
    const double R = pr->radius_mm;
    const uint8_t *touch = ((const body_work *)b->work)->touch; /* a solve made the work */
    for (size_t i = 0; i < b->nn; i++) {
        if (b->fix[i] == CF_BODY_FIX_ALL || !touch[i])
            continue;
        double r[3], s = 0, r2 = 0;
        for (int a = 0; a < 3; a++) {
            r[a] = b->x[3 * i + (size_t)a] - pr->center_mm[a];
            s += r[a] * pr->dir[a];
            r2 += r[a] * r[a];
        }
        const double q2 = fmax(r2 - s * s, 0); /* squared distance from the axis */
        if (!(q2 < R * R))
            continue;
        /* a sphere's surface reaches the node at s - sqrt(R^2 - q^2), a punch's face at s */
        const double d = pr->shape == CF_PROBE_SPHERE ? s - sqrt(R * R - q2) : s;
        if (d >= now)
            dmin = fmin(dmin, d);
    }
    return dmin;
}

/* A bracket of the probe's depth for a force: below at dlo (force flo, body xlo; flo -INFINITY
** when unknown), at or above at dhi (fhi, xhi); the Newton iterations of every trial. */
typedef struct depth_bracket {
    double dlo, flo, dhi, fhi;
    double *xlo, *xhi;
    int iters;
} depth_bracket;

/* The bracket's ends from the probe's current depth: the lower end there, or where the probe
** first touches; the upper end by steps that double from a tenth of the mean edge. *s is the
** last solve's step. */
static cf_status bracket_force(cf_body *b, const cf_probe *probe, double force_N, double depth_mm,
                               double kp, depth_bracket *q, cf_body_step *s, cf_error *err)
{
    const size_t n = 3 * b->nn;
    cf_status st;
    q->dlo = depth_mm, q->flo = 0, q->dhi = 0, q->fhi = 0;
    if ((st = cf_body_solve(b, probe, q->dlo, kp, s, err)) != CF_OK)
        return st;
    q->flo = s->force_N;
    q->iters += s->newton_iters;
    if (s->contacts == 0) {
        const double dt = touch_depth(b, probe, q->dlo);
        if (!isfinite(dt))
            return cf_error_set(err, CF_E_DATA, "body: the probe moves past the body without "
                                "touching it, so it cannot reach %g N", force_N);
        if (dt > q->dlo) {
            q->dlo = dt;
            q->flo = 0;
        }
    }
    memcpy(q->xlo, b->x, n * sizeof *q->xlo);
    if (q->flo >= force_N) { /* already there or past it: the bracket's upper end is here */
        q->dhi = q->dlo;
        q->fhi = q->flo;
        memcpy(q->xhi, q->xlo, n * sizeof *q->xhi);
        q->dlo = depth_mm > q->dhi ? q->dhi : depth_mm;
        q->flo = -INFINITY;
    }
    double step = 0.1 * b->mean_edge_mm;
    for (int k = 0; q->fhi < force_N; k++) {
        if (k == 60)
            return cf_error_set(err, CF_E_NOCONV, "body: the probe did not reach %g N", force_N);
        q->dhi = q->dlo + step;
        memcpy(b->x, q->xlo, n * sizeof *q->xlo);
        if ((st = cf_body_solve(b, probe, q->dhi, kp, s, err)) != CF_OK) {
            if (err)
                snprintf(err->msg + strlen(err->msg), sizeof err->msg - strlen(err->msg),
                         " (seeking the depth of the probe force %g N)", force_N);
            return st;
        }
        q->fhi = s->force_N;
        q->iters += s->newton_iters;
        memcpy(q->xhi, b->x, n * sizeof *q->xhi);
        if (q->fhi < force_N) {
            q->dlo = q->dhi;
            q->flo = q->fhi;
            memcpy(q->xlo, q->xhi, n * sizeof *q->xlo);
            step *= 2;
        }
    }
    return CF_OK;
}

/* Regula falsi with Illinois' halving inside bracket q to 1e-6 of the force, from the bracket's
** last solve *s; *s ends as the solve at the depth found. */
static cf_status refine_force(cf_body *b, const cf_probe *probe, double force_N, double kp,
                              depth_bracket *q, cf_body_step *s, cf_error *err)
{
    const size_t n = 3 * b->nn;
    cf_status st;
    int side = 0;
    double d = q->dhi, f = q->fhi;
    for (int it = 0; it < 200; it++) {
        if (fabs(f - force_N) <= 1e-6 * force_N || q->dhi - q->dlo <= 1e-12 * b->mean_edge_mm)
            break;
        d = isfinite(q->flo) && q->fhi > q->flo
                ? q->dlo + (force_N - q->flo) * (q->dhi - q->dlo) / (q->fhi - q->flo)
                : 0.5 * (q->dlo + q->dhi);
        if (!(d > q->dlo && d < q->dhi))
            d = 0.5 * (q->dlo + q->dhi);
        memcpy(b->x, force_N - q->flo < q->fhi - force_N ? q->xlo : q->xhi, n * sizeof *q->xlo);
        if ((st = cf_body_solve(b, probe, d, kp, s, err)) != CF_OK)
            return st;
        q->iters += s->newton_iters;
        f = s->force_N;
        if (f < force_N) {
            q->dlo = d;
            q->flo = f;
            memcpy(q->xlo, b->x, n * sizeof *q->xlo);
            if (side == -1 && isfinite(q->fhi))
                q->fhi = force_N + 0.5 * (q->fhi - force_N);
            side = -1;
        } else {
            q->dhi = d;
            q->fhi = f;
            memcpy(q->xhi, b->x, n * sizeof *q->xhi);
            if (side == 1 && isfinite(q->flo))
                q->flo = force_N - 0.5 * (force_N - q->flo);
            side = 1;
        }
    }
    if (d != s->depth_mm) { /* the last trial was not at d: solve there */
        if ((st = cf_body_solve(b, probe, d, kp, s, err)) != CF_OK)
            return st;
        q->iters += s->newton_iters;
    }
    return CF_OK;
}

cf_status cf_body_solve_force(cf_body *b, const cf_probe *probe, double force_N, double *depth_mm,
                              double penalty_N_per_mm, cf_body_step *out, cf_error *err)
{
    const size_t n = 3 * b->nn;
    if (!(force_N > 0) || !isfinite(force_N) || !isfinite(*depth_mm))
        return cf_error_set(err, CF_E_DATA, "body: probe force %g N: must be finite and > 0",
                            force_N);
    depth_bracket q = {0};
    q.xlo = malloc(n * sizeof *q.xlo);
    q.xhi = malloc(n * sizeof *q.xhi);
    cf_body_step s = {0};
    cf_status st;
    if (!q.xlo || !q.xhi)
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory for the force-driven probe");
    else if ((st = bracket_force(b, probe, force_N, *depth_mm, penalty_N_per_mm, &q, &s, err)) ==
                 CF_OK &&
             (st = refine_force(b, probe, force_N, penalty_N_per_mm, &q, &s, err)) == CF_OK) {
        *depth_mm = s.depth_mm;
        *out = s;
        out->newton_iters = q.iters;
    }
    free(q.xlo);
    free(q.xhi);
    return st;
}
