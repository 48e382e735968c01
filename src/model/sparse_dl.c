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

/* Binds f of the library h (named lib) into lib_struct.f; on a missing one, returns NULL from the
** enclosing function, the lock released. */
#define CF_SPARSE_DL_BIND(f)                                                                       \
    if (!(*(void **)(&fns.f) = cf_dynlib_sym(h, names[0], #f, err))) {                            \
        cf_dynlib_close(h);                                                                        \
        pthread_mutex_unlock(&dl_lock);                                                            \
        return NULL;                                                                               \
    }

const cf_cholmod_lib *cf_cholmod_lib_get(cf_error *err)
{
    pthread_mutex_lock(&dl_lock);
    if (!cholmod_loaded) {
        const char *names[] = {cholmod_name ? cholmod_name : CF_CHOLMOD_SONAME,
                               cholmod_name ? NULL : "libcholmod.so", NULL};
        void *h = cf_dynlib_open("CHOLMOD, the sparse Cholesky factorisation", names, err);
        cf_cholmod_lib fns;
        if (!h) {
            pthread_mutex_unlock(&dl_lock);
            return NULL;
        }
        CF_CHOLMOD_FUNCTIONS(CF_SPARSE_DL_BIND)
        cholmod = fns;
        cholmod_loaded = 1;
    }
    pthread_mutex_unlock(&dl_lock);
    return &cholmod;
}

const cf_mumps_lib *cf_mumps_lib_get(cf_error *err)
{
    pthread_mutex_lock(&dl_lock);
    if (!mumps_loaded) {
        const char *names[] = {mumps_name ? mumps_name : CF_MUMPS_SONAME,
                               mumps_name ? NULL : "libdmumps_seq.so", NULL};
        void *h = cf_dynlib_open("MUMPS, the indefinite (L D L^T) factorisation", names, err);
        cf_mumps_lib fns;
        if (!h) {
            pthread_mutex_unlock(&dl_lock);
            return NULL;
        }
        CF_MUMPS_FUNCTIONS(CF_SPARSE_DL_BIND)
        mumps = fns;
        mumps_loaded = 1;
    }
    pthread_mutex_unlock(&dl_lock);
    return &mumps;
}
