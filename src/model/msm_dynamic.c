/*
** Explicit symplectic dynamics of the lattice (see msm.h): the stable step, one step (the fused
** stencil of lattice_step.h when the springs are elastic only), the energies, and the steps
** between two samples.
*/
#include "model/msm_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

double cf_msm_stable_step(cf_lattice *lat, const cf_msm_effects *fx)
{
    cf_lattice_forces(lat);
    double kmax = 0, cmax = 0;
    double H2 = lat->H_mm * lat->H_mm;
    double branch = fx->maxwell_E_MPa > 0 ? fx->maxwell_E_MPa : 0.0;
    for (size_t q = 0; q < lat->ns; q++) {
        double k = lat->w[q] * lat->a[q] * lat->k_N_per_mm[q] + fabs(lat->T_N[q]) / lat->L_mm[q] +
                   lat->w[q] * H2 * branch / lat->L0_mm[q];
        kmax = fmax(kmax, k);
        cmax = fmax(cmax, lat->w[q] * H2 * fx->eta_MPa_s / lat->L0_mm[q]);
    }
    /* Gershgorin: omega^2 <= (2 * degree * k_max + the volume term's largest row sum) / m_min
    ** (the row sums of the springs' and the volume term's stiffness add) */
    double deg = lat->max_degree > 0 ? lat->max_degree : 1;
    double om2 = (2 * deg * kmax + cf_lattice_volume_row_bound(lat)) / lat->m_min_t;
    if (!(om2 > 0))
        return INFINITY;
    double om = sqrt(om2);
    double zeta = deg * cmax / (lat->m_min_t * om); /* c_node / (2 m omega), c_node <= 2 deg c */
    return 2.0 / om * (sqrt(1 + zeta * zeta) - zeta);
}

/* One symplectic Euler step of length h ending at drive value v1 (rate for prescribed DOFs). */
static void dyn_step(solver *s, dyn *d, double h, double v1, double rate)
{
    cf_lattice *lat = s->lat;
    const cf_msm_effects *fx = s->fx;
    const size_t ns = lat->ns, nn = lat->nn;
    if (d->fused) {
        /* node forces are zero here (cleared by the last advance or before the interval) */
        cf_lattice_stepper_forces(&d->step);
        cf_lattice_add_volume_forces(lat);
        cf_msm_add_external(s);
        cf_lattice_stepper_advance(&d->step, h, d->vx, d->vy, d->vz);
        goto drive;
    }
    lat->with_stiffness = 0; /* an explicit step needs forces only */
    cf_lattice_forces(lat);
    lat->with_stiffness = 1;
    double H2 = lat->H_mm * lat->H_mm;
    if (fx->eta_MPa_s > 0 || s->sigm) {
        /* Rate of change of every spring length. */
        for (size_t q = 0; q < ns; q++) {
            uint32_t i = lat->si[q], j = lat->sj[q];
            d->Ld[q] = ((lat->x[j] - lat->x[i]) * (d->vx[j] - d->vx[i]) +
                        (lat->y[j] - lat->y[i]) * (d->vy[j] - d->vy[i]) +
                        (lat->z[j] - lat->z[i]) * (d->vz[j] - d->vz[i])) /
                       lat->L_mm[q];
        }
        memset(d->Tt, 0, ns * sizeof(double));
        if (fx->eta_MPa_s > 0)
            for (size_t q = 0; q < ns; q++)
                d->Tt[q] += lat->w[q] * H2 * fx->eta_MPa_s / lat->L0_mm[q] * d->Ld[q];
        if (s->sigm) {
            double E1 = exp(-h / fx->maxwell_tau_s);
            double mc = fx->maxwell_E_MPa * fx->maxwell_tau_s * (-expm1(-h / fx->maxwell_tau_s));
            for (size_t q = 0; q < ns; q++) {
                d->Tt[q] += lat->w[q] * H2 * s->sigm[q];
                s->sigm[q] = s->sigm[q] * E1 + mc * d->Ld[q] / lat->L0_mm[q];
            }
        }
        cf_lattice_add_tensions(lat, d->Tt);
    }
    cf_msm_add_external(s);
    double *v[3] = {d->vx, d->vy, d->vz};
    for (int a = 0; a < 3; a++) {
        double *x = coord(lat, a), *f = force(lat, a), *va = v[a];
        for (size_t p = 0; p < nn; p++) {
            if (s->eq[3 * p + a] < 0)
                continue;
            va[p] += h * f[p] / lat->mass_t[p];
            x[p] += h * va[p];
        }
    }
drive:
    if (s->drive == CF_DRIVE_DISPLACEMENT) {
        cf_msm_place_top(lat, v1);
        for (size_t t = 0; t < lat->ntop; t++)
            d->vz[lat->top[t]] = -rate * lat->height_mm;
    }
    if (s->st)
        s->st->steps++;
}

double cf_msm_kinetic(const cf_lattice *lat, const dyn *d)
{
    double e = 0;
    for (size_t p = 0; p < lat->nn; p++)
        e += 0.5 * lat->mass_t[p] * (d->vx[p] * d->vx[p] + d->vy[p] * d->vy[p] + d->vz[p] * d->vz[p]);
    return e;
}

/* Total energy for a constant load: kinetic + elastic + gravity - work potential of the load. */
double cf_msm_total_energy(solver *s, const dyn *d)
{
    cf_lattice *lat = s->lat;
    double e = cf_msm_kinetic(lat, d) + cf_lattice_elastic_energy(lat);
    if (s->fx->gravity_mm_per_s2 != 0)
        for (size_t p = 0; p < lat->nn; p++)
            e += lat->mass_t[p] * s->fx->gravity_mm_per_s2 * (lat->z[p] - lat->Z[p]);
    if (s->drive == CF_DRIVE_FORCE)
        for (size_t t = 0; t < lat->ntop; t++) {
            uint32_t p = lat->top[t];
            e += s->load * lat->H_mm * lat->H_mm * lat->top_share[t] * (lat->z[p] - lat->Z[p]);
        }
    return e;
}

void cf_msm_dyn_free(dyn *d)
{
    free(d->vx);
    free(d->vy);
    free(d->vz);
    free(d->Ld);
    free(d->Tt);
    if (d->fused)
        cf_lattice_stepper_free(&d->step);
}

/* The dynamic state (velocities at rest) of an explicit run; the fused step when the springs are
** elastic only. */
cf_status cf_msm_dyn_init(dyn *d, solver *s, cf_error *err)
{
    cf_lattice *lat = s->lat;
    d->vx = calloc(lat->nn, sizeof(double));
    d->vy = calloc(lat->nn, sizeof(double));
    d->vz = calloc(lat->nn, sizeof(double));
    d->Ld = calloc(lat->ns ? lat->ns : 1, sizeof(double));
    d->Tt = calloc(lat->ns ? lat->ns : 1, sizeof(double));
    if (!d->vx || !d->vy || !d->vz || !d->Ld || !d->Tt)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the dynamic state");
    d->fused = !(s->fx->eta_MPa_s > 0) && !s->sigm;
    cf_status rc = CF_OK;
    if (d->fused && (rc = cf_lattice_stepper_init(&d->step, lat, s->eq, err)) != CF_OK)
        d->fused = 0;
    return rc;
}

/* Explicit steps from t to tk, each within the stable step (and cfg->dt_s when set). */
cf_status cf_msm_explicit_interval(solver *s, dyn *d, const cf_msm_path *path,
                                   double t, double tk, cf_msm_stats *st, cf_error *err)
{
    cf_lattice *lat = s->lat;
    const cf_msm_effects *fx = s->fx;
    double stab = CF_MSM_DT_SAFETY * cf_msm_stable_step(lat, fx);
    double want = s->cfg->dt_s > 0 ? s->cfg->dt_s : stab;
    if (want > stab) {
        want = stab;
        st->substepped++;
    }
    double n = ceil((tk - t) / want - 1e-9);
    if (n > 1e12)
        return cf_error_set(err, CF_E_DATA, "stable step %.3g s is too small for %.3g s", want,
                            tk - t);
    double h = (tk - t) / n;
    if (st->dt_used_min_s == 0 || h < st->dt_used_min_s)
        st->dt_used_min_s = h;
    for (double m = 1; m <= n; m++) {
        double tb = t + m * h;
        double vb = cf_msm_path_value(path, tb);
        double rate = (vb - cf_msm_path_value(path, tb - h)) / h;
        s->load = vb;
        if (m == 1 && d->fused) { /* the fused step adds onto zeroed node forces */
            memset(lat->fx, 0, lat->nn * sizeof(double));
            memset(lat->fy, 0, lat->nn * sizeof(double));
            memset(lat->fz, 0, lat->nn * sizeof(double));
        }
        dyn_step(s, d, h, vb, rate);
    }
    double um = cf_lattice_forces(lat);
    st->max_u_over_travel = fmax(st->max_u_over_travel, um);
    if (um >= 1)
        return cf_error_set(err, CF_E_NOCONV,
                            "a spring reached solid length at t = %.6g s (strain %.6g): the load "
                            "is more than the lattice can carry",
                            tk, cf_lattice_top_strain(lat));
    return CF_OK;
}
