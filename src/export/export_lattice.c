/*
** Export of the whole validation lattice (see export.h, cf_export_write_lattice): the lattice is
** built from the fitted spring exactly as the validation builds it, run once by conifit's own
** static solver along the loading (its top reaction at every step goes into the file, and a
** loading it cannot follow is refused), and its springs are grouped by rest length and weight so
** that each group carries one table: the law in strain form, u = -(L - L0) H/L0, times the
** group's weight (the family's weight times the cell shares of a spring on a face or an edge).
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "export/export.h"
#include "base/gslguard.h"
#include "model/lattice.h"
#include "check/validate.h"
#include "export/export_internal.h"

cf_export_lattice cf_export_lattice_default(const cf_law *law)
{
    cf_export_lattice lx;
    memset(&lx, 0, sizeof lx);
    const cf_validate_setup v = cf_validate_default();
    lx.cfg = v.cfg;
    lx.method = v.method;
    lx.nsteps = CF_EXPORT_DEFAULT_STEPS;
    const double end = CF_EXPORT_DEFAULT_STRAIN_FRACTION * law->travel_mm / law->p.H_mm;
    for (size_t k = 0; k < lx.nsteps; k++)
        lx.strain[k] = end * (double)(k + 1) / (double)lx.nsteps;
    return lx;
}

/* A scene's time protocol as its quasi-static displacement history: refused (CF_E_DATA) under a
** stress drive or with gravity; what it leaves out into lx->note. */
static cf_status time_protocol(const cf_scene *sc, const char *name, cf_export_lattice *lx,
                               cf_error *err)
{
    const char *kind = sc->kind == CF_PROTO_CYCLES ? "cycles"
                       : sc->kind == CF_PROTO_HOLD ? "hold"
                                                   : "history";
    lx->stress_drive = sc->drive != CF_DRIVE_DISPLACEMENT;
    const cf_msm_effects *e = &sc->effects;
    if (e->gravity_mm_per_s2 != 0)
        return cf_error_set(err, CF_E_DATA,
                            "%s: key 'effects.gravity': the lattice export writes no body force",
                            name);
    char left[200] = "";
    size_t n = 0;
    if (e->prony_count > 0)
        n += (size_t)snprintf(left + n, sizeof left - n, "%s%d Prony terms (viscosity)",
                              n ? ", " : "", e->prony_count);
    if (e->maxwell_E_MPa != 0 && n < sizeof left)
        n += (size_t)snprintf(left + n, sizeof left - n, "%sthe Maxwell branch (viscosity)",
                              n ? ", " : "");
    if (e->eta_MPa_s != 0 && n < sizeof left)
        n += (size_t)snprintf(left + n, sizeof left - n, "%sthe dashpots (damping)",
                              n ? ", " : "");
    if (e->inertia && n < sizeof left)
        snprintf(left + n, sizeof left - n, "%sinertia", n ? ", " : "");
    snprintf(lx->note, sizeof lx->note,
             "protocol '%s' written as its quasi-static displacement history, one static "
             "step per sample, of the elastic lattice%s%s%s; the reference reactions are "
             "conifit's elastic run along the same path, not the scene's simulation",
             kind,
             lx->stress_drive ? " (its stress history turned into the strains of conifit's "
                                "elastic lattice under it, force-driven)"
                              : "",
             left[0] ? ": not carried: " : "", left);
    return CF_OK;
}

cf_status cf_export_lattice_from_scene(const cf_scene *sc, const char *name,
                                       cf_export_lattice *lx, cf_error *err)
{
    memset(lx, 0, sizeof *lx);
    if (sc->fibre_fit)
        return cf_error_set(err, CF_E_DATA,
                            "%s: key 'fibres': a fibre fit's lattice (its matrix, groups and "
                            "weights from the fit file) is not exported; give its groups as "
                            "'fibres' entries with an axis and a spring",
                            name);
    cf_validate_setup v;
    const int timed = sc->kind != CF_PROTO_RAMP;
    cf_status st = timed ? time_protocol(sc, name, lx, err) : CF_OK;
    if (st != CF_OK)
        return st;
    lx->nfibre = sc->nfibres; /* the validation's lattice takes none: they are the writer's */
    for (size_t k = 0; k < sc->nfibres; k++) {
        lx->fibre_spring[k] = sc->fibres[k].spring;
        memcpy(lx->fibre_dir[k], sc->fibres[k].axis, sizeof lx->fibre_dir[k]);
        lx->fibre_density[k] = sc->fibres[k].density;
        lx->fibre_slack[k] = sc->fibres[k].slack;
    }
    cf_scene nofib = *sc;
    nofib.nfibres = 0;
    sc = &nofib;
    if (timed) { /* the elastic lattice along the protocol's displacement history */
        cf_scene elastic = *sc;
        elastic.kind = CF_PROTO_RAMP;
        elastic.drive = CF_DRIVE_DISPLACEMENT; /* a stress history: its strains, see above */
        memset(&elastic.effects, 0, sizeof elastic.effects);
        st = cf_validate_from_scene(&elastic, name, &v, err);
    } else
        st = cf_validate_from_scene(sc, name, &v, err);
    if (st != CF_OK)
        return st;
    lx->cfg = v.cfg;
    lx->cfg.progress = NULL;
    lx->ngroups = sc->ngroups; /* the scene's spring groups, their laws made by the writer */
    for (size_t k = 0; k < sc->ngroups; k++) {
        lx->group_family[k] = sc->groups[k].family;
        lx->group_spring[k] = sc->groups[k].spring;
    }
    /* the reference run needs no table: the closed form is within 2.5e-15 of exact */
    lx->method = v.method == CF_LAW_TABLE ? CF_LAW_CLOSED : v.method;
    const cf_msm_path p = cf_scene_path(sc);
    for (size_t k = 0; k < sc->nsamples; k++) {
        const double t = sc->sample_t_s[k];
        if (!(t > p.t_s[0]))
            continue; /* the rest state is not a step */
        double e = p.value[p.count - 1];
        for (size_t i = 1; i < p.count; i++)
            if (t <= p.t_s[i]) {
                const double f = (t - p.t_s[i - 1]) / (p.t_s[i] - p.t_s[i - 1]);
                e = p.value[i - 1] + f * (p.value[i] - p.value[i - 1]);
                break;
            }
        if (lx->nsteps == CF_EXPORT_MAX_STEPS)
            return cf_error_set(err, CF_E_DATA,
                                "%s: %zu samples: a lattice export takes at most %d load steps "
                                "(use fewer samples_per_segment)",
                                name, sc->nsamples, CF_EXPORT_MAX_STEPS);
        if (e == 0.0 && !timed)
            continue;
        lx->strain[lx->nsteps++] = e;
    }
    if (lx->nsteps == 0)
        return cf_error_set(err, CF_E_DATA, "%s: the loading never leaves the rest state", name);
    return CF_OK;
}

/* Title of the lattice model. */
static void lattice_title(char *buf, size_t cap, const cf_lattice_config *c)
{
    snprintf(buf, cap,
             "lattice of %d x %d x %d cells (family weights: edge %.6g, face diagonal %.6g, body "
             "diagonal %.6g), bottom %s, uniaxial compression along z",
             c->nx, c->ny, c->nz, c->weight[CF_FAMILY_EDGE], c->weight[CF_FAMILY_FACE],
             c->weight[CF_FAMILY_BODY],
             c->bottom == CF_BOTTOM_CLAMPED ? "clamped" : "held along z (sliding)");
}

/* The lattice's net (its generator's nodes, springs and fixity: those the lattice was built from)
** into m with its springs grouped, its top nodes and its cells. */
static int model_of_lattice(cf_xmodel *m, const cf_lattice *lat)
{
    cf_net net;
    cf_error e = {0};
    if (cf_net_lattice(&net, &lat->cfg, lat->H_mm, &e) != CF_OK)
        return -1; /* the lattice was built from this configuration: only memory can fail */
    int rc = cf_xmodel_of_net(m, &net, CF_XGROUP_SHARED);
    m->ntop = lat->ntop;
    m->top = malloc(m->ntop * sizeof *m->top);
    m->area_mm2 = lat->area_mm2;
    m->height_mm = lat->height_mm;
    m->kappa_MPa = lat->cfg.volume_modulus_MPa;
    m->hg_k_N_per_mm = lat->hg_k_N_per_mm;
    if (m->kappa_MPa > 0 || m->hg_k_N_per_mm > 0 || lat->cfg.nfibre > 0) {
        /* the net's cells, eight nodes each, corner di + 2 dj + 4 dk */
        m->ncells = net.nc;
        m->cell = malloc(8 * m->ncells * sizeof *m->cell);
        if (m->cell)
            memcpy(m->cell, net.cell, 8 * m->ncells * sizeof *m->cell);
        else
            rc = -1;
    }
    cf_net_free(&net);
    if (rc != 0 || !m->top)
        return -1;
    memcpy(m->top, lat->top, m->ntop * sizeof *m->top);
    /* the springs a horizontal plane through the middle of a layer of cells cuts */
    const double zc = lat->H_mm * (floor(lat->cfg.nz / 2.0) + 0.5);
    double cut = 0.0;
    for (size_t s = 0; s < m->ns; s++) {
        const double za = lat->Z[lat->si[s]], zb = lat->Z[lat->sj[s]];
        if ((za - zc) * (zb - zc) < 0.0)
            cut += lat->w[s] * fabs(zb - za) / lat->L0_mm[s];
    }
    m->reaction_tol_N = cut; /* times tol F_C by the caller */
    return 0;
}

/* conifit's static run of the elastic lattice along lx's values (strains, or stresses when drive
** is CF_DRIVE_FORCE), one sample per step into out, from and back to the lattice at rest. */
static cf_status run_loading(cf_lattice *lat, const cf_export_lattice *lx, cf_msm_drive drive,
                             cf_msm_sample *out, cf_msm_stats *stats, cf_error *err)
{
    double t[CF_EXPORT_MAX_STEPS + 1], v[CF_EXPORT_MAX_STEPS + 1];
    t[0] = 0.0;
    v[0] = 0.0;
    for (size_t k = 0; k < lx->nsteps; k++) {
        t[k + 1] = (double)(k + 1);
        v[k + 1] = lx->strain[k];
    }
    const cf_msm_path path = {drive, lx->nsteps + 1, t, v};
    const cf_msm_effects none = {0};
    size_t done = 0;
    cf_lattice_reset(lat);
    cf_status st = cf_msm_run(lat, &none, &lx->cfg, &path, t + 1, lx->nsteps, out, &done, stats,
                              err);
    cf_lattice_reset(lat);
    return st;
}

/* conifit's static run along the loading (the same solver as `conifit simulate`): compressive
** top reaction (N) at each step into ref_N, the largest spring compression (mm), and the first
** step whose equilibrium is unstable (negative pivots of the tangent; 0 when none is). */
static cf_status reference_run(cf_lattice *lat, const cf_export_lattice *lx, double *ref_N,
                               double *max_u_mm, size_t *unstable, long *pivots, cf_error *err)
{
    cf_msm_sample out[CF_EXPORT_MAX_STEPS];
    cf_msm_stats stats = {0};
    cf_status st = run_loading(lat, lx, CF_DRIVE_DISPLACEMENT, out, &stats, err);
    if (st != CF_OK)
        return st;
    *unstable = 0;
    for (size_t k = 0; k < lx->nsteps; k++) {
        ref_N[k] = out[k].stress_MPa * lat->area_mm2;
        if (!*unstable && out[k].neg_pivots > 0) {
            *unstable = k + 1;
            *pivots = out[k].neg_pivots;
        }
    }
    *max_u_mm = stats.max_u_over_travel * lat->travel_mm;
    return CF_OK;
}

/* The largest number of leading steps (< n) that conifit's lattice follows stably and within the
** tables, by bisection. */
static size_t steps_that_work(cf_lattice *lat, const cf_export_lattice *lx, double u_limit,
                              size_t n)
{
    size_t lo = 0, hi = n; /* lo steps work, hi do not */
    while (hi - lo > 1) {
        size_t mid = (lo + hi) / 2;
        cf_export_lattice part = *lx;
        part.nsteps = mid;
        double ref[CF_EXPORT_MAX_STEPS], umax;
        size_t bad;
        long piv;
        cf_error e = {0};
        if (reference_run(lat, &part, ref, &umax, &bad, &piv, &e) == CF_OK && umax <= u_limit &&
            bad == 0)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

/* The format writes models and the loading has 1 to CF_EXPORT_MAX_STEPS finite steps. */
static cf_status check_loading(const cf_export_options *opt, const cf_export_lattice *lx,
                               cf_error *err)
{
    const cf_export_format_info *fi = cf_export_format_get(opt->format);
    if (!fi || !fi->model)
        return cf_error_set(err, CF_E_DATA, "format %s writes no model",
                            cf_export_format_name(opt->format));
    if (lx->nsteps == 0 || lx->nsteps > CF_EXPORT_MAX_STEPS)
        return cf_error_set(err, CF_E_DATA, "%zu load steps: a lattice export takes 1 to %d",
                            lx->nsteps, CF_EXPORT_MAX_STEPS);
    for (size_t k = 0; k < lx->nsteps; k++)
        if (!isfinite(lx->strain[k]))
            return cf_error_set(err, CF_E_DATA, "load step %zu: strain is not finite", k + 1);
    return CF_OK;
}

/* The model of the lattice built from law with table t, loaded along lx (its title into title,
** cap bytes). 0, or -1 when memory runs out. */
static int lattice_model(cf_xmodel *m, const cf_lattice *lat, const cf_law *law,
                         const cf_export_table *t, const cf_export_lattice *lx,
                         const cf_export_options *opt, char *title, size_t cap)
{
    if (model_of_lattice(m, lat) != 0)
        return -1;
    m->reaction_tol_N *= t->tol * law->F_C_N;
    m->law = law;
    m->base = t;
    m->source = opt->source;
    m->output = opt->output;
    lattice_title(title, cap, &lx->cfg.lattice);
    m->title = title;
    m->nsteps = lx->nsteps;
    m->dz_mm = malloc(m->nsteps * sizeof *m->dz_mm);
    m->ref_N = malloc(m->nsteps * sizeof *m->ref_N);
    m->strain = malloc(m->nsteps * sizeof *m->strain);
    if (!m->dz_mm || !m->ref_N || !m->strain)
        return -1;
    for (size_t k = 0; k < m->nsteps; k++) {
        m->strain[k] = lx->strain[k];
        m->dz_mm[k] = -lx->strain[k] * lat->height_mm;
    }
    return 0;
}

/* Why the lattice cannot follow the loading (the reference run failed with run_err, was
** unstable from step `unstable` with `pivots` negative pivots, or compressed a spring to umax
** past u_limit), with the largest strain that works (its first ok steps): CF_E_DATA. */
static cf_status refuse_loading(const cf_law *law, const cf_export_lattice *lx, size_t ok,
                                cf_status run_st, const cf_error *run_err, double umax,
                                double u_limit, size_t unstable, long pivots, cf_error *err)
{
    char works[160];
    if (ok > 0)
        snprintf(works, sizeof works, "the loading works up to strain %.6g (step %zu)",
                 lx->strain[ok - 1], ok);
    else
        snprintf(works, sizeof works, "not even the first step (strain %.6g) works",
                 lx->strain[0]);
    if (run_st != CF_OK)
        return cf_error_set(err, CF_E_DATA,
                            "the lattice cannot follow the loading to strain %.6g: %s; %s",
                            lx->strain[lx->nsteps - 1], run_err->msg, works);
    if (!unstable)
        return cf_error_set(err, CF_E_DATA,
                            "a spring of the lattice is compressed to %.6g mm, past the table's "
                            "end at %.6g mm (solid at %.6g mm); %s",
                            umax, u_limit, law->travel_mm, works);
    /* where exactly: the first negative pivot along this side of the loading */
    double limit = 0.0;
    cf_error e2 = {0};
    const int side = lx->strain[unstable - 1] > 0 ? -1 : +1;
    char where[96] = "";
    if (cf_msm_stability_limit(law, lx->method, &lx->cfg, side, &limit, &e2) == CF_OK &&
        limit != 0.0)
        snprintf(where, sizeof where, " (stable up to strain %.6g)", fabs(limit));
    return cf_error_set(err, CF_E_DATA,
                        "the lattice loses stability within the loading%s: at strain %.6g "
                        "(step %zu) its tangent has %ld negative pivots, so a simulator "
                        "would leave the homogeneous state there; %s",
                        where, lx->strain[unstable - 1], unstable, pivots, works);
}

/* A stress-driven loading (lx->stress_drive) as the strains conifit's elastic lattice takes
** under it, force-driven, into *strained; lx itself otherwise. NULL, *st and err set, when the
** run fails. */
static const cf_export_lattice *strained_loading(cf_lattice *lat, const cf_export_lattice *lx,
                                                 cf_export_lattice *strained, cf_status *st,
                                                 cf_error *err)
{
    if (!lx->stress_drive)
        return lx;
    cf_msm_sample out[CF_EXPORT_MAX_STEPS];
    cf_msm_stats stats = {0};
    cf_error e = {0};
    *st = run_loading(lat, lx, CF_DRIVE_FORCE, out, &stats, &e);
    if (*st != CF_OK) {
        cf_error_set(err, *st, "the elastic lattice under the scene's stress history: %s", e.msg);
        return NULL;
    }
    *strained = *lx;
    strained->stress_drive = 0;
    for (size_t k = 0; k < lx->nsteps; k++)
        strained->strain[k] = out[k].strain;
    return strained;
}

/* The loading to write: lx when conifit's lattice follows it (stably, within the tables), else
** its leading steps that it follows, in *part, with why the rest is cut at the end of note (after
** lx->note); conifit's reactions along it into ref. NULL, *st and err set, when not even the first
** step works or memory runs out. */
static const cf_export_lattice *loading_that_works(cf_lattice *lat, const cf_law *law,
                                                   const cf_export_table *t,
                                                   const cf_export_lattice *lx,
                                                   cf_export_lattice *part, double *ref,
                                                   char *note, size_t cap, cf_status *st,
                                                   cf_error *err)
{
    double umax = 0.0;
    size_t unstable = 0;
    long pivots = 0;
    cf_error run_err = {0};
    snprintf(note, cap, "%s", lx->note);
    cf_status rs = reference_run(lat, lx, ref, &umax, &unstable, &pivots, &run_err);
    /* the table's ends against the largest compression (either side: max_u_over_travel is of
    ** each spring's own side's travel) */
    const double u_limit = fmin(t->u_hi_mm, -t->u_lo_mm);
    if (rs == CF_OK && umax <= u_limit && !unstable)
        return lx;
    const size_t ok = steps_that_work(lat, lx, u_limit, lx->nsteps);
    cf_error why = {0};
    refuse_loading(law, lx, ok, rs, &run_err, umax, u_limit, unstable, pivots, &why);
    if (ok == 0) {
        *st = cf_error_set(err, CF_E_DATA, "%s", why.msg);
        return NULL;
    }
    *part = *lx;
    part->nsteps = ok;
    if ((rs = reference_run(lat, part, ref, &umax, &unstable, &pivots, &run_err)) != CF_OK) {
        *st = cf_error_set(err, rs, "%s", run_err.msg); /* it worked in the bisection */
        return NULL;
    }
    const size_t n = strlen(note);
    snprintf(note + n, cap - n,
             "%sthe loading is cut after step %zu of %zu (strain %.6g), where conifit's lattice "
             "stops following it: %s",
             n ? "; " : "", ok, lx->nsteps, lx->strain[ok - 1], why.msg);
    return part;
}

/* What propagated_tol gathers along its run: after every even sample (a step's equilibrium) the
** springs' lengths, after every odd one (h back toward rest) the largest sum of w |dL| / dD. */
typedef struct rate_walk {
    cf_lattice *lat;
    double *L_mm;        /* lengths at the last step's equilibrium */
    const double *dD_mm; /* top displacement between a step and its neighbour, per step */
    double worst;        /* the largest sum so far */
} rate_walk;

static void rate_sample(void *ctx, size_t done, size_t total, double t_s)
{
    (void)total;
    (void)t_s;
    rate_walk *r = ctx;
    const cf_lattice *lat = r->lat;
    double sum = 0.0;
    for (size_t s = 0; s < lat->ns; s++) {
        const size_t i = lat->si[s], j = lat->sj[s];
        const double len =
            hypot(hypot(lat->x[j] - lat->x[i], lat->y[j] - lat->y[i]), lat->z[j] - lat->z[i]);
        if (done % 2 == 1)
            r->L_mm[s] = len;
        else
            sum += lat->w[s] * fabs(len - r->L_mm[s]);
    }
    if (done % 2 == 0) {
        const double rate = sum / r->dD_mm[done / 2 - 1];
        if (isfinite(rate) && rate > r->worst)
            r->worst = rate;
    }
}

/* The reaction tolerance of a lattice with a volume term or hourglass control (N, before the
** factor tol F_C): a table's force error dF (|dF| <= tol F_C, in a spring w dF) moves the
** equilibrium, and the cells' stiffness turns that move into reaction. To first order (virtual
** work with the symmetric tangent) a tension dT_s added to spring s changes the top reaction by
** dT_s dL_s/dD, dL_s/dD the rate of the spring's length along conifit's equilibrium path per unit
** top displacement D. So |dR| <= tol F_C sum_s w_s |dL_s/dD|, taken here at every step (the rates
** by a difference of two equilibria 1e-6 of the height apart, one run along the loading that
** steps back by that after every step) and the largest kept; at least `cut`, which is also the
** answer when memory runs out or the run fails (it followed the same steps as the reference). */
static double propagated_tol(cf_lattice *lat, const cf_export_lattice *lx, double cut)
{
    const size_t n = lx->nsteps, m = 2 * n;
    double *t = malloc((m + 1) * sizeof *t), *v = malloc((m + 1) * sizeof *v);
    double *dD = malloc(n * sizeof *dD), *L = malloc(lat->ns * sizeof *L);
    cf_msm_sample *out = malloc(m * sizeof *out);
    rate_walk r = {lat, L, dD, cut};
    if (t && v && dD && L && out) {
        t[0] = v[0] = 0.0;
        for (size_t k = 0; k < n; k++) {
            const double e = lx->strain[k], h = e >= 0.0 ? 1e-6 : -1e-6;
            t[2 * k + 1] = (double)(2 * k + 1);
            v[2 * k + 1] = e;
            t[2 * k + 2] = (double)(2 * k + 2);
            v[2 * k + 2] = e - h; /* toward rest */
            dD[k] = 1e-6 * lat->height_mm;
        }
        const cf_msm_path path = {CF_DRIVE_DISPLACEMENT, m + 1, t, v};
        const cf_msm_effects none = {0};
        cf_msm_config cfg = lx->cfg;
        cfg.progress = rate_sample;
        cfg.progress_ctx = &r;
        cf_msm_stats stats = {0};
        size_t done = 0;
        cf_error err = {0};
        cf_lattice_reset(lat);
        if (cf_msm_run(lat, &none, &cfg, &path, t + 1, m, out, &done, &stats, &err) != CF_OK)
            r.worst = cut;
        cf_lattice_reset(lat);
    }
    free(t);
    free(v);
    free(dD);
    free(L);
    free(out);
    return r.worst;
}

/* The laws of lx's spring groups into group[family] with their tables gt[family] (the others left
** zeroed), and *glx a copy of *lx whose lattice points at them; CF_E_DATA when the fit fs is a
** double-acting element. */
static cf_status group_laws(const cf_fitted_spring *fs, const cf_export_lattice *lx,
                            const cf_export_options *opt, cf_law group[CF_FAMILY_COUNT],
                            cf_export_table gt[CF_FAMILY_COUNT], cf_export_lattice *glx,
                            cf_error *err)
{
    if (fs->has_extension)
        return cf_error_set(err, CF_E_DATA, "spring groups do not combine with a double-acting "
                                            "element (the fit holds one)");
    *glx = *lx;
    for (size_t k = 0; k < lx->ngroups; k++) {
        const int f = lx->group_family[k];
        if (f < 0 || f >= CF_FAMILY_COUNT)
            return cf_error_set(err, CF_E_DATA, "spring group %zu: family %d unknown", k, f);
        cf_status st = cf_law_init(&group[f], &lx->group_spring[k], err);
        if (st == CF_OK)
            st = cf_export_table_for(&group[f], opt, &gt[f], err);
        if (st != CF_OK)
            return st;
        glx->cfg.lattice.group_law[f] = &group[f];
    }
    return CF_OK;
}

/* A lattice's fibre groups as the writer builds them: laws, their tables, the groups. */
typedef struct fibre_set {
    cf_law law[CF_FIBRE_MAX];
    cf_export_table t[CF_FIBRE_MAX];
    cf_fibre_group grp[CF_FIBRE_MAX];
} fibre_set;

/* The laws of lx's fibre groups into f with their tables and groups, the lattice's configuration
** lc pointing at them; CalculiX and Abaqus only (CF_E_DATA naming the format). */
static cf_status fibre_laws(const cf_export_lattice *lx, const cf_export_options *opt,
                            fibre_set *f, cf_lattice_config *lc, cf_error *err)
{
    cf_law *law = f->law;
    cf_export_table *t = f->t;
    cf_fibre_group *grp = f->grp;
    if (opt->format != CF_EXPORT_CALCULIX && opt->format != CF_EXPORT_ABAQUS)
        return cf_error_set(err, CF_E_DATA,
                            "%s: the lattice's %zu fibre group%s (embedded tension-only springs "
                            "tied to the cells by linear constraints) %s no form in this export; "
                            "export it to calculix",
                            cf_export_format_name(opt->format), lx->nfibre,
                            lx->nfibre == 1 ? "" : "s", lx->nfibre == 1 ? "has" : "have");
    if (lx->nfibre > CF_FIBRE_MAX)
        return cf_error_set(err, CF_E_DATA, "%zu fibre groups: at most %d", lx->nfibre,
                            CF_FIBRE_MAX);
    for (size_t k = 0; k < lx->nfibre; k++) {
        cf_status st = cf_law_init(&law[k], &lx->fibre_spring[k], err);
        if (st == CF_OK)
            st = cf_export_table_for(&law[k], opt, &t[k], err);
        if (st != CF_OK)
            return st;
        grp[k].law = &law[k];
        grp[k].method = lx->method;
        memcpy(grp[k].dir, lx->fibre_dir[k], sizeof grp[k].dir);
        grp[k].density = lx->fibre_density[k];
        grp[k].slack = lx->fibre_slack[k];
    }
    lc->fibre = grp;
    lc->nfibre = (int)lx->nfibre;
    return CF_OK;
}

/* The model's groups given their spring group's law and table (a group's family from its rest
** length, H, sqrt 2 H or sqrt 3 H), and the largest tol F_C over the tables (the model's reaction
** tolerance scaled to it): the one law's t->tol F_C without groups. */
static double group_tables_of_model(cf_xmodel *m, const cf_lattice *lat, const cf_law *law,
                                    const cf_export_table *t, const cf_law group[CF_FAMILY_COUNT],
                                    const cf_export_table gt[CF_FAMILY_COUNT])
{
    double tolF = t->tol * law->F_C_N;
    if (!lat->grouped)
        return tolF;
    for (size_t g = 0; g < m->ng; g++) {
        const double r = m->g[g].L0_mm / lat->H_mm;
        const long f = lround(r * r) - 1;
        if (f >= 0 && f < CF_FAMILY_COUNT && lat->cfg.group_law[f]) {
            m->g[g].law = &group[f];
            m->g[g].table = &gt[f];
            tolF = fmax(tolF, gt[f].tol * group[f].F_C_N);
        }
    }
    m->reaction_tol_N *= tolF / (t->tol * law->F_C_N); /* the group whose table errs most */
    return tolF;
}

/* Builds the table and the lattice, runs conifit's reference along the loading (refusing a
** loading the lattice cannot follow), then writes the model. */
cf_status cf_export_write_lattice(FILE *out, const cf_fitted_spring *fs,
                                  const cf_export_options *opt, const cf_export_lattice *lx,
                                  cf_export_report *rep, cf_error *err)
{
    CF_GSL_GUARD;
    cf_law law, ext;
    cf_lattice lat;
    cf_export_table t = {0};
    cf_xmodel m = {0};
    cf_export_report r = {0};
    char title[256], note[sizeof r.warning];
    cf_export_lattice part, strained, glx;
    double ref[CF_EXPORT_MAX_STEPS];
    cf_law group[CF_FAMILY_COUNT] = {0};
    cf_export_table gt[CF_FAMILY_COUNT] = {0};
    fibre_set fib = {0};
    memset(&lat, 0, sizeof lat);
    memset(&ext, 0, sizeof ext);
    cf_status st = check_loading(opt, lx, err);
    if (st != CF_OK || (st = cf_fitted_law(fs, &law, err)) != CF_OK)
        return st;
    if (lx->ngroups > 0) { /* spring groups: each its law and table, the lattice pointing at them */
        if ((st = group_laws(fs, lx, opt, group, gt, &glx, err)) != CF_OK)
            goto done;
        lx = &glx;
    }
    /* the fit's whole element and volume term (a scene naming the fit file brings the same) */
    cf_lattice_config lc = lx->cfg.lattice;
    if (lx->nfibre > 0 && (st = fibre_laws(lx, opt, &fib, &lc, err)) != CF_OK)
        goto done;
    if (!(lc.volume_modulus_MPa > 0))
        lc.volume_modulus_MPa = fs->volume_modulus_MPa;
    /* the cells' hourglass control (lattice_hourglass.h) as CalculiX and Abaqus write it; the other
    ** formats have no element that carries it, so their lattice is built without it: the
    ** reference reactions of a homogeneous loading are the same, and the stability check below is
    ** then of the model the file holds (which can buckle where conifit's lattice with hourglass
    ** control does not, and is refused there) */
    if (!cf_xmodel_carries_hourglass(opt->format))
        lc.hourglass = 0;
    if (fs->has_extension && ((st = cf_law_init(&ext, &fs->extension, err)) != CF_OK ||
                              (st = cf_law_pair(&law, &ext, err)) != CF_OK))
        goto done;
    if ((st = cf_export_table_for(&law, opt, &t, err)) != CF_OK ||
        (st = cf_lattice_create(&lat, &law, lx->method, &lc, err)) != CF_OK)
        goto done;
    if (!(lx = strained_loading(&lat, lx, &strained, &st, err)) ||
        !(lx = loading_that_works(&lat, &law, &t, lx, &part, ref, note, sizeof note, &st, err)))
        goto done;
    if (lattice_model(&m, &lat, &law, &t, lx, opt, title, sizeof title) != 0)
        goto oom;
    const double tolF = group_tables_of_model(&m, &lat, &law, &t, group, gt);
    m.note = note;
    memcpy(m.ref_N, ref, m.nsteps * sizeof *m.ref_N);
    if (m.ncells > 0) /* the cells' stiffness propagates the tables' error (propagated_tol) */
        m.reaction_tol_N = tolF * propagated_tol(&lat, lx, m.reaction_tol_N / tolF);
    const char *no_volume = cf_xmodel_volume_refusal(&m, opt->format);
    if (no_volume) {
        st = cf_error_set(err, CF_E_DATA,
                          "the lattice has a volume term (kappa = %g MPa) that format %s cannot "
                          "carry: %s",
                          m.kappa_MPa, cf_export_format_name(opt->format), no_volume);
        goto done;
    }
    for (size_t k = 0; k < m.nsteps; k++)
        if (!isfinite(m.ref_N[k])) {
            st = cf_error_set(err, CF_E_INTERNAL, "reference reaction at step %zu is not finite",
                              k + 1);
            goto done;
        }
    if (cf_xmodel_tables(&m) != 0 || cf_xmodel_lattice_fibres(&m, &lat, fib.t) != 0 ||
        cf_xmodel_write(out, &m, opt->format) != 0)
        goto oom;
    r = cf_export_report_of_table(&t, &law);
    r.groups = m.ng;
    r.springs = m.ns;
    r.nodes = m.nn;
    r.steps = m.nsteps;
    snprintf(r.warning, sizeof r.warning, "%s", note);
    if (ferror(out))
        st = cf_error_set(err, CF_E_CANTWRITE, "cannot write the %s lattice export",
                          cf_export_format_name(opt->format));
    goto done;
oom:
    st = cf_error_set(err, CF_E_INTERNAL, "out of memory writing the lattice model");
done:
    if (rep)
        *rep = r;
    cf_xmodel_free(&m);
    cf_lattice_free(&lat);
    cf_export_table_free(&t);
    cf_law_free(&law);
    cf_law_free(&ext);
    for (int f = 0; f < CF_FAMILY_COUNT; f++) {
        cf_export_table_free(&gt[f]);
        cf_law_free(&group[f]);
    }
    for (int k = 0; k < CF_FIBRE_MAX; k++)
        cf_export_table_free(&fib.t[k]), cf_law_free(&fib.law[k]);
    return st;
}
