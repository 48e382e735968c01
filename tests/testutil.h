/*
** Helpers shared by the cmocka tests: running the conifit binary, temporary folders, and the
** location of the published measurement tables (read from ../shared/datasets when present).
*/
#ifndef CF_TESTUTIL_H
#define CF_TESTUTIL_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>
#include <math.h>

/* Fails unless |a - b| <= tol, printing both values to 17 digits (cmocka 1.1.5 has no double
** comparison of its own). */
/* 1 in the AddressSanitizer build (make sanitize). A long fit of published tables whose code the
** suite's smaller cases already run there may skip itself under it, saying so (TU_SKIP_SANITIZED);
** make test asserts its numbers. */
#if defined(__SANITIZE_ADDRESS__)
#define TU_SANITIZED 1
#else
#define TU_SANITIZED 0
#endif
#define TU_SKIP_SANITIZED(what)                                                                    \
    do {                                                                                           \
        if (TU_SANITIZED) {                                                                        \
            print_message("%s: asserted by make test, skipped under the sanitizers\n", (what));    \
            skip();                                                                                \
        }                                                                                          \
    } while (0)

#define assert_close(a, b, tol) tu_assert_close((a), (b), (tol), #a, __FILE__, __LINE__)
static inline void tu_assert_close(double a, double b, double tol, const char *expr,
                                   const char *file, int line)
{
    if (!(fabs(a - b) <= tol))
    {
        print_error("%s = %.17g, expected %.17g within %.3g (off by %.3g)\n", expr, a, b, tol,
                    fabs(a - b));
        _fail(file, line);
    }
}

/* Path of the conifit binary under test (the Makefile sets CONIFIT). */
static inline const char *tu_conifit(void)
{
    const char *p = getenv("CONIFIT");
    return p ? p : "build/conifit";
}

/* Runs `conifit ARGS` through the shell with stdout and stderr captured into the given buffers
** (each up to cap bytes, NUL-terminated); returns the exit status. */
static inline int tu_run(char *out, size_t out_cap, char *errbuf, size_t err_cap, const char *fmt,
                         ...)
{
    char args[4096], cmd[8192];
    char outfile[] = "/tmp/conifit-test-out-XXXXXX", errfile[] = "/tmp/conifit-test-err-XXXXXX";
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(args, sizeof args, fmt, ap);
    va_end(ap);
    int fo = mkstemp(outfile), fe = mkstemp(errfile);
    assert_true(fo >= 0 && fe >= 0);
    snprintf(cmd, sizeof cmd, "%s %s >%s 2>%s </dev/null", tu_conifit(), args, outfile, errfile);
    int st = system(cmd);
    const char *files[2] = {outfile, errfile};
    char *bufs[2] = {out, errbuf};
    size_t caps[2] = {out_cap, err_cap};
    for (int i = 0; i < 2; i++) {
        if (!bufs[i])
            continue;
        FILE *f = fopen(files[i], "rb");
        size_t n = f ? fread(bufs[i], 1, caps[i] - 1, f) : 0;
        bufs[i][n] = '\0';
        if (f)
            fclose(f);
    }
    close(fo);
    close(fe);
    remove(outfile);
    remove(errfile);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* A scratch folder for a group of tests: TU_SCRATCH_GROUP("name") defines `static char dir[]`
** (/tmp/conifit-name-XXXXXX) and the group's setup (creates it) and teardown (removes it with all
** it holds), for cmocka_run_group_tests(tests, setup, teardown). */
#define TU_SCRATCH_GROUP(name)                                                                     \
    static char dir[] = "/tmp/conifit-" name "-XXXXXX";                                           \
    static int setup(void **state)                                                                 \
    {                                                                                              \
        (void)state;                                                                               \
        return mkdtemp(dir) ? 0 : -1;                                                              \
    }                                                                                              \
    static int teardown(void **state)                                                              \
    {                                                                                              \
        (void)state;                                                                               \
        char cmd_[sizeof dir + 16];                                                                \
        snprintf(cmd_, sizeof cmd_, "rm -rf '%s'", dir);                                           \
        return system(cmd_) == 0 ? 0 : -1;                                                         \
    }

/* Runs argv (argv[0] a full path; no shell, so arguments may hold any byte) in folder dir (NULL:
** here) with env_extra ("NAME=VALUE", or NULL) added to the environment, standard input and
** output on /dev/null and standard error into the file err_path (relative to dir). Returns the
** exit status, or -1 when the program did not exit. */
static inline int tu_exec(const char *dir, const char *env_extra, char *const argv[],
                          const char *err_path)
{
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        if (dir && chdir(dir) != 0)
            _exit(126);
        int null = open("/dev/null", O_RDWR);
        int e = open(err_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (null < 0 || e < 0)
            _exit(126);
        dup2(null, 0);
        dup2(null, 1);
        dup2(e, 2);
        if (env_extra)
            putenv((char *)env_extra);
        execv(argv[0], argv);
        _exit(127);
    }
    int st;
    assert_int_equal(waitpid(pid, &st, 0), pid);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* Fails unless the text files a and b hold the same lines with the same words, where a word that
** reads as a number (strtod, whole word) need only agree with its counterpart to rel relatively
** (|x - y| <= rel * max(|x|, |y|)). For outputs whose numbers pass through the vector copies of the
** law or the lattice (model/simd.h, cf_simd_level), which round differently from one another. */
#define assert_text_close(a, b, rel) tu_assert_text_close((a), (b), (rel), __FILE__, __LINE__)
static inline void tu_assert_text_close(const char *a, const char *b, double rel, const char *file,
                                        int line)
{
    FILE *fa = fopen(a, "r"), *fb = fopen(b, "r");
    if (!fa || !fb) {
        print_error("cannot open %s or %s\n", a, b);
        _fail(file, line);
    }
    char la[4096], lb[4096];
    int lineno = 0, bad = 0;
    for (;;) {
        char *ra = fgets(la, sizeof la, fa), *rb = fgets(lb, sizeof lb, fb);
        lineno++;
        if (!ra || !rb) {
            bad = ra != rb; /* one file ends before the other */
            break;
        }
        const char *pa = la, *pb = lb;
        while (!bad && (*pa || *pb)) {
            char *ea, *eb;
            double x = strtod(pa, &ea), y = strtod(pb, &eb);
            if (ea != pa && eb != pb) { /* numbers on both sides */
                const double m = fabs(x) > fabs(y) ? fabs(x) : fabs(y);
                bad = !(x == y || fabs(x - y) <= rel * m); /* 9e999 (a word) is inf on both */
                pa = ea;
                pb = eb;
            } else {
                bad = *pa != *pb;
                pa += *pa != 0;
                pb += *pb != 0;
            }
        }
        if (bad)
            break;
    }
    fclose(fa);
    fclose(fb);
    if (bad) {
        print_error("%s and %s differ at line %d beyond %.3g relative:\n  %s  %s", a, b, lineno,
                    rel, la, lb);
        _fail(file, line);
    }
}

/* The twelve published tables of ../shared/datasets, by file name. */
static const char *const tu_published_tables[] = {
    "brain_coronaradiata_compression.csv", "brain_coronaradiata_tension.csv",
    "brain_cortex_compression.csv",        "brain_cortex_shear.csv",
    "brain_cortex_tension.csv",            "heart_myocardium_biaxial_1to1_fiber.csv",
    "heart_myocardium_shear_fs.csv",       "muscle_compression_relaxation_crossfiber30.csv",
    "muscle_compression_relaxation_fiber30.csv", "skin_porcine_stripbiaxial_x.csv",
    "thrombus_pureshear_force_displacement.csv", "treloar1944_rubber_uniaxial.csv"};
#define TU_PUBLISHED_COUNT (sizeof tu_published_tables / sizeof tu_published_tables[0])

/* The folder of published tables, or NULL when it is absent (tests that need it then skip). */
static inline const char *tu_datasets(void)
{
    static const char *dir = "../shared/datasets";
    FILE *f = fopen("../shared/datasets/README.md", "r");
    if (!f)
        return NULL;
    fclose(f);
    return dir;
}

/* The whole file at path, NUL-terminated (caller frees), or NULL when it cannot be read. */
static inline char *tu_slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = n >= 0 ? malloc((size_t)n + 1) : NULL;
    size_t got = buf ? fread(buf, 1, (size_t)n, f) : 0;
    if (buf)
        buf[got] = '\0';
    fclose(f);
    return buf;
}

/* The reaction tolerance (N) an exported deck's header states ("reaction tolerance implied by
** the tables: "), failing the test when the header lacks it or it is not positive. */
static inline double tu_deck_tolerance(const char *deck)
{
    const char *key = "reaction tolerance implied by the tables: ";
    const char *p = strstr(deck, key);
    if (!p)
        fail_msg("the deck's header states no reaction tolerance");
    const double tol = strtod(p + strlen(key), NULL);
    if (!(tol > 0))
        fail_msg("the deck's reaction tolerance %g is not positive", tol);
    return tol;
}

/* Writes len bytes of text into a new file at path: 0, or -1. */
static inline int tu_write_bytes(const char *path, const char *text, size_t len)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return -1;
    int ok = fwrite(text, 1, len, f) == len;
    return fclose(f) == 0 && ok ? 0 : -1;
}

/* A ligament's force-displacement table (mm, N), written to path: 50 rows to 5 mm and 450 N in
** the toe-linear form of Blankevoort and Huiskes (J. Biomech. Eng. 113 (1991) 263-269):
** f = k u^2/(4 u_l) up to 2 u_l (the toe, as the crimped fibres straighten), k (u - u_l) beyond
** (linear), here with u_l = 1 mm (their toe strain 0.03 on a 33 mm ligament, an ACL's length) and
** k = 112.5 N/mm (within the 100-250 N/mm measured on human ACLs). 0, or -1. */
static inline int tu_ligament_csv(const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    fprintf(f, "displacement_mm,force_N\n");
    const double k = 112.5, ul = 1.0;
    for (int i = 1; i <= 50; i++) {
        const double u = 5.0 * i / 50;
        fprintf(f, "%.3f,%.3f\n", u, u <= 2 * ul ? k * u * u / (4 * ul) : k * (u - ul));
    }
    return fclose(f) == 0 ? 0 : -1;
}

#endif
