/*
** Tissue bodies (body.h): the static probe solve, Newton's method on the sparse tangent with an
** active set of the nodes in contact.
*/
#include <math.h>
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
