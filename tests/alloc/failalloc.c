/*
** An allocation-failure injector for tests/props/test_alloc_failure.c, loaded with LD_PRELOAD into the
** conifit program: it counts the allocations made from inside GSL and NLopt (the caller's code
** lies in libgsl* or libnlopt*) and makes the one numbered CF_FAIL_ALLOC_AT fail (malloc, calloc
** and realloc return NULL), as a full memory would. With CF_FAIL_ALLOC_REPORT=FILE it writes the
** number of such allocations to FILE at exit. Every other allocation passes through.
**
** CF_FAIL_ALLOC_WITHIN=START:SIZE (hexadecimal offsets of a function in the program, as `nm -S`
** prints them) counts instead every allocation, whoever makes it (the program, GSL, NLopt), made
** while that function is on the stack: the allocations of one loop and of what it calls.
*/
#define _GNU_SOURCE
#include <dlfcn.h>
#include <execinfo.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void *(*real_malloc)(size_t);
static void *(*real_calloc)(size_t, size_t);
static void *(*real_realloc)(void *, size_t);
static void (*real_free)(void *);
static long fail_at = -1, counted;
static uintptr_t within_lo, within_hi; /* CF_FAIL_ALLOC_WITHIN, offsets in the program */
static int within_set, in_backtrace;
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
    const char *w = getenv("CF_FAIL_ALLOC_WITHIN");
    char *colon = NULL;
    if (w) {
        within_lo = (uintptr_t)strtoull(w, &colon, 16);
        if (colon && *colon == ':') {
            within_hi = within_lo + (uintptr_t)strtoull(colon + 1, NULL, 16);
            within_set = within_hi > within_lo;
        }
    }
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

/* 1 when the function of CF_FAIL_ALLOC_WITHIN is on the stack. */
static int inside_within(void)
{
    if (in_backtrace) /* backtrace itself may allocate the first time */
        return 0;
    in_backtrace = 1;
    void *frames[64];
    int n = backtrace(frames, 64), hit = 0;
    for (int i = 0; i < n && !hit; i++) {
        Dl_info info;
        if (!dladdr(frames[i], &info) || !info.dli_fname || strstr(info.dli_fname, ".so"))
            continue;
        uintptr_t off = (uintptr_t)frames[i] - (uintptr_t)info.dli_fbase;
        hit = off >= within_lo && off < within_hi;
    }
    in_backtrace = 0;
    return hit;
}

/* 1 when this allocation, made from code at ret, is the one to fail. */
static int fails(void *ret)
{
    Dl_info info;
    if (!ready)
        return 0;
    if (within_set)
        return inside_within() && ++counted == fail_at;
    if (!dladdr(ret, &info) || !info.dli_fname)
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
