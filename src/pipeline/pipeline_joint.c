/*
** The joint fit (see pipeline_joint.h).
*/
#include "conifit/pipeline_joint.h"

#include <stdio.h>
#include <string.h>

#include "conifit/joint.h"

cf_status cf_pipeline_fit_joint(const cf_table *const *tables, size_t n,
                                const cf_pipeline_options *opt, cf_joint_report *r,
                                cf_error *err)
{
    memset(r, 0, sizeof *r);
    r->tables = tables;
    r->ntables = n;
    r->with_timing = opt->with_timing;
    for (int ty = CF_TELESCOPING; ty <= CF_NON_TELESCOPING; ty++) {
        if (!(opt->types & (1u << ty)))
            continue;
        if (opt->progress) {
            char what[128];
            snprintf(what, sizeof what, "fitting the %s spring to %zu tables jointly",
                     cf_spring_type_name((cf_spring_type)ty), n);
            opt->progress(opt->progress_ctx, NULL, what);
        }
        cf_status st = cf_joint_fit(tables, n, &opt->fit, &opt->lattice, (cf_spring_type)ty,
                                    &r->fits[r->nfits], err);
        if (st != CF_OK)
            return st;
        r->nfits++;
    }
    return CF_OK;
}
