/*
** Tests of the sparse solvers opened at their first use (src/model/sparse_dl.c, base/dynlib.c):
** a program linked with libconifit carries none of CHOLMOD, MUMPS, the BLAS, LAPACK or the
** Fortran runtime until a factorisation needs them; a library that cannot be loaded is an error
** that names it (through the sparse factorisation and through the linear solver's cascade), and
** is tried again on the next call; MUMPS is opened only by the first indefinite matrix.
** The tests run in order in one process: what is loaded cannot be unloaded.
*/
#include "testutil.h"

#include "model/linsolve.h"
#include "model/sparse_chol.h"
#include "model/sparse_dl.h"

#define N 12
#define ABSENT_CHOLMOD "libconifit-test-absent-cholmod.so"
#define ABSENT_MUMPS "libconifit-test-absent-mumps.so"

/* 1 when a file whose name holds word is mapped into this process. */
static int mapped(const char *word)
{
    FILE *f = fopen("/proc/self/maps", "r");
    assert_non_null(f);
    char line[4096];
    int found = 0;
    while (!found && fgets(line, sizeof line, f)) {
        const char *slash = strrchr(line, '/');
        found = slash && strstr(slash, word) != NULL;
    }
    fclose(f);
    return found;
}

/* The 1-D Laplacian tridiag(-1, 2, -1) of order N minus sigma I, both triangles, in compressed
** columns. Its eigenvalues are 2 - 2 cos(k pi / (N + 1)), k = 1..N. */
static int colp[N + 1], rowi[3 * N];
static double val[3 * N];

static void laplacian(double sigma)
{
    int k = 0;
    for (int c = 0; c < N; c++) {
        colp[c] = k;
        for (int r = c - 1; r <= c + 1; r++)
            if (r >= 0 && r < N) {
                rowi[k] = r;
                val[k++] = r == c ? 2.0 - sigma : -1.0;
            }
    }
    colp[N] = k;
}

static long eigenvalues_below(double sigma)
{
    long neg = 0;
    for (int k = 1; k <= N; k++)
        neg += 2.0 - 2.0 * cos(k * M_PI / (N + 1)) < sigma;
    return neg;
}

static void fill(void *ctx, double *v)
{
    (void)ctx;
    memcpy(v, val, (size_t)colp[N] * sizeof *v);
}

/* |A x - b| for A = the matrix in val. */
static double residual(const double *x, const double *b)
{
    double worst = 0;
    for (int r = 0; r < N; r++) {
        double s = -b[r];
        for (int c = 0; c < N; c++)
            for (int k = colp[c]; k < colp[c + 1]; k++)
                if (rowi[k] == r)
                    s += val[k] * x[c];
        worst = fmax(worst, fabs(s));
    }
    return worst;
}

/* The factorisation of the matrix of laplacian(sigma), created (its libraries then loaded). */
static cf_sparse_chol *created(double sigma)
{
    laplacian(sigma);
    cf_sparse_chol *ch = NULL;
    cf_error err = {0};
    assert_int_equal(cf_sparse_chol_create(&ch, N, colp, rowi, &err), CF_OK);
    return ch;
}

/* Solves with the last factors for b[r] = b0 + db r and checks the residual against tol. */
static void solves(cf_sparse_chol *ch, double b0, double db, double tol)
{
    double b[N], x[N];
    cf_error err = {0};
    for (int r = 0; r < N; r++)
        b[r] = b0 + db * r;
    assert_int_equal(cf_sparse_chol_solve(ch, b, x, &err), CF_OK);
    assert_true(residual(x, b) < tol);
}

static void nothing_heavy_is_loaded_before_a_factorisation(void **state)
{
    (void)state;
    /* (GSL's own CBLAS, libgslcblas, is linked: it is small) */
    static const char *const heavy[] = {"cholmod", "mumps", "libblas", "openblas", "liblapack",
                                        "gfortran", "metis", "scotch", "gmsh"};
    for (size_t k = 0; k < sizeof heavy / sizeof heavy[0]; k++)
        if (mapped(heavy[k]))
            fail_msg("a library named *%s* is loaded before any factorisation", heavy[k]);
}

static void a_missing_cholmod_is_an_error_naming_it(void **state)
{
    (void)state;
    cf_sparse_dl_names(ABSENT_CHOLMOD, ABSENT_MUMPS);
    laplacian(0.0);
    cf_sparse_chol *ch = NULL;
    cf_error err = {0};
    assert_int_equal(cf_sparse_chol_create(&ch, N, colp, rowi, &err), CF_E_INTERNAL);
    assert_null(ch);
    assert_non_null(strstr(err.msg, "CHOLMOD"));
    assert_non_null(strstr(err.msg, ABSENT_CHOLMOD));
    /* the linear solver's cascade does not fall back silently: it reports the library */
    cf_linsolve *ls = NULL;
    cf_error lerr = {0};
    assert_int_equal(cf_linsolve_create(&ls, N, colp, rowi, fill, NULL, 0, &lerr), CF_OK);
    double b[N], x[N];
    for (int r = 0; r < N; r++)
        b[r] = 1.0 + r;
    assert_int_equal(cf_linsolve_direction(ls, b, x, NULL, &lerr), CF_E_INTERNAL);
    assert_non_null(strstr(lerr.msg, ABSENT_CHOLMOD));
    cf_linsolve_free(ls);
    assert_false(mapped("cholmod"));
}

static void cholmod_loads_at_its_first_use_and_mumps_stays_out(void **state)
{
    (void)state;
    cf_sparse_dl_names(NULL, ABSENT_MUMPS); /* CHOLMOD tried again, by its default name */
    cf_sparse_chol *ch = created(0.0);
    cf_chol_info info;
    cf_error err = {0};
    assert_int_equal(cf_sparse_chol_factor(ch, val, &info, &err), CF_OK);
    assert_int_equal(info.neg_pivots, 0);
    assert_int_equal(info.ldlt, 0);
    solves(ch, 1.0, 1.0, 1e-10);
    cf_sparse_chol_free(ch);
    assert_true(mapped("cholmod"));
    assert_false(mapped("mumps"));
}

static void a_missing_mumps_is_an_error_naming_it_at_the_first_indefinite_matrix(void **state)
{
    (void)state;
    assert_true(eigenvalues_below(1.0) > 0); /* indefinite: eigenvalues below 1 become negative */
    cf_sparse_chol *ch = created(1.0);
    cf_error err = {0};
    cf_chol_info info;
    assert_int_equal(cf_sparse_chol_factor(ch, val, &info, &err), CF_E_INTERNAL);
    assert_non_null(strstr(err.msg, "MUMPS"));
    assert_non_null(strstr(err.msg, ABSENT_MUMPS));
    /* this object does not try again: its indefinite factorisation is off */
    cf_error again = {0};
    assert_int_equal(cf_sparse_chol_factor(ch, val, &info, &again), CF_E_NOCONV);
    cf_sparse_chol_free(ch);
    assert_false(mapped("mumps"));
}

static void mumps_loads_at_the_first_indefinite_matrix(void **state)
{
    (void)state;
    cf_sparse_dl_names(NULL, NULL);
    cf_sparse_chol *ch = created(1.0);
    cf_error err = {0};
    cf_chol_info info;
    assert_int_equal(cf_sparse_chol_factor(ch, val, &info, &err), CF_OK);
    assert_int_equal(info.ldlt, 1);
    assert_int_equal(info.neg_pivots, eigenvalues_below(1.0));
    solves(ch, 1.0, -0.1, 1e-9);
    cf_sparse_chol_free(ch);
    assert_true(mapped("mumps"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(nothing_heavy_is_loaded_before_a_factorisation),
        cmocka_unit_test(a_missing_cholmod_is_an_error_naming_it),
        cmocka_unit_test(cholmod_loads_at_its_first_use_and_mumps_stays_out),
        cmocka_unit_test(a_missing_mumps_is_an_error_naming_it_at_the_first_indefinite_matrix),
        cmocka_unit_test(mumps_loads_at_the_first_indefinite_matrix),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
