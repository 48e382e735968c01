/*
** Libraries opened at run time (see dynlib.h).
*/
#include "base/dynlib.h"

#include <dlfcn.h>
#include <stdio.h>

void *cf_dynlib_open(const char *what, const char *const names[], cf_error *err)
{
    char why[CF_ERROR_MSG_LEN / 2] = "not found"; /* the first name's reason: the rest are fallbacks */
    for (size_t k = 0; names[k]; k++) {
        void *h = dlopen(names[k], RTLD_NOW | RTLD_LOCAL);
        if (h)
            return h;
        const char *e = dlerror();
        if (k == 0 && e)
            snprintf(why, sizeof why, "%s", e);
    }
    cf_error_set(err, CF_E_INTERNAL, "cannot load the library of %s (%s): %s", what,
                 names[0] ? names[0] : "no name", why);
    return NULL;
}

void *cf_dynlib_sym(void *h, const char *lib, const char *sym, cf_error *err)
{
    void *p = dlsym(h, sym);
    if (!p)
        cf_error_set(err, CF_E_INTERNAL, "the library %s has no function %s", lib, sym);
    return p;
}

void cf_dynlib_close(void *h)
{
    if (h)
        dlclose(h);
}
