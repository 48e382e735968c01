/*
** CHOLMOD and MUMPS opened at their first use (see sparse_dl.h).
*/
#include "model/sparse_dl.h"

#include "base/dynlib.h"

#include <pthread.h>
#include <stddef.h>

/* The SONAMEs of the libraries the build found (the Makefile reads them from the libraries the
** linker would take); otherwise CHOLMOD's by its major version, MUMPS's unversioned name. */
#define CF_STR2(x) #x
#define CF_STR(x) CF_STR2(x)
#ifndef CF_CHOLMOD_SONAME
#define CF_CHOLMOD_SONAME "libcholmod.so." CF_STR(CHOLMOD_MAIN_VERSION)
#endif
#ifndef CF_MUMPS_SONAME
#define CF_MUMPS_SONAME "libdmumps_seq.so"
#endif

static pthread_mutex_t dl_lock = PTHREAD_MUTEX_INITIALIZER;
static const char *cholmod_name, *mumps_name; /* the tests' names, NULL for the defaults */
static cf_cholmod_lib cholmod;
static cf_mumps_lib mumps;
static int cholmod_loaded, mumps_loaded;

void cf_sparse_dl_names(const char *cholmod_file, const char *mumps_file)
{
    pthread_mutex_lock(&dl_lock);
    cholmod_name = cholmod_file;
    mumps_name = mumps_file;
    pthread_mutex_unlock(&dl_lock);
}

/* Binds f of the library h (file lib) into fns.f; 0 from the enclosing function when it lacks f. */
#define CF_SPARSE_DL_BIND(f)                                                                       \
    if (!(*(void **)(&fns.f) = cf_dynlib_sym(h, lib, #f, err)))                                    \
        return 0;

static int bind_cholmod(void *h, const char *lib, cf_error *err)
{
    cf_cholmod_lib fns;
    CF_CHOLMOD_FUNCTIONS(CF_SPARSE_DL_BIND)
    cholmod = fns;
    return 1;
}

static int bind_mumps(void *h, const char *lib, cf_error *err)
{
    cf_mumps_lib fns;
    CF_MUMPS_FUNCTIONS(CF_SPARSE_DL_BIND)
    mumps = fns;
    return 1;
}

/* Opens a library once, under the lock: the tests' name (*chosen) or the build's SONAME, then the
** unversioned name; bind takes its functions. 1 when it is loaded. */
static int load(int *loaded, const char *what, const char *const *chosen, const char *soname,
                const char *plain, int (*bind)(void *, const char *, cf_error *), cf_error *err)
{
    pthread_mutex_lock(&dl_lock);
    if (!*loaded) {
        const char *names[] = {*chosen ? *chosen : soname, *chosen ? NULL : plain, NULL};
        void *h = cf_dynlib_open(what, names, err);
        if (h && bind(h, names[0], err))
            *loaded = 1;
        else
            cf_dynlib_close(h);
    }
    const int ok = *loaded;
    pthread_mutex_unlock(&dl_lock);
    return ok;
}

const cf_cholmod_lib *cf_cholmod_lib_get(cf_error *err)
{
    return load(&cholmod_loaded, "CHOLMOD, the sparse Cholesky factorisation", &cholmod_name,
                CF_CHOLMOD_SONAME, "libcholmod.so", bind_cholmod, err)
               ? &cholmod
               : NULL;
}

const cf_mumps_lib *cf_mumps_lib_get(cf_error *err)
{
    return load(&mumps_loaded, "MUMPS, the indefinite (L D L^T) factorisation", &mumps_name,
                CF_MUMPS_SONAME, "libdmumps_seq.so", bind_mumps, err)
               ? &mumps
               : NULL;
}
