/* The public output handle (conifit/output.h) over the atomic writer (base/atomic.h). */
#include "conifit/output.h"

#include <stdlib.h>

#include "base/atomic.h"

static int holds_file(const cf_atomic *a)
{
    return a->fp || a->tmp[0];
}

cf_status cf_output_new(cf_output **out, cf_error *err)
{
    if (!out)
        return cf_error_set(err, CF_E_USAGE, "cf_output_new: no place for the handle (NULL)");
    *out = calloc(1, sizeof **out);
    return *out ? CF_OK : cf_error_set(err, CF_E_INTERNAL, "cf_output_new: out of memory");
}

cf_status cf_output_commit(cf_output *o, cf_error *err)
{
    if (!o)
        return cf_error_set(err, CF_E_USAGE, "cf_output_commit: no output handle (NULL)");
    if (!holds_file(o))
        return cf_error_set(err, CF_E_USAGE,
                            "cf_output_commit: the handle holds no file (not prepared, or "
                            "already committed or aborted)");
    return cf_atomic_commit(o, err);
}

void cf_output_abort(cf_output *o)
{
    cf_atomic_abort(o);
}

const char *cf_output_path(const cf_output *o)
{
    return o && holds_file(o) ? o->path : "";
}

void cf_output_free(cf_output *o)
{
    cf_atomic_abort(o);
    free(o);
}

static cf_status check_one(const char *call, const char *path, const cf_atomic *out,
                           cf_error *err)
{
    if (path && !out)
        return cf_error_set(err, CF_E_USAGE, "%s: no output handle for a file to write (NULL)",
                            call);
    if (out && holds_file(out))
        return cf_error_set(err, CF_E_USAGE,
                            "%s: the output handle still holds an uncommitted file; commit or "
                            "abort it first",
                            call);
    return CF_OK;
}

cf_status cf_atomic_begin(const char *call, const void *r, const char *path1, cf_atomic *out1,
                          const char *path2, cf_atomic *out2, cf_error *err)
{
    if (!r)
        return cf_error_set(err, CF_E_USAGE, "%s: no report (NULL)", call);
    cf_status st = check_one(call, path1, out1, err);
    if (st == CF_OK)
        st = check_one(call, path2, out2, err);
    if (st != CF_OK)
        return st;
    if (out1)
        *out1 = (cf_atomic){0};
    if (out2)
        *out2 = (cf_atomic){0};
    return CF_OK;
}

cf_status cf_atomic_begin_one(const char *call, const void *r, const char *path, cf_atomic *out,
                              cf_error *err)
{
    if (!path)
        return cf_error_set(err, CF_E_USAGE, "%s: no path for the file (NULL)", call);
    return cf_atomic_begin(call, r, path, out, NULL, NULL, err);
}
