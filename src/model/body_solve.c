/*
** Tissue bodies (body.h): the static probe solve, Newton's method on the sparse tangent with an
** active set of the nodes in contact.
*/
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model/body_internal.h"

cf_status cf_body_solve(cf_body *b, const cf_probe *probe, double depth_mm,
                        double penalty_N_per_mm, cf_body_step *out, cf_error *err)
{
    const size_t n = 3 * b->nn;
    const double kp = penalty_N_per_mm > 0 ? penalty_N_per_mm : 1e4 * b->E_MPa * b->mean_edge_mm;
    double c[3];
    for (int k = 0; k < 3; k++)
        c[k] = probe->center_mm[k] + depth_mm * probe->dir[k];
    body_work *w = NULL;
    cf_status st = cf_body_work_get(b, &w, err);
    if (st != CF_OK)
        return st;
    pattern *P = &w->P;
    double *g = w->g, *dx = w->dx, *xt = w->xt;
    uint8_t *active = w->active;
    /* Active set: Newton's method with the set of nodes in contact held (each held node pushed
    ** back by the penalty in proportion to its signed depth), then the set replaced by the nodes
    ** inside the probe, until it no longer changes (penalty contact with a set that changes
    ** inside Newton's iteration cycles between states). Within a set, the factors of an earlier
    ** tangent serve as long as each step reduces the residual to a quarter (chord steps: the
    ** next update of a probe moving slowly reuses the last factors); otherwise, and whenever the
    ** set changes, the tangent is assembled and factored afresh. */
    const double fscale = b->E_MPa * b->mean_edge_mm * b->mean_edge_mm;
    int it = 0, contacts = 0, rounds, fresh = 0;
    double force = 0;
    for (size_t i = 0; i < b->nn; i++) {
        double nrm[3];
        uint8_t in = b->fix[i] != CF_BODY_FIX_ALL && cf_body_penetration(probe, c, b->x + 3 * i, nrm, 0) > 0;
        fresh |= in != active[i];
        active[i] = in;
    }
    fresh |= !w->factored;
    for (rounds = 0; rounds < 100; rounds++) {
        int conv = 0;
        double rprev = INFINITY;
        for (int k = 0; k < 200 && !conv; k++, it++) {
            force = cf_body_assemble(b, b->x, probe, c, kp, active, g, fresh ? P : NULL, &contacts);
            if (isnan(force)) {
                st = cf_error_set(err, CF_E_INTERNAL, "out of memory for the body's tangent");
                goto end;
            }
            cf_body_apply_fixed(b, fresh ? P : NULL, g);
            double r = body_norm_inf(g, n);
            if (r <= 1e-8 * fscale) {
                conv = 1;
                break;
            }
            if (!fresh && !(r <= 0.25 * rprev)) {
                /* the old factors no longer converge fast: take the tangent here */
                fresh = 1;
                rprev = INFINITY;
                k--;
                it--;
                continue;
            }
            if (fresh) {
                w->factored = 0;
                if ((st = cf_sparse_chol_factor(w->ch, P->val, NULL, err)) != CF_OK)
                    goto end;
                w->factored = 1;
            }
            if ((st = cf_sparse_chol_solve(w->ch, g, dx, err)) != CF_OK)
                goto end;
            for (size_t i = 0; i < b->nn; i++) /* held components never move (old factors */
                for (int a = 0; a < 3; a++)    /* may have been made with other ones held) */
                    if ((b->fix[i] >> a) & 1)
                        dx[3 * i + (size_t)a] = 0;
            fresh = 0;
            rprev = r;
            double alpha = 2;
            int ok = 0;
            for (int bt = 0; bt < 40 && !ok; bt++) {
                alpha *= 0.5;
                for (size_t i = 0; i < n; i++)
                    xt[i] = b->x[i] - alpha * dx[i];
                ok = cf_body_admissible(b, xt);
            }
            if (!ok) {
                st = cf_error_set(err, CF_E_NOCONV,
                                  "body: at probe depth %g mm every Newton step would invert a "
                                  "tetrahedron or take a spring to solid",
                                  depth_mm);
                goto end;
            }
            memcpy(b->x, xt, n * sizeof *xt);
            if (alpha < 0.99)
                fresh = 1; /* a shortened step: take the tangent where it landed */
            if (alpha * body_norm_inf(dx, n) <= 1e-14 * b->mean_edge_mm)
                conv = 1;
        }
        if (!conv) {
            st = cf_error_set(err, CF_E_NOCONV,
                              "body: Newton's method did not converge at probe depth %g mm",
                              depth_mm);
            goto end;
        }
        int changed = 0;
        for (size_t i = 0; i < b->nn; i++) {
            double nrm[3];
            uint8_t in = b->fix[i] != CF_BODY_FIX_ALL && cf_body_penetration(probe, c, b->x + 3 * i, nrm, 0) > 0;
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
    cf_body_keep_reaction(b, g);
    out->depth_mm = depth_mm;
    out->force_N = force;
    out->contacts = contacts;
    out->newton_iters = it;
    out->min_J = cf_body_measure(b, NULL, &out->max_u_over_travel);
end:
    return st;
}

/* The depth, from `now` on, at which the probe first touches a node at its current position
** (INFINITY: never). */
static double touch_depth(const cf_body *b, const cf_probe *pr, double now)
{
    double dmin = INFINITY;
    const double R = pr->radius_mm;
    for (size_t i = 0; i < b->nn; i++) {
        if (b->fix[i] == CF_BODY_FIX_ALL)
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

cf_status cf_body_solve_force(cf_body *b, const cf_probe *probe, double force_N, double *depth_mm,
                              double penalty_N_per_mm, cf_body_step *out, cf_error *err)
{
    const size_t n = 3 * b->nn;
    if (!(force_N > 0) || !isfinite(force_N) || !isfinite(*depth_mm))
        return cf_error_set(err, CF_E_DATA, "body: probe force %g N: must be finite and > 0",
                            force_N);
    double *xlo = malloc(n * sizeof *xlo), *xhi = malloc(n * sizeof *xhi);
    if (!xlo || !xhi) {
        free(xlo);
        free(xhi);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the force-driven probe");
    }
    cf_status st = CF_OK;
    cf_body_step s = {0};
    int iters = 0; /* Newton iterations of every trial */
    /* the lower end: the current depth, or where the probe first touches */
    double dlo = *depth_mm, flo = 0, dhi = 0, fhi = 0;
    if ((st = cf_body_solve(b, probe, dlo, penalty_N_per_mm, &s, err)) != CF_OK)
        goto end;
    flo = s.force_N;
    iters += s.newton_iters;
    if (s.contacts == 0) {
        const double dt = touch_depth(b, probe, dlo);
        if (!isfinite(dt)) {
            st = cf_error_set(err, CF_E_DATA, "body: the probe moves past the body without "
                              "touching it, so it cannot reach %g N", force_N);
            goto end;
        }
        if (dt > dlo) {
            dlo = dt;
            flo = 0;
        }
    }
    memcpy(xlo, b->x, n * sizeof *xlo);
    if (flo >= force_N) { /* already there or past it: the bracket's upper end is here */
        dhi = dlo;
        fhi = flo;
        memcpy(xhi, xlo, n * sizeof *xhi);
        dlo = *depth_mm > dhi ? dhi : *depth_mm;
        flo = -INFINITY;
    }
    /* the upper end: steps that double from a tenth of the mean edge */
    double step = 0.1 * b->mean_edge_mm;
    for (int k = 0; fhi < force_N; k++) {
        if (k == 60) {
            st = cf_error_set(err, CF_E_NOCONV, "body: the probe did not reach %g N", force_N);
            goto end;
        }
        dhi = dlo + step;
        memcpy(b->x, xlo, n * sizeof *xlo);
        if ((st = cf_body_solve(b, probe, dhi, penalty_N_per_mm, &s, err)) != CF_OK) {
            if (err)
                snprintf(err->msg + strlen(err->msg), sizeof err->msg - strlen(err->msg),
                         " (seeking the depth of the probe force %g N)", force_N);
            goto end;
        }
        fhi = s.force_N;
        iters += s.newton_iters;
        memcpy(xhi, b->x, n * sizeof *xhi);
        if (fhi < force_N) {
            dlo = dhi;
            flo = fhi;
            memcpy(xlo, xhi, n * sizeof *xlo);
            step *= 2;
        }
    }
    /* regula falsi with Illinois' halving between dlo (force below) and dhi (at or above) */
    int side = 0;
    double d = dhi, f = fhi;
    for (int it = 0; it < 200; it++) {
        if (fabs(f - force_N) <= 1e-6 * force_N ||
            dhi - dlo <= 1e-12 * b->mean_edge_mm)
            break;
        d = isfinite(flo) && fhi > flo ? dlo + (force_N - flo) * (dhi - dlo) / (fhi - flo)
                                       : 0.5 * (dlo + dhi);
        if (!(d > dlo && d < dhi))
            d = 0.5 * (dlo + dhi);
        memcpy(b->x, force_N - flo < fhi - force_N ? xlo : xhi, n * sizeof *xlo);
        if ((st = cf_body_solve(b, probe, d, penalty_N_per_mm, &s, err)) != CF_OK)
            goto end;
        iters += s.newton_iters;
        f = s.force_N;
        if (f < force_N) {
            dlo = d;
            flo = f;
            memcpy(xlo, b->x, n * sizeof *xlo);
            if (side == -1 && isfinite(fhi))
                fhi = force_N + 0.5 * (fhi - force_N);
            side = -1;
        } else {
            dhi = d;
            fhi = f;
            memcpy(xhi, b->x, n * sizeof *xhi);
            if (side == 1 && isfinite(flo))
                flo = force_N - 0.5 * (force_N - flo);
            side = 1;
        }
    }
    if (d != s.depth_mm) { /* the last trial was not at d: solve there */
        if ((st = cf_body_solve(b, probe, d, penalty_N_per_mm, &s, err)) != CF_OK)
            goto end;
        iters += s.newton_iters;
    }
    *depth_mm = s.depth_mm;
    *out = s;
    out->newton_iters = iters;
end:
    free(xlo);
    free(xhi);
    return st;
}
