/* The public output handle (conifit/output.h) over the atomic writer (base/atomic.h). */
#include "conifit/output.h"

#include <libgen.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

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

int cf_same_target(const char *a, const char *b)
{
    if (strcmp(a, b) == 0)
        return 1;
    struct stat sa, sb;
    int ea = stat(a, &sa) == 0, eb = stat(b, &sb) == 0;
    if (ea || eb)
        return ea && eb && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    char ca[PATH_MAX], cb[PATH_MAX], ra[PATH_MAX], rb[PATH_MAX];
    if (strlen(a) >= sizeof ca || strlen(b) >= sizeof cb)
        return 0;
    strcpy(ca, a);
    strcpy(cb, b);
    if (strcmp(basename(ca), basename(cb)) != 0)
        return 0;
    strcpy(ca, a);
    strcpy(cb, b);
    return realpath(dirname(ca), ra) && realpath(dirname(cb), rb) && strcmp(ra, rb) == 0;
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
    /* one handle or one file for both: the second output would replace the first */
    if (path1 && path2 && out1 == out2)
        return cf_error_set(err, CF_E_USAGE,
                            "%s: one output handle given for both files (%s and %s): give each "
                            "its own",
                            call, path1, path2);
    if (path1 && path2 && cf_same_target(path1, path2))
        return cf_error_set(err, CF_E_USAGE, "%s: both outputs name one file (%s and %s)", call,
                            path1, path2);
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
