/*
** The joint fit (see pipeline_joint.h).
*/
#include "pipeline/pipeline_joint.h"
#include "base/gslguard.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

#include "fit/joint.h"
#include "fit/lawkind.h"

/* 1 when the joint fit b is kept over a (the one law choice, cf_law_pick): asked for, or
** feasible with a lower joint AIC and a lattice stable over every table's range unless a's is
** not either; between two fits that are both buildable and stable, the one whose cell stays
** strongly elliptic over every range when its objective is within CF_JOINT_ELLIPTIC_SLACK of the
** other's. */
static int pick(const cf_joint_result *a, const cf_joint_result *b, int asked)
{
    /* a lattice unstable at rest models no solid: never kept over one that is stable there */
    if (!asked && cf_joint_stable_at_rest(a) != cf_joint_stable_at_rest(b))
        return cf_joint_stable_at_rest(b);
    const cf_law_standing s[2] = {{a->fit.feasible, cf_joint_stable(a), a->aic},
                                  {b->fit.feasible, cf_joint_stable(b), b->aic}};
    /* between two buildable lattices stable over every range, the one whose cell stays strongly
    ** elliptic there at an objective close enough (cf_joint_elliptic_wins); otherwise the
    ** ordinary choice */
    if (!asked && cf_joint_elliptic_wins(b, a))
        return 1;
    if (!asked && cf_joint_elliptic_wins(a, b))
        return 0;
    return cf_law_pick(s, 2, asked ? 1 : -1) == 1;
}

/* The tailed law's joint fit beside the conical one in fits[k], and the law kept: --law
** conical-tail the tail, auto the tail only with a lower joint AIC, a feasible spring and a
** lattice stable over every table's range (unless the conical law's is not either), as a single
** fit chooses (pipeline.c). A tailed fit that ends worse than the conical one or finds
** no spring is the conical optimum it contains, with no tail (cf_joint_fit_tail): auto then keeps
** the conical law, --law conical-tail reports that optimum. */
static cf_status choose_law(const cf_table *const *tables, size_t n,
                            const cf_pipeline_options *opt, cf_joint_report *r, int k,
                            cf_error *err)
{
    if (opt->progress) {
        char what[128];
        snprintf(what, sizeof what, "fitting the %s spring with a tail to %zu table%s jointly",
                 cf_spring_type_name(r->fits[k].fit.type), n, n == 1 ? "" : "s");
        opt->progress(opt->progress_ctx, NULL, what);
    }
    cf_joint_law_choice *lc = &r->law_choice[k];
    cf_joint_result tail;
    cf_error e = {0};
    cf_status st = cf_joint_fit_tail(tables, n, &opt->fit, &opt->lattice, &r->fits[k], &tail, &e);
    if (st == CF_E_INTERNAL || (st != CF_OK && opt->fit.law == CF_KIND_TAIL))
        return cf_error_set(err, st, "%s", e.msg);
    if (st != CF_OK)
        return CF_OK; /* auto: the conical law, the report saying no tail was fitted */
    lc->ran = 1;
    /* auto keeps a tail whose lattice loses stability inside a table's range only when the
    ** conical law's does too */
    lc->chose_tail = pick(&r->fits[k], &tail, opt->fit.law == CF_KIND_TAIL);
    if (lc->chose_tail) {
        lc->other = r->fits[k];
        r->fits[k] = tail;
    } else {
        lc->other = tail;
    }
    return CF_OK;
}

/* 1 when the pair a ranks above b: a buildable element first, then a lattice stable over every
** table's range, then (between two such, within CF_JOINT_ELLIPTIC_SLACK in objective) a cell
** strongly elliptic over every range, then the lower joint AIC. */
static int pair_ranks_above(const cf_joint_result *a, const cf_joint_result *b)
{
    if (cf_joint_stable_at_rest(a) != cf_joint_stable_at_rest(b))
        return cf_joint_stable_at_rest(a);
    if (a->fit.feasible != b->fit.feasible)
        return a->fit.feasible;
    if (cf_joint_stable(a) != cf_joint_stable(b))
        return cf_joint_stable(a);
    if (cf_joint_elliptic_wins(a, b) || cf_joint_elliptic_wins(b, a))
        return cf_joint_elliptic_wins(a, b);
    return a->aic < b->aic;
}

/* The pair with a tailed compression spring fitted from the pair *pair (conical compression
** spring; its optimum the tailed search's start and floor, cf_joint_fit_pair), and the better kept in *pair (pair_ranks_above), the other summarised in lc. A tailed
** pair that finds no lattice leaves *pair alone. */
static cf_status choose_pair_tail(const cf_table *const *tables, size_t n,
                                  const cf_pipeline_options *opt, cf_joint_law_choice *lc,
                                  cf_joint_result *pair, cf_error *err)
{
    if (opt->progress) {
        char what[160];
        snprintf(what, sizeof what, "fitting the %s double-acting element with a tailed "
                                    "compression spring to %zu table%s jointly",
                 cf_spring_type_name(pair->fit.type), n, n == 1 ? "" : "s");
        opt->progress(opt->progress_ctx, NULL, what);
    }
    cf_joint_result tp;
    cf_error e = {0};
    /* the tailed pair contains the conical pair: its optimum is the start, and the floor */
    cf_status st = cf_joint_fit_pair(tables, n, &opt->fit, &opt->lattice, pair->fit.type, 2,
                                     pair, &tp, &e);
    if (st == CF_E_INTERNAL)
        return cf_error_set(err, st, "%s", e.msg);
    if (st != CF_OK)
        return CF_OK;
    lc->pair_tail_ran = 1;
    lc->pair_tail_kept = pair_ranks_above(&tp, pair);
    const cf_joint_result *alt = lc->pair_tail_kept ? pair : &tp;
    lc->alt_aic = alt->aic;
    lc->alt_objective = alt->objective;
    lc->alt_feasible = alt->fit.feasible;
    lc->alt_stable = cf_joint_stable(alt);
    lc->alt_nparams = alt->nparams;
    if (lc->pair_tail_kept) {
        cf_joint_free(pair);
        *pair = tp;
    } else {
        cf_joint_free(&tp);
    }
    return CF_OK;
}

/* The double-acting element's joint fit beside the single-sided law in fits[k] (from the conical
** law's quantities plain), and the law kept: double-acting the pair, auto the pair only with a
** lower joint AIC, both springs buildable and a lattice stable over every table's range (unless
** the single-sided law's is not either). A pair that finds no lattice leaves auto's choice
** alone; double-acting then fails. */
static cf_status choose_pair(const cf_table *const *tables, size_t n,
                             const cf_pipeline_options *opt, const cf_joint_result *plain,
                             cf_joint_report *r, int k, cf_error *err)
{
    if (opt->progress) {
        char what[128];
        snprintf(what, sizeof what, "fitting the %s double-acting element to %zu table%s jointly",
                 cf_spring_type_name(r->fits[k].fit.type), n, n == 1 ? "" : "s");
        opt->progress(opt->progress_ctx, NULL, what);
    }
    cf_joint_law_choice *lc = &r->law_choice[k];
    cf_joint_result pair;
    cf_error e = {0};
    cf_status st = cf_joint_fit_pair(tables, n, &opt->fit, &opt->lattice, r->fits[k].fit.type, 1,
                                     plain, &pair, &e);
    if (st == CF_E_INTERNAL || (st != CF_OK && opt->fit.law == CF_KIND_DOUBLE))
        return cf_error_set(err, st, "%s", e.msg);
    if (st != CF_OK) { /* auto: the single-sided law, the report saying why */
        snprintf(lc->pair_refused, sizeof lc->pair_refused, "%s", e.msg);
        return CF_OK;
    }
    if ((st = choose_pair_tail(tables, n, opt, lc, &pair, err)) != CF_OK) {
        cf_joint_free(&pair);
        return st;
    }
    lc->pair_ran = 1;
    /* auto keeps a pair whose lattice loses stability inside a table's range only when the
    ** single-sided law's does too */
    lc->chose_pair = pick(&r->fits[k], &pair, opt->fit.law == CF_KIND_DOUBLE);
    if (lc->chose_pair) {
        lc->pair_other = r->fits[k];
        r->fits[k] = pair;
    } else {
        lc->pair_other = pair;
    }
    return CF_OK;
}

/* The single-sided law with the volume term (the conical law's fit plain its start) in place of
** plain in fits[k]. */
static cf_status with_volume(const cf_table *const *tables, size_t n,
                             const cf_pipeline_options *opt, cf_joint_report *r, int k,
                             cf_joint_result *plain, cf_error *err)
{
    *plain = r->fits[k];
    memset(&r->fits[k], 0, sizeof r->fits[k]);
    cf_status st = cf_joint_fit_pair(tables, n, &opt->fit, &opt->lattice, plain->fit.type, 0,
                                     plain, &r->fits[k], err);
    if (st != CF_OK) {
        r->fits[k] = *plain;
        memset(plain, 0, sizeof *plain);
        return st;
    }
    /* a volume term whose lattice is unstable at rest where kappa 0's is not came back as kappa
    ** 0 (cf_joint_fit_pair: the fit contains it and it ranks above) */
    return st;
}

/* The Holzapfel-Ogden baselines when a table is biaxial (jointreport.h): the transversely
** isotropic form, then the full one from it, with a biaxial table's second direction along s and
** along n. A set the law has no form for, or a fit that finds nothing, is said in r->ho_why. */
static void ho_baselines(const cf_table *const *tables, size_t n, cf_joint_report *r)
{
    int biaxial = 0;
    for (size_t k = 0; k < n; k++)
        biaxial |= tables[k]->mode == CF_MODE_BIAXIAL;
    if (!biaxial || cf_ho_unfit(tables, n, r->ho_why, sizeof r->ho_why))
        return;
    cf_error e = {0};
    for (int c = 0; c < 2; c++) {
        const char cross = c ? 'n' : 's';
        if (cf_ho_fit_joint(tables, n, CF_HO_TI, cross, NULL, &r->ho[CF_HO_TI][c], &e) != CF_OK ||
            cf_ho_fit_joint(tables, n, CF_HO_FULL, cross, &r->ho[CF_HO_TI][c],
                            &r->ho[CF_HO_FULL][c], &e) != CF_OK) {
            snprintf(r->ho_why, sizeof r->ho_why, "%s", e.msg);
            return;
        }
    }
    r->ho_ran = 1;
}

/* The fibre-reinforced lattice with opt->fibres' groups, second directions along s and along n;
** why not into r->fibre_why. */
static void fibre_fits(const cf_table *const *tables, size_t n, const char *groups,
                       cf_joint_report *r)
{
    snprintf(r->fibre_groups, sizeof r->fibre_groups, "%.*s", CF_FIBRE_MAX, groups);
    if (cf_ho_unfit(tables, n, r->fibre_why, sizeof r->fibre_why))
        return;
    cf_error e = {0};
    for (int c = 0; c < 2; c++) {
        const clock_t t0 = clock();
        if (cf_fibre_fit_joint(tables, n, groups, c ? 'n' : 's', &r->fibre[c], &e) != CF_OK) {
            snprintf(r->fibre_why, sizeof r->fibre_why, "%s", e.msg);
            return;
        }
        r->fibre_cpu_s[c] = r->with_timing ? (double)(clock() - t0) / CLOCKS_PER_SEC : 0;
    }
    r->fibre_ran = 1;
}

cf_status cf_pipeline_fit_joint(const cf_table *const *tables, size_t n,
                                const cf_pipeline_options *opt, cf_joint_report *r,
                                cf_error *err)
{
    CF_GSL_GUARD;
    memset(r, 0, sizeof *r);
    r->tables = tables;
    r->ntables = n;
    r->with_timing = opt->with_timing;
    r->law = opt->fit.law;
    for (int ty = CF_TELESCOPING; ty <= CF_NON_TELESCOPING; ty++) {
        if (!(opt->types & (1u << ty)))
            continue;
        if (opt->progress) {
            char what[128];
            snprintf(what, sizeof what, "fitting the %s spring to %zu table%s jointly",
                     cf_spring_type_name((cf_spring_type)ty), n, n == 1 ? "" : "s");
            opt->progress(opt->progress_ctx, NULL, what);
        }
        cf_status st = cf_joint_fit(tables, n, &opt->fit, &opt->lattice, (cf_spring_type)ty,
                                    &r->fits[r->nfits], err);
        if (st != CF_OK) {
            cf_joint_report_free(r);
            return st;
        }
        r->nfits++;
        const int k = r->nfits - 1;
        const cf_law_kind law = opt->fit.law;
        const int volume = opt->fit.volume != CF_VOLUME_NONE;
        cf_joint_result plain;
        memset(&plain, 0, sizeof plain);
        /* with a volume term the single-sided law is the conical law with it (no tailed law),
        ** also where the pair is asked for: the pair starts from it */
        if (volume)
            st = with_volume(tables, n, opt, r, k, &plain, err);
        else if (law == CF_KIND_TAIL || law == CF_KIND_AUTO)
            st = choose_law(tables, n, opt, r, k, err);
        /* a declared nu has no meaning for a pair's two sides: auto then keeps single-sided */
        if (st == CF_OK && (law == CF_KIND_DOUBLE ||
                            (law == CF_KIND_AUTO && opt->fit.volume != CF_VOLUME_POISSON))) {
            const cf_joint_law_choice *lc = &r->law_choice[k];
            /* the single-sided law with the same kappa treatment: the pair contains it */
            const cf_joint_result *start = !volume && lc->ran && lc->chose_tail ? &lc->other
                                                                                : &r->fits[k];
            st = choose_pair(tables, n, opt, start, r, k, err);
        }
        cf_joint_free(&plain);
        if (st != CF_OK) {
            cf_joint_report_free(r);
            return st;
        }
    }
    ho_baselines(tables, n, r);
    if (opt->fibres && opt->fibres[0])
        fibre_fits(tables, n, opt->fibres, r);
    return CF_OK;
}
