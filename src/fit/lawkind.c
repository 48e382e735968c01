/*
** The law kinds' table (lawkind.h): the rows of the conical law, the conical law with a tail and
** the double-acting pair, and the lookups the report and the fit file read.
*/
#include "fit/lawkind.h"

#include <math.h>
#include <string.h>

#include "fit/tail.h"

/* The cone's three quantities, which every conical kind starts with (family.h). */
#define CONE_QUANTITIES                                                                       \
    {"rho", "rho", "rho = D1/D2", "rho = D1/D2", "rho", "rho", "", "", NULL},                 \
        {"solid_strain", "travel_mm", "solid strain s/H", "travel s", "solid strain", "travel", \
         "", "mm", NULL},                                                                     \
        {"stress_scale_MPa", "F_C_N", "stress scale F_C/H^2", "solid load F_C", "stress scale", \
         "solid load", "y", "N", NULL}

/* The tailed law contains the conical law (tail compliance 0): its fitter returns that optimum
** where its own search ends worse (cf_fit_tail_run). Through the lattice the same nesting is
** done here: a search that fails or ends worse than the conical fit through the lattice gives
** that fit with no tail, and the conical fit's lattice record. */
static cf_status tail_fit_lattice(const cf_table *t, const cf_fit_options *opt,
                                  const cf_validate_setup *s, const cf_fit_result *plain,
                                  const cf_through_msm *plain_thr, cf_fit_result *res,
                                  cf_through_msm *thr, cf_error *err)
{
    cf_error e = {0};
    cf_status st = cf_lattice_fit_tail(t, opt, s, plain, res, thr, &e);
    if (st == CF_E_INTERNAL)
        return cf_error_set(err, st, "%s", e.msg);
    if (st != CF_OK) {
        memset(res, 0, sizeof *res);
        res->objective = INFINITY; /* none found: nested_rmse 0 */
    }
    if (cf_tail_nest(plain, res)) {
        *thr = *plain_thr;
        st = CF_OK;
    }
    if (st != CF_OK)
        return cf_error_set(err, st, "%s", e.msg);
    return CF_OK;
}

const cf_law_row cf_law_conical_row = {
    .name = "conical",
    .title = "conical law",
    .spring = "the conical spring",
    .nq = 3,
    .cone = 1,
    .q = {CONE_QUANTITIES},
};

const cf_law_row cf_law_tail_row = {
    .name = "conical-tail",
    .title = "conical spring with a cylindrical tail",
    .adds = "the tail",
    .spring = "the tailed spring",
    .nq = 4,
    .cone = 1,
    .ncorr = 3,
    .q = {CONE_QUANTITIES,
          {"tail_compliance", "tail_compliance_mm", "tail compliance e_t",
           "tail compliance F_C/k_t", "tail compliance", "tail compliance", "", "mm",
           "0 (none: conical)"}},
    .fit = cf_fit_tail_run,
    .fit_lattice = tail_fit_lattice,
};

const cf_law_row cf_law_double_row = {
    .name = "double-acting",
    .title = "double-acting pair",
    .adds = "the extension spring",
    .spring = "the pair",
    .nq = 6,
    .cone = 1,
    .ncorr = 3,
    .q = {CONE_QUANTITIES,
          {"extension_rho", "extension_rho", "extension rho", "extension rho",
           "extension rho", "extension rho", "", "", NULL},
          {"extension_solid_strain", "extension_travel_mm", "extension solid strain",
           "extension travel", "extension solid strain", "extension travel", "", "mm", NULL},
          {"extension_stress_scale_MPa", "extension_F_C_N", "extension stress scale",
           "extension solid load", "extension stress scale", "extension solid load", "y", "N",
           NULL}},
};

const cf_law_row *cf_law_row_of(cf_law_kind kind)
{
    switch (kind) {
    case CF_KIND_CONICAL: return &cf_law_conical_row;
    case CF_KIND_TAIL: return &cf_law_tail_row;
    case CF_KIND_DOUBLE: return &cf_law_double_row;
    case CF_KIND_AUTO: break;
    }
    return NULL;
}

cf_status cf_law_kind_parse(const char *name, cf_law_kind *f, cf_error *err)
{
    static const cf_law_kind kinds[] = {CF_KIND_CONICAL, CF_KIND_TAIL, CF_KIND_AUTO,
                                        CF_KIND_DOUBLE};
    for (size_t i = 0; i < sizeof kinds / sizeof kinds[0]; i++)
        if (name && strcmp(name, cf_law_kind_name(kinds[i])) == 0) {
            *f = kinds[i];
            return CF_OK;
        }
    return cf_error_set(err, CF_E_DATA,
                        "unknown law '%s' (expected conical, conical-tail, auto or "
                        "double-acting)",
                        name ? name : "(null)");
}

const char *cf_law_kind_name(cf_law_kind f)
{
    const cf_law_row *row = cf_law_row_of(f);
    return row ? row->name : f == CF_KIND_AUTO ? "auto" : "?";
}

const char *cf_law_q_key(const cf_law_row *row, int k, const cf_table *t)
{
    return cf_table_is_force(t) ? row->q[k].key_force : row->q[k].key;
}

const char *cf_law_q_label(const cf_law_row *row, int k, const cf_table *t)
{
    return cf_table_is_force(t) ? row->q[k].label_force : row->q[k].label;
}

const char *cf_law_q_name(const cf_law_row *row, int k, const cf_table *t)
{
    return cf_table_is_force(t) ? row->q[k].name_force : row->q[k].name;
}

const char *cf_law_q_unit(const cf_law_row *row, int k, const cf_table *t)
{
    return cf_table_is_force(t) ? row->q[k].unit_force : row->q[k].unit;
}

const cf_law_row *cf_fit_kind_of(const cf_fit_result *f)
{
    return f->kind ? f->kind : f->tail ? &cf_law_tail_row : &cf_law_conical_row;
}

cf_ident cf_fit_family(const cf_fit_result *f, int force_displacement)
{
    const cf_law_row *row = cf_fit_kind_of(f);
    if (row->cone)
        return f->ident;
    return cf_ident_of_type(&f->params, f->type, force_displacement);
}

int cf_law_pick(const cf_law_standing *s, int n, int asked)
{
    if (asked >= 0 && asked < n)
        return asked;
    int kept = 0;
    for (int j = 1; j < n; j++)
        if (s[j].feasible && s[j].aic < s[kept].aic && (s[j].stable || !s[kept].stable))
            kept = j;
    return kept;
}
