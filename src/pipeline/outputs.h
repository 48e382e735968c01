/*
** What the pipelines of a table and of a time series share in writing their outputs (private to
** src/pipeline/): a fit file and a plot prepared as temporaries beside their targets, both
** dropped when either fails.
*/
#ifndef CF_PIPELINE_OUTPUTS_H
#define CF_PIPELINE_OUTPUTS_H

#include "base/atomic.h"
#include "conifit/error.h"

/* Ends the preparation of the two outputs: st is the status so far (the fit file prepared, the
** plot drawn into plot_out when plot_path is not NULL). On CF_OK closes the plot's temporary
** (cf_atomic_finish); on any failure aborts both. Returns the final status. */
cf_status cf_pipeline_outputs_end(cf_status st, const char *plot_path, cf_atomic *json_out,
                                  cf_atomic *plot_out, cf_error *err);

#endif
