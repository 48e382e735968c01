/*
** An allocation-failure injector for tests/test_alloc_failure.c, loaded with LD_PRELOAD into the
** conifit program: it counts the allocations made from inside GSL and NLopt (the caller's code
** lies in libgsl* or libnlopt*) and makes the one numbered CF_FAIL_ALLOC_AT fail (malloc, calloc
** and realloc return NULL), as a full memory would. With CF_FAIL_ALLOC_REPORT=FILE it writes the
** number of such allocations to FILE at exit. Every other allocation passes through.
*/
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void *(*real_malloc)(size_t);
static void *(*real_calloc)(size_t, size_t);
static void *(*real_realloc)(void *, size_t);
static void (*real_free)(void *);
static long fail_at = -1, counted;
static int ready, starting;
/* dlsym itself may allocate before the real functions are known: served from here */
static _Alignas(16) char boot[8192];
static size_t boot_used;

static void start(void)
{
    if (ready || starting)
        return;
    starting = 1;
    real_malloc = (void *(*)(size_t))dlsym(RTLD_NEXT, "malloc");
    real_calloc = (void *(*)(size_t, size_t))dlsym(RTLD_NEXT, "calloc");
    real_realloc = (void *(*)(void *, size_t))dlsym(RTLD_NEXT, "realloc");
    real_free = (void (*)(void *))dlsym(RTLD_NEXT, "free");
    const char *s = getenv("CF_FAIL_ALLOC_AT");
    fail_at = s ? atol(s) : -1;
    starting = 0;
    ready = 1;
}

static void *from_boot(size_t n)
{
    n = (n + 15) & ~(size_t)15;
    if (boot_used + n > sizeof boot)
        return NULL;
    void *p = boot + boot_used;
    boot_used += n;
    return p;
}

static int in_boot(const void *p)
{
    return (const char *)p >= boot && (const char *)p < boot + sizeof boot;
}

/* 1 when this allocation, made from code at ret, is the one to fail. */
static int fails(void *ret)
{
    Dl_info info;
    if (!ready || !dladdr(ret, &info) || !info.dli_fname)
        return 0;
    if (!strstr(info.dli_fname, "libgsl") && !strstr(info.dli_fname, "libnlopt"))
        return 0;
    return ++counted == fail_at;
}

void *malloc(size_t n)
{
    start();
    if (!real_malloc)
        return from_boot(n);
    return fails(__builtin_return_address(0)) ? NULL : real_malloc(n);
}

void *calloc(size_t k, size_t n)
{
    start();
    if (!real_calloc) {
        void *p = from_boot(k * n);
        if (p)
            memset(p, 0, k * n);
        return p;
    }
    return fails(__builtin_return_address(0)) ? NULL : real_calloc(k, n);
}

void *realloc(void *p, size_t n)
{
    start();
    if (in_boot(p)) {
        void *q = malloc(n);
        if (q)
            memcpy(q, p, n); /* boot blocks are never larger than asked for later */
        return q;
    }
    return fails(__builtin_return_address(0)) ? NULL : real_realloc(p, n);
}

void free(void *p)
{
    if (!p || in_boot(p))
        return;
    start();
    if (real_free)
        real_free(p);
}

__attribute__((destructor)) static void report(void)
{
    const char *path = getenv("CF_FAIL_ALLOC_REPORT");
    if (!path)
        return;
    FILE *f = fopen(path, "w");
    if (f) {
        fprintf(f, "%ld\n", counted);
        fclose(f);
    }
}
