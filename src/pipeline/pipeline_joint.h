/*
** The joint fit as a library call beside cf_pipeline_fit (pipeline.h): one lattice for several
** tables, each in its own test mode.
**
**   cf_table x N --cf_joint_fit, each type--> cf_joint_result (joint.h)
**   = cf_joint_report (jointreport.h) --cf_joint_prepare--> fit file and figure
*/
#ifndef CF_PIPELINE_JOINT_H
#define CF_PIPELINE_JOINT_H

#include <stddef.h>

#include "conifit/error.h"
#include "report/jointreport.h"
#include "io/measure.h"
#include "pipeline/pipeline.h"

/* Fits one lattice (opt->lattice) to the n tables jointly with opt->fit, once for each spring
** type of opt->types, and fills r: r->tables = tables (which must outlive r), r->with_timing from
** opt, r->fits[0 .. r->nfits) the fits done. Before each type, opt->progress (when set) is called
** with table NULL and what says which type and how many tables. Stops at the first failure with
** its error (cf_joint_fit's); release each r->fits[k] with cf_joint_free in either case. */
cf_status cf_pipeline_fit_joint(const cf_table *const *tables, size_t n,
                                const cf_pipeline_options *opt, cf_joint_report *r,
                                cf_error *err);

#endif
