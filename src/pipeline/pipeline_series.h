/*
** The fitting pipeline for a time series (a table with a time column), as library calls beside
** cf_pipeline_fit (pipeline.h):
**
**   cf_table with t --cf_visco_fit_run---------> the viscoelastic fit (viscofit.h)
**                   --cf_fit_place, each type---> one design spring per type
**   = cf_visco_report (viscoreport.h) --cf_pipeline_series_prepare--> fit file and plot
*/
#ifndef CF_PIPELINE_SERIES_H
#define CF_PIPELINE_SERIES_H

#include "conifit/error.h"
#include "io/measure.h"
#include "conifit/output.h"
#include "pipeline/pipeline.h"
#include "fit/viscofit.h"
#include "report/viscoreport.h"

/* Fits the series t (t->t not NULL) with vo and places a spring of each type of opt->types from
** the fitted identifiable quantities (opt->fit: fixed parameters, index bound). Fills r (r->table
** = t, which must outlive r; release with cf_visco_report_free). Errors: those of
** cf_visco_fit_run, prefixed with the table's path; CF_E_DATA when no spring of the asked types
** can be placed. */
cf_status cf_pipeline_fit_series(const cf_table *t, const cf_pipeline_options *opt,
                                 const cf_visco_fit_options *vo, cf_visco_report *r,
                                 cf_error *err);

/* As cf_pipeline_prepare: the fit file and the plot (either path NULL: not written) as complete
** temporaries beside their targets, for the caller to commit or abort. */
cf_status cf_pipeline_series_prepare(const cf_visco_report *r, const char *json_path,
                                     const char *plot_path, const char *const *inputs,
                                     cf_output *json_out, cf_output *plot_out,
                                     cf_error *err);

#endif
