/*
** Tissue bodies (body.h): dynamic runs, an implicit step of Newmark's average-acceleration
** scheme (Newmark 1959, J Eng Mech Div ASCE 85:67-94; beta = 1/4, gamma = 1/2, the trapezoidal
** rule: unconditionally stable for a linear system, second-order accurate, and without numerical
** damping) on the static solve's Newton iteration. Written as a residual in the end-of-step
** positions x: with a = (4/dt^2)(x - x_n) - (4/dt) v_n - a_n and v = (2/dt)(x - x_n) - v_n,
** M a + c M v = mcoef M (x - xstar), mcoef = 4/dt^2 + 2c/dt,
** xstar = x_n + ((4/dt + c) v_n + a_n)/mcoef, a term the assembly adds to the residual and, as
** mcoef m_i, to the diagonal of the tangent (cf_body_add_inertia). The step takes Newmark's
** gamma from the motion (cf_body_motion.gamma; beta = (gamma + 1/2)^2/4), of which these are
** the formulas at gamma = 1/2; above it the step damps the fastest vibrations.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/body_internal.h"

void cf_body_motion_free(cf_body_motion *m)
{
    if (!m)
        return;
    free(m->mass);
    free(m->v);
    free(m->a);
    free(m->xprev);
    memset(m, 0, sizeof *m);
}

cf_status cf_body_motion_init(const cf_body *b, double rho_t_per_mm3, double damping_per_s,
                              cf_body_motion *m, cf_error *err)
{
    memset(m, 0, sizeof *m);
    if (!(rho_t_per_mm3 > 0) || !isfinite(rho_t_per_mm3))
        return cf_error_set(err, CF_E_DATA, "body: density %g t/mm^3: must be finite and > 0",
                            rho_t_per_mm3);
    if (!(damping_per_s >= 0) || !isfinite(damping_per_s))
        return cf_error_set(err, CF_E_DATA, "body: damping %g 1/s: must be finite and >= 0",
                            damping_per_s);
    const size_t n = 3 * b->nn;
    m->mass = calloc(b->nn, sizeof *m->mass);
    m->v = calloc(n, sizeof *m->v);
    m->a = calloc(n, sizeof *m->a);
    m->xprev = malloc(n * sizeof *m->xprev);
    if (!m->mass || !m->v || !m->a || !m->xprev) {
        cf_body_motion_free(m);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the motion of %zu nodes",
                            b->nn);
    }
    for (size_t t = 0; t < b->nt; t++)
        for (int k = 0; k < 4; k++)
            m->mass[b->tet[4 * t + (size_t)k]] += 0.25 * rho_t_per_mm3 * b->V0[t];
    memcpy(m->xprev, b->x, n * sizeof *m->xprev);
    m->damping_per_s = damping_per_s;
    return CF_OK;
}

cf_status cf_body_dynamic_step(cf_body *b, cf_body_motion *m, const cf_probe *probe,
                               double depth_mm, double dt_s, double penalty_N_per_mm,
                               cf_body_step *out, cf_error *err)
{
    if (!(dt_s > 0) || !isfinite(dt_s))
        return cf_error_set(err, CF_E_DATA, "body: time step %g s: must be finite and > 0", dt_s);
    body_work *w = NULL;
    cf_status st = cf_body_work_static(b, &w, err);
    if (st != CF_OK)
        return st;
    const size_t n = 3 * b->nn;
    const double c = m->damping_per_s;
    /* Newmark's family: gamma >= 1/2, beta = (gamma + 1/2)^2 / 4 (gamma 1/2: average
    ** acceleration); A = 1/(beta dt^2), a = A (x - x_n) - A dt v_n - (1/(2 beta) - 1) a_n,
    ** v = v_n + dt ((1 - gamma) a_n + gamma a) */
    const double gam = m->gamma > 0.5 ? m->gamma : 0.5, beta = 0.25 * (gam + 0.5) * (gam + 0.5);
    const double A = 1 / (beta * dt_s * dt_s), ka = 1 / (2 * beta) - 1;
    const double mcoef = A * (1 + c * gam * dt_s);
    double *xstar = malloc(n * sizeof *xstar);
    if (!xstar)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the motion of %zu nodes",
                            b->nn);
    for (size_t q = 0; q < n; q++) {
        /* a + c v = mcoef (x - x_n) + r0, r0 the terms without x */
        const double a0 = -A * dt_s * m->v[q] - ka * m->a[q];
        const double v0 = m->v[q] + dt_s * (1 - gam) * m->a[q] + dt_s * gam * a0;
        xstar[q] = m->xprev[q] - (a0 + c * v0) / mcoef;
        if (!((b->fix[q / 3] >> (q % 3)) & 1))
            b->x[q] = m->xprev[q] + dt_s * m->v[q]; /* the predictor: constant velocity */
    }
    if (!cf_body_admissible(b, b->x)) /* too far: start where the last step ended */
        for (size_t q = 0; q < n; q++)
            if (!((b->fix[q / 3] >> (q % 3)) & 1))
                b->x[q] = m->xprev[q];
    w->mass = m->mass;
    w->xstar = xstar;
    w->mcoef = mcoef;
    st = cf_body_solve(b, probe, depth_mm, penalty_N_per_mm, out, err);
    w->mcoef = 0;
    w->mass = w->xstar = NULL;
    free(xstar);
    if (st != CF_OK)
        return st;
    for (size_t q = 0; q < n; q++) {
        const double a = A * (b->x[q] - m->xprev[q]) - A * dt_s * m->v[q] - ka * m->a[q];
        m->v[q] += dt_s * ((1 - gam) * m->a[q] + gam * a);
        m->a[q] = a;
        m->xprev[q] = b->x[q];
    }
    m->t_s += dt_s;
    return CF_OK;
}
