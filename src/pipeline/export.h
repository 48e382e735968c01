/*
** An export rendered whole in memory as one library call (export.c): the spring's table in the
** chosen format, or the lattice built from it as a runnable model, so that a failure never
** leaves partial output. Used by `conifit export` and by the flat call cf_flat_export alike.
*/
#ifndef CF_PIPELINE_EXPORT_H
#define CF_PIPELINE_EXPORT_H

#include <stddef.h>

#include "export/export.h"
#include "io/fitfile.h"

/* Renders fitted spring fs as opt says into *buf (*len bytes; the caller frees *buf, NULL on
** failure): the spring's table, or with lx the lattice lx describes as a model. *rep (may be
** NULL) receives the rows, the achieved error and the lattice's size. */
cf_status cf_pipeline_export(const cf_fitted_spring *fs, const cf_export_options *opt,
                             const cf_export_lattice *lx, cf_export_report *rep, char **buf,
                             size_t *len, cf_error *err);

#endif
