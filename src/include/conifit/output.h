/*
** Output handles: a file that appears whole or not at all.
**
** The calls that write a fit file (cf_tablefit_prepare, conifit/tablefit.h; and inside the
** library the pipeline's, the report's and the plot's) leave each output as a complete temporary
** file beside its target, held by a cf_output. The caller puts it in place with cf_output_commit
** once every output of its run is ready, or drops it with cf_output_abort; so a run with several
** outputs replaces all of them or none.
**
**   cf_output *json = NULL;
**   cf_output_new(&json, &err);
**   if (cf_tablefit_prepare(fit, "tissue.json", json, &err) == CF_OK)
**       cf_output_commit(json, &err);
**   cf_output_free(json);              (aborts what was not committed)
**
** A handle is empty when new, after a commit and after an abort; a prepare call refuses a handle
** that still holds an uncommitted file. Temporaries are named `.NAME.conifit-...` in the
** target's folder; a file that is not a regular file (link, FIFO, device, folder) is never
** replaced. One handle belongs to one thread at a time.
*/
#ifndef CF_OUTPUT_H
#define CF_OUTPUT_H

#include "conifit/error.h"

typedef struct cf_output cf_output;

/* A new, empty handle in *out (heap; release with cf_output_free). CF_E_USAGE when out is NULL,
** CF_E_INTERNAL when memory runs out (*out is then NULL). */
cf_status cf_output_new(cf_output **out, cf_error *err);

/* Puts the prepared file in place under its final name; the handle is empty afterwards.
** CF_E_USAGE when o is NULL or holds no file (never prepared, or already committed or aborted);
** CF_E_CANTWRITE when the file cannot be finished or renamed (the temporary is then removed). */
cf_status cf_output_commit(cf_output *o, cf_error *err);

/* Removes the prepared file, if any; the handle is empty afterwards. NULL is ignored. */
void cf_output_abort(cf_output *o);

/* The final name of the file the handle holds; "" when it holds none (or o is NULL). */
const char *cf_output_path(const cf_output *o);

/* Aborts what the handle still holds and releases it. NULL is ignored. */
void cf_output_free(cf_output *o);

#endif
