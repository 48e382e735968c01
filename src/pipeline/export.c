/*
** An export rendered whole in memory (export.h).
*/
#include "pipeline/export.h"

#include <stdio.h>
#include <stdlib.h>

cf_status cf_pipeline_export(const cf_fitted_spring *fs, const cf_export_options *opt,
                             const cf_export_lattice *lx, cf_export_report *rep, char **buf,
                             size_t *len, cf_error *err)
{
    cf_export_report own;
    if (!rep)
        rep = &own;
    *buf = NULL;
    *len = 0;
    FILE *mem = open_memstream(buf, len);
    if (!mem)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory");
    cf_status st = lx ? cf_export_write_lattice(mem, fs, opt, lx, rep, err)
                      : cf_export_write(mem, fs, opt, rep, err);
    if (fclose(mem) != 0 && st == CF_OK)
        st = cf_error_set(err, CF_E_INTERNAL, "out of memory");
    if (st != CF_OK) {
        free(*buf);
        *buf = NULL;
        *len = 0;
    }
    return st;
}
