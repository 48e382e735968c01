/*
** The table-fit handle (conifit/tablefit.h): the table, the pipeline's report on it and the
** table's path, behind accessors; the fit itself is cf_pipeline_fit's, the fit file
** cf_pipeline_prepare's, so a program gets what conifit fit writes.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/gslguard.h"
#include "conifit/tablefit.h"
#include "fit/joint.h"
#include "fit/lawkind.h"
#include "io/measure.h"
#include "pipeline/pipeline.h"
#include "report/report.h"

struct cf_tablefit {
    cf_table table;    /* the report points at it: the handle never moves */
    cf_fit_report rep;
    char *path;        /* the table's path, refused as a target of the fit file */
};

cf_tablefit_options cf_tablefit_default_options(void)
{
    return (cf_tablefit_options){.types = CF_TABLEFIT_BOTH, .law = NULL, .validate = 0,
                                 .with_timing = 0};
}

cf_status cf_tablefit_run(const char *table_path, const cf_tablefit_options *opt,
                          cf_tablefit **out, cf_error *err)
{
    CF_GSL_GUARD;
    if (!out)
        return cf_error_set(err, CF_E_USAGE, "the handle pointer is NULL");
    *out = NULL;
    if (!table_path)
        return cf_error_set(err, CF_E_USAGE, "the table path is NULL");
    cf_tablefit_options o = opt ? *opt : cf_tablefit_default_options();
    if (o.types == 0 || (o.types & ~(unsigned)CF_TABLEFIT_BOTH))
        return cf_error_set(err, CF_E_USAGE,
                            "types = %#x: give CF_TABLEFIT_TELESCOPING, "
                            "CF_TABLEFIT_NON_TELESCOPING or both",
                            o.types);
    cf_pipeline_options po = cf_pipeline_default_options();
    po.types = o.types;
    po.validate = o.validate != 0;
    po.with_timing = o.with_timing != 0;
    cf_status s;
    if (o.law) {
        cf_error e = {0};
        if (cf_law_kind_parse(o.law, &po.fit.law, &e) != CF_OK)
            return cf_error_set(err, CF_E_USAGE, "%s", e.msg);
    }
    cf_tablefit *f = calloc(1, sizeof *f);
    if (!f || !(f->path = strdup(table_path))) {
        free(f);
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the fit handle");
    }
    cf_measure_options mo = cf_measure_default_options();
    if ((s = cf_measure_load(table_path, &mo, &f->table, err)) != CF_OK) {
        free(f->path);
        free(f);
        return s;
    }
    const cf_table *one = &f->table;
    if (f->table.t) {
        s = cf_error_set(err, CF_E_DATA, "%s is a time series: fit it with conifit fit",
                         table_path);
    } else if (po.fit.law == CF_KIND_DOUBLE) {
        /* conifit fit --law double-acting fits the element through the lattice (a joint fit of
        ** its tables); a table that cannot determine both springs is refused as it refuses it,
        ** one that can is the joint fit's, which this handle does not hold */
        s = cf_joint_pair_determined(&one, 1, err);
        if (s == CF_OK)
            s = cf_error_set(err, CF_E_USAGE,
                             "%s: law 'double-acting' is fitted through the lattice as one "
                             "element (conifit fit --law double-acting); this call fits one "
                             "spring per type: give law \"conical\", \"conical-tail\" or "
                             "\"auto\"",
                             table_path);
    } else {
        s = cf_pipeline_fit(&f->table, &po, &f->rep, err);
    }
    if (s != CF_OK) {
        cf_table_free(&f->table);
        free(f->path);
        free(f);
        return s;
    }
    *out = f;
    return CF_OK;
}

static const cf_fit_result *fit_at(const cf_tablefit *f, int i)
{
    return f && i >= 0 && i < f->rep.nfits ? &f->rep.fits[i] : NULL;
}

int cf_tablefit_count(const cf_tablefit *f)
{
    return f ? f->rep.nfits : 0;
}

int cf_tablefit_better(const cf_tablefit *f)
{
    return f ? cf_report_better(&f->rep) : -1;
}

cf_spring_type cf_tablefit_type(const cf_tablefit *f, int i)
{
    const cf_fit_result *r = fit_at(f, i);
    return r ? r->type : CF_SPRING_TYPE_NONE;
}

const cf_spring *cf_tablefit_spring(const cf_tablefit *f, int i)
{
    const cf_fit_result *r = fit_at(f, i);
    return r ? &r->params : NULL;
}

const char *cf_tablefit_law(const cf_tablefit *f, int i)
{
    const cf_fit_result *r = fit_at(f, i);
    return r ? cf_fit_kind_of(r)->name : NULL;
}

double cf_tablefit_rmse(const cf_tablefit *f, int i)
{
    const cf_fit_result *r = fit_at(f, i);
    return r ? r->rmse * f->table.y_to_file : NAN;
}

const char *cf_tablefit_y_unit(const cf_tablefit *f)
{
    return f ? f->table.y_unit : "";
}

int cf_tablefit_quantity_count(const cf_tablefit *f, int i)
{
    const cf_fit_result *r = fit_at(f, i);
    return r ? cf_fit_kind_of(r)->nq : 0;
}

const char *cf_tablefit_quantity_key(const cf_tablefit *f, int i, int k)
{
    const cf_fit_result *r = fit_at(f, i);
    if (!r || k < 0 || k >= cf_fit_kind_of(r)->nq)
        return NULL;
    return cf_law_q_key(cf_fit_kind_of(r), k, &f->table);
}

/* The index of the quantity of fit i called key, or -1. */
static int quantity_index(const cf_tablefit *f, int i, const char *key)
{
    const cf_fit_result *r = fit_at(f, i);
    if (!r || !key)
        return -1;
    const cf_law_row *row = cf_fit_kind_of(r);
    for (int k = 0; k < row->nq; k++)
        if (strcmp(cf_law_q_key(row, k, &f->table), key) == 0)
            return k;
    return -1;
}

const char *cf_tablefit_quantity_unit(const cf_tablefit *f, int i, const char *key)
{
    int k = quantity_index(f, i, key);
    if (k < 0)
        return NULL;
    const char *u = cf_law_q_unit(cf_fit_kind_of(&f->rep.fits[i]), k, &f->table);
    /* "y": the table's stress or force, which the fit holds in MPa or N */
    return strcmp(u, "y") == 0 ? (cf_table_is_force(&f->table) ? "N" : "MPa") : u;
}

double cf_tablefit_quantity(const cf_tablefit *f, int i, const char *key, double *se)
{
    int k = quantity_index(f, i, key);
    if (se)
        *se = k < 0 ? -1 : f->rep.fits[i].q_se[k];
    return k < 0 ? NAN : f->rep.fits[i].q[k];
}

cf_status cf_tablefit_prepare(const cf_tablefit *f, const char *path, cf_output *out,
                              cf_error *err)
{
    CF_GSL_GUARD;
    if (!f || !path || !out)
        return cf_error_set(err, CF_E_USAGE, "%s is NULL",
                            !f ? "the fit handle" : !path ? "the fit file's path" : "the output");
    const char *inputs[] = {f->path, NULL};
    return cf_pipeline_prepare(&f->rep, path, NULL, inputs, out, NULL, err);
}

void cf_tablefit_free(cf_tablefit *f)
{
    if (!f)
        return;
    cf_report_free(&f->rep);
    cf_table_free(&f->table);
    free(f->path);
    free(f);
}
