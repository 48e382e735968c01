/*
** The time-dependent model of a fitted tissue (see viscomodel.h): the lattice of msm.h with Prony
** branches, driven by a measured strain history.
*/
#include "model/viscomodel.h"
#include "base/gslguard.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/cell.h"

cf_visco_setup cf_visco_default(void)
{
    cf_visco_setup s;
    s.cell = 1;
    s.cfg = cf_msm_default();
    s.method = CF_LAW_CLOSED;
    return s;
}

cf_msm_effects cf_visco_effects(const cf_visco_params *p)
{
    cf_msm_effects fx;
    memset(&fx, 0, sizeof fx);
    fx.eta_MPa_s = p->eta_MPa_s;
    fx.prony_count = p->nbranch;
    for (int i = 0; i < p->nbranch && i < CF_PRONY_MAX; i++) {
        fx.prony_g[i] = p->g[i];
        fx.prony_tau_s[i] = p->tau_s[i];
        fx.prony_k[i] = p->k[i];
    }
    return fx;
}

static cf_status check_params(const cf_visco_params *p, cf_error *err)
{
    if (!(p->ident.rho > 0 && p->ident.rho <= 1))
        return cf_error_set(err, CF_E_DATA, "rho = %g: must be in (0, 1]", p->ident.rho);
    if (!(p->ident.solid > 0 && p->ident.solid < 1))
        return cf_error_set(err, CF_E_DATA, "solid strain = %g: must be in (0, 1)",
                            p->ident.solid);
    if (!(p->ident.scale > 0) || !isfinite(p->ident.scale))
        return cf_error_set(err, CF_E_DATA, "stress scale = %g MPa: must be finite and > 0",
                            p->ident.scale);
    /* the cone closes at s/H + e_t: below the free length, with room for the solid lengths */
    if (!(p->e_tail >= 0) || !isfinite(p->e_tail) || !(p->ident.solid + p->e_tail < 1))
        return cf_error_set(err, CF_E_DATA,
                            "tail compliance e_t = %g: must be finite, >= 0 and below 1 - s/H "
                            "(%g)",
                            p->e_tail, 1 - p->ident.solid);
    if (!(p->eta_MPa_s >= 0) || !isfinite(p->eta_MPa_s))
        return cf_error_set(err, CF_E_DATA, "dashpot eta = %g MPa s: must be finite and >= 0",
                            p->eta_MPa_s);
    if (p->nbranch < 0 || p->nbranch > CF_PRONY_MAX)
        return cf_error_set(err, CF_E_DATA, "%d Prony terms: between 0 and %d", p->nbranch,
                            CF_PRONY_MAX);
    cf_msm_effects fx = cf_visco_effects(p);
    return cf_msm_prony_check(&fx, err);
}


cf_spring cf_visco_member(const cf_visco_params *p)
{
    return p->e_tail > 0 ? cf_ident_member_tail(&p->ident, p->e_tail / p->ident.solid)
                         : cf_ident_member(&p->ident);
}

/* The law of the model's spring (cf_visco_member) after checking p, with its table when s
** asks for one. */
static cf_status member_law(const cf_visco_params *p, const cf_visco_setup *s, cf_law *law,
                            cf_error *err)
{
    cf_status st = check_params(p, err);
    if (st != CF_OK)
        return st;
    cf_spring sp = cf_visco_member(p);
    st = cf_law_init(law, &sp, err);
    if (st == CF_OK && s->method == CF_LAW_TABLE &&
        (st = cf_law_table_build(law, CF_LAW_TABLE_DEFAULT, err)) != CF_OK)
        cf_law_free(law);
    return st;
}

/* ---- the homogenised cell -------------------------------------------------------------------- */

/* The state of the model in the cell: per direction the Prony branch forces (N per unit weight,
** compression positive), the law force and length at the start of the step. */
typedef struct cell_run {
    cf_cell cell;
    const cf_law *law;
    cf_law_method method;
    const cf_visco_params *p;
    double H;                          /* cell edge, mm */
    double L0[CF_CELL_DIRS], w[CF_CELL_DIRS];
    int mirror[CF_CELL_DIRS];          /* the first direction whose offsets differ in sign only */
    double h[CF_CELL_DIRS][CF_PRONY_MAX];
    double Fprev[CF_CELL_DIRS], Lprev[CF_CELL_DIRS];
    cf_cell_state st;                  /* the current state */
    int strain_moduli;                 /* 1 when a Prony modulus changes with strain */
    cf_msm_effects fx;                 /* p's effects (cf_visco_effects) */
    double a_prev, dt_prev;            /* free stretch of the step before, and that step's dt */
    /* the branches' decay and update factors over a step of length coef_dt (NaN: none yet): the
    ** steps of one sample interval, and of a series sampled evenly, share them */
    double coef_dt, pe[CF_PRONY_MAX], pb[CF_PRONY_MAX], alpha, slope;
} cell_run;

/* Where the lateral solve of a step of length dt starts: the stretch of the step before carried
** on along the change over the last step, scaled to dt (its Newton iteration then starts within
** the step's second-order change, which saves about one evaluation of the cell per step); the
** last stretch when there is no step before. The solve's answer does not depend on the start
** beyond rounding. */
static double stretch_guess(const cell_run *r, double dt)
{
    const double a = r->cell.stretch_hint;
    if (!(dt > 0) || !(a > 0) || !(r->a_prev > 0) || !(r->dt_prev > 0))
        return a;
    const double g = a + (a - r->a_prev) * (dt / r->dt_prev);
    return isfinite(g) && g > 0 ? g : a;
}

/* One implicit step of length dt (0: the relaxed state at the start) to table strain e. Over the
** step every spring's tension is w (alpha F(u) + c) plus its dashpot, alpha = 1 - sum g_i (1 - b_i)
** - |e| sum k_i (1 - b_i) at the spring's strain e (relaxation growing with strain, msm.h), and c
** from the branches' state (the exact recursive update for a law force linear in time along
** the step): the law scaled by alpha and a term affine in the spring's length, which is what the
** cell takes (cf_cell.law_scale and cf_cell_extra), so the cell's own solve of its free lateral
** stretch (cf_cell_mode) gives the step's equilibrium exactly. */
static cf_status cell_step(cell_run *r, double dt, double e, cf_error *err)
{
    const cf_visco_params *p = r->p;
    const int np = p->nbranch;
    double *pe = r->pe, *pb = r->pb;
    if (!(dt == r->coef_dt)) {
        double alpha = 1, slope = 0;
        for (int i = 0; i < np; i++) {
            pe[i] = dt > 0 ? exp(-dt / p->tau_s[i]) : 0;
            pb[i] = dt > 0 ? -expm1(-dt / p->tau_s[i]) * p->tau_s[i] / dt : 0;
            alpha -= p->g[i] * (1 - pb[i]);
            slope -= p->k[i] * (1 - pb[i]);
        }
        r->coef_dt = dt;
        r->alpha = alpha;
        r->slope = slope;
    }
    const double alpha = r->alpha, slope = r->slope;
    const double H = r->H, visc = dt > 0 ? p->eta_MPa_s / dt : 0;
    cf_cell_extra x;
    double e0[CF_CELL_DIRS]; /* each spring's |strain| at the start of the step */
    /* alike[d]: d starts the step in the state of its mirror (the same length, force and branch
    ** forces, the same rest length and weight), so every quantity of the step is the mirror's to
    ** the bit and is copied */
    int alike[CF_CELL_DIRS];
    for (int d = 0; d < CF_CELL_DIRS; d++) {
        const int m = r->mirror[d];
        alike[d] = m < d && r->Lprev[m] == r->Lprev[d] && r->Fprev[m] == r->Fprev[d];
        for (int i = 0; i < np && alike[d]; i++)
            alike[d] = r->h[m][i] == r->h[d][i];
        if (alike[d]) {
            e0[d] = e0[m];
            x.T0_N[d] = x.T0_N[m];
            x.k_N_per_mm[d] = x.k_N_per_mm[m];
            x.Lref_mm[d] = x.Lref_mm[m];
            continue;
        }
        double c = 0;
        e0[d] = fabs(1 - r->Lprev[d] / r->L0[d]);
        for (int i = 0; i < np && dt > 0; i++)
            c += pe[i] * r->h[d][i] - (p->g[i] + p->k[i] * e0[d]) * pb[i] * r->Fprev[d];
        x.T0_N[d] = -r->w[d] * c;                                    /* branches, tension + */
        x.k_N_per_mm[d] = r->w[d] * H * H * visc / r->L0[d];         /* dashpot, as msm.h */
        x.Lref_mm[d] = r->Lprev[d];
    }
    /* dt = 0 (the first sample): e_i = b_i = 0, so alpha = g_inf and the branches hold nothing,
    ** the relaxed state the lattice starts from (msm.h) */
    r->cell.law_scale = alpha;
    r->cell.law_scale_strain = slope;
    const double a_start = r->cell.stretch_hint;
    r->cell.stretch_hint = stretch_guess(r, dt);
    cf_status st = cf_cell_mode(&r->cell, CF_MODE_UNIAXIAL, e, &x, &r->st, err);
    r->cell.law_scale = 1.0;
    r->cell.law_scale_strain = 0.0;
    r->cell.stretch_hint = a_start;
    if (st != CF_OK)
        return st;
    if (dt > 0 && a_start > 0) {
        r->a_prev = a_start;
        r->dt_prev = dt;
    }
    r->cell.stretch_hint = r->st.free_stretch; /* the next step starts here */
    if (r->strain_moduli) { /* the moduli where the springs went (msm.h) */
        for (int d = 0; d < CF_CELL_DIRS && st == CF_OK; d++) {
            int same = 0; /* an earlier spring of the same strain was checked */
            while (same < d && !(r->st.L_mm[same] == r->st.L_mm[d] && r->L0[same] == r->L0[d]))
                same++;
            if (same == d)
                st = cf_msm_prony_at_strain(&r->fx, fabs(1 - r->st.L_mm[d] / r->L0[d]), err);
        }
        if (st != CF_OK)
            return st;
    }
    double fd[CF_CELL_DIRS];
    for (int d = 0; d < CF_CELL_DIRS; d++) {
        const int m = r->mirror[d];
        if (alike[d] && r->st.L_mm[m] == r->st.L_mm[d]) { /* and ends it where its mirror does */
            fd[d] = fd[m];
            memcpy(r->h[d], r->h[m], (size_t)np * sizeof r->h[d][0]);
            r->Fprev[d] = r->Fprev[m];
            r->Lprev[d] = r->Lprev[m];
            continue;
        }
        const double u = H * (1 - r->st.L_mm[d] / r->L0[d]), e1 = fabs(u) / H;
        int same = 0; /* an earlier spring of the same rest and current length: its force */
        while (same < d && !(r->st.L_mm[same] == r->st.L_mm[d] && r->L0[same] == r->L0[d]))
            same++;
        const double f = fd[d] =
            same < d ? fd[same] : cf_law_force(r->law, r->method, u, NULL, NULL);
        for (int i = 0; i < np && dt > 0; i++)
            r->h[d][i] = pe[i] * r->h[d][i] +
                         (p->k[i] == 0 ? p->g[i] * pb[i] * (f - r->Fprev[d])
                                       : pb[i] * ((p->g[i] + p->k[i] * e1) * f -
                                                  (p->g[i] + p->k[i] * e0[d]) * r->Fprev[d]));
        r->Fprev[d] = f;
        r->Lprev[d] = r->st.L_mm[d];
    }
    return CF_OK;
}

/* A force-driven step: the table strain whose stress is the target (MPa, table sign), by the
** secant method inside a bracket on a copy of the state. */
static cf_status cell_step_force(cell_run *r, double dt, double target, double e0, cf_error *err)
{
    cell_run trial;
    double lo = -r->law->travel_mm / r->H * (1 - 1e-9), hi = -lo;
    double ea = e0, eb = e0 + (target >= 0 ? 1e-3 : -1e-3), fa, fb;
    cf_status st;
    trial = *r;
    if ((st = cell_step(&trial, dt, ea, err)) != CF_OK)
        return st;
    fa = trial.st.stress_MPa - target;
    for (int it = 0; it < 100; it++) {
        trial = *r;
        eb = fmin(fmax(eb, lo), hi);
        if ((st = cell_step(&trial, dt, eb, err)) != CF_OK) {
            eb = 0.5 * (ea + eb);
            continue;
        }
        fb = trial.st.stress_MPa - target;
        if (fabs(fb) <= 1e-13 * fmax(fabs(target), 1e-300) || fabs(eb - ea) <= 1e-15) {
            *r = trial;
            return CF_OK;
        }
        double en = fb != fa ? eb - fb * (eb - ea) / (fb - fa) : eb + 1e-3;
        ea = eb;
        fa = fb;
        eb = en;
    }
    return cf_error_set(err, CF_E_NOCONV, "the cell found no strain carrying %g MPa", target);
}


/* cf_msm_path_value(p, t), its search started at segment *from (t past that segment's start,
** times not decreasing: the segment it would find is then at or after it) and *from moved to the
** segment found; the same value to the bit. */
static double path_value_from(const cf_msm_path *p, double t, size_t *from)
{
    size_t i = *from;
    if (!(i >= 1 && i < p->count && t > p->t_s[i - 1]))
        return cf_msm_path_value(p, t);
    for (; i < p->count; i++)
        if (t <= p->t_s[i]) {
            *from = i;
            double h = p->t_s[i] - p->t_s[i - 1];
            double f = h > 0 ? (t - p->t_s[i - 1]) / h : 1.0;
            return p->value[i - 1] + f * (p->value[i] - p->value[i - 1]);
        }
    return p->value[p->count - 1];
}

/* The model in the cell along a path, stepped as cf_msm_run steps it (quasi_substeps implicit
** steps per sample interval, or steps of dt_s), samples as msm.h reports them (compressive
** positive). */
static cf_status cell_path(const cf_visco_params *p, const cf_visco_setup *s, const cf_law *law,
                           const cf_msm_path *path, const double *ts, size_t ns,
                           cf_msm_sample *out, cf_error *err)
{
    cell_run *r = calloc(1, sizeof *r);
    if (!r)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the cell");
    cf_status st = cf_cell_init(&r->cell, law, s->method, s->cfg.lattice.weight, err);
    if (st != CF_OK) {
        free(r);
        return st;
    }
    r->cell.linear_finish = 1; /* the state to first order in the solve's last, tiny step */
    r->law = law;
    r->method = s->method;
    r->p = p;
    r->H = law->p.H_mm;
    r->fx = cf_visco_effects(p);
    r->strain_moduli = cf_msm_prony_depends_on_strain(&r->fx);
    r->coef_dt = NAN;
    for (int d = 0; d < CF_CELL_DIRS; d++) {
        int N[3], fam, M[3], mf;
        cf_cell_direction(d, N, &fam);
        r->mirror[d] = d;
        for (int e = 0; e < d && r->mirror[d] == d; e++) {
            cf_cell_direction(e, M, &mf);
            if (abs(M[0]) == abs(N[0]) && abs(M[1]) == abs(N[1]) && abs(M[2]) == abs(N[2]))
                r->mirror[d] = e;
        }
        r->L0[d] = r->H * sqrt((double)(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]));
        r->w[d] = s->cfg.lattice.weight[fam];
        r->Lprev[d] = r->L0[d];
    }
    const int force = path->drive == CF_DRIVE_FORCE;
    size_t seg = 1; /* where the path's search starts (1 always starts it afresh) */
    for (size_t i = 1; i < path->count; i++)
        if (!(path->t_s[i] >= path->t_s[i - 1]))
            seg = 0; /* times that go back: every search from the start */
    double t = ns ? fmin(ts[0], path->t_s[0]) : 0, e = 0;
    for (size_t k = 0; k < ns && st == CF_OK; k++) {
        const double tk = ts[k];
        if (k == 0 || !(tk > t)) {
            if (k == 0) { /* at rest: the branches relaxed */
                double v = cf_msm_path_value(path, tk);
                st = force ? cell_step_force(r, 0, -v, e, err) : cell_step(r, 0, -v, err);
            }
        } else {
            int n = s->cfg.quasi_substeps > 0 ? s->cfg.quasi_substeps : 1;
            if (s->cfg.dt_s > 0)
                n = (int)fmin(1e9, ceil((tk - t) / s->cfg.dt_s - 1e-9));
            if (n < 1)
                n = 1;
            const double h = (tk - t) / n;
            for (int j = 1; j <= n && st == CF_OK; j++) {
                double v = seg ? path_value_from(path, t + j * h, &seg)
                               : cf_msm_path_value(path, t + j * h);
                st = force ? cell_step_force(r, h, -v, e, err) : cell_step(r, h, -v, err);
                if (force && st == CF_OK)
                    e = r->st.F[8] - 1; /* the next secant starts here */
            }
        }
        if (force && st == CF_OK)
            e = r->st.F[8] - 1;
        t = tk;
        if (st == CF_OK) {
            out[k].t_s = tk;
            out[k].strain = -(r->st.F[8] - 1);
            out[k].stress_MPa = force ? cf_msm_path_value(path, tk) : -r->st.stress_MPa;
            out[k].kinetic_mJ = 0;
            if (!isfinite(out[k].strain) || !isfinite(out[k].stress_MPa))
                st = cf_error_set(err, CF_E_INTERNAL, "the cell became non-finite at t = %g s",
                                  tk);
        }
    }
    free(r);
    return st;
}

static cf_status run(const cf_visco_params *p, const cf_visco_setup *s, const cf_msm_path *path,
                     const double *sample_t_s, size_t nsamples, cf_msm_sample *out,
                     cf_msm_stats *stats, cf_error *err)
{
    cf_law law;
    cf_status st = member_law(p, s, &law, err);
    if (st != CF_OK)
        return st;
    cf_lattice lat;
    if (s->cell) {
        st = cell_path(p, s, &law, path, sample_t_s, nsamples, out, err);
    } else if ((st = cf_lattice_create(&lat, &law, s->method, &s->cfg.lattice, err)) == CF_OK) {
        cf_msm_effects fx = cf_visco_effects(p);
        cf_msm_config cfg = s->cfg;
        cfg.progress = NULL;
        st = cf_msm_run(&lat, &fx, &cfg, path, sample_t_s, nsamples, out, NULL, stats, err);
        cf_lattice_free(&lat);
    }
    cf_law_free(&law);
    return st;
}

cf_status cf_visco_run(const cf_visco_params *p, const cf_visco_setup *s, const cf_msm_path *path,
                       const double *sample_t_s, size_t nsamples, cf_msm_sample *out,
                       cf_error *err)
{
    CF_GSL_GUARD;
    return run(p, s, path, sample_t_s, nsamples, out, NULL, err);
}

cf_status cf_visco_curve(const cf_visco_params *p, const cf_visco_setup *s,
                         const cf_visco_series *series, double *stress_MPa, cf_msm_stats *stats,
                         cf_error *err)
{
    CF_GSL_GUARD;
    const size_t n = series->count;
    if (n < 2)
        return cf_error_set(err, CF_E_DATA, "a time series needs at least 2 points");
    for (size_t k = 0; k < n; k++) {
        if (!isfinite(series->t_s[k]) || !isfinite(series->strain[k]))
            return cf_error_set(err, CF_E_DATA, "point %zu of the series is not finite", k + 1);
        if (k > 0 && !(series->t_s[k] > series->t_s[k - 1]))
            return cf_error_set(err, CF_E_DATA,
                                "time %.17g s at point %zu does not increase (previous %.17g s)",
                                series->t_s[k], k + 1, series->t_s[k - 1]);
    }
    double *v = malloc(n * sizeof(double));
    cf_msm_sample *out = malloc(n * sizeof(cf_msm_sample));
    if (!v || !out) {
        free(v);
        free(out);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for a series of %zu points", n);
    }
    for (size_t k = 0; k < n; k++)
        v[k] = -series->strain[k]; /* compressive positive */
    cf_msm_path path = {CF_DRIVE_DISPLACEMENT, n, series->t_s, v};
    cf_status st = run(p, s, &path, series->t_s, n, out, stats, err);
    for (size_t k = 0; st == CF_OK && k < n; k++)
        stress_MPa[k] = -out[k].stress_MPa;
    free(v);
    free(out);
    return st;
}

cf_status cf_visco_elastic_curve(const cf_visco_params *p, const cf_visco_setup *s,
                                 const double *strain, size_t count, double *stress_MPa,
                                 cf_error *err)
{
    CF_GSL_GUARD;
    cf_law law;
    cf_status st = member_law(p, s, &law, err);
    if (st != CF_OK)
        return st;
    if (s->cell) {
        cf_cell c;
        if ((st = cf_cell_init(&c, &law, s->method, s->cfg.lattice.weight, err)) == CF_OK)
            st = cf_cell_curve(&c, CF_MODE_UNIAXIAL, strain, count, stress_MPa, err);
    } else {
        st = cf_msm_uniaxial(&law, s->method, &s->cfg, strain, count, stress_MPa, NULL, err);
    }
    cf_law_free(&law);
    return st;
}
