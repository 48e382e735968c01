/*
** Tests of the sparse factorisation with inertia (src/model/sparse_chol.c): the negative pivots of
** shifted Laplacians against their known eigenvalues (a small one, factored simplicially, and a
** 3-D one large enough for supernodes), the solution against the matrix, a singular matrix, and
** factorisations on several threads at once.
*/
#include "testutil.h"

#include <pthread.h>

#include "model/sparse_chol.h"

/* A symmetric matrix in compressed columns with both triangles stored and the rows of every
** column in descending order (CHOLMOD must not rely on sorted input). */
typedef struct csc {
    size_t n;
    int *p, *i;
    double *x;
} csc;

static void csc_free(csc *a)
{
    free(a->p);
    free(a->i);
    free(a->x);
}

/* The 7-point Laplacian of an N1 x N2 x N3 grid with Dirichlet ends, minus sigma I (N2 = N3 = 1
** gives the 1-D tridiagonal one). */
static csc laplacian(int N1, int N2, int N3, double sigma)
{
    csc a;
    a.n = (size_t)N1 * N2 * N3;
    a.p = calloc(a.n + 1, sizeof(int));
    a.i = calloc(7 * a.n, sizeof(int));
    a.x = calloc(7 * a.n, sizeof(double));
    assert_non_null(a.p);
    assert_non_null(a.i);
    assert_non_null(a.x);
    int k = 0;
    for (int c = 0; c < N3; c++)
        for (int b = 0; b < N2; b++)
            for (int q = 0; q < N1; q++) {
                int col = q + N1 * (b + N2 * c);
                a.p[col] = k;
                /* neighbours in descending order of index */
                const int nb[6][3] = {{0, 0, 1}, {0, 1, 0}, {1, 0, 0},
                                      {-1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
                const double diag = 2.0 * (1 + (N2 > 1) + (N3 > 1)) - sigma;
                for (int m = 0; m < 3; m++) {
                    int q2 = q + nb[m][0], b2 = b + nb[m][1], c2 = c + nb[m][2];
                    if (q2 < N1 && b2 < N2 && c2 < N3) {
                        a.i[k] = q2 + N1 * (b2 + N2 * c2);
                        a.x[k++] = -1.0;
                    }
                }
                a.i[k] = col;
                a.x[k++] = diag;
                for (int m = 3; m < 6; m++) {
                    int q2 = q + nb[m][0], b2 = b + nb[m][1], c2 = c + nb[m][2];
                    if (q2 >= 0 && b2 >= 0 && c2 >= 0) {
                        a.i[k] = q2 + N1 * (b2 + N2 * c2);
                        a.x[k++] = -1.0;
                    }
                }
            }
    a.p[a.n] = k;
    return a;
}

/* Eigenvalues of the Dirichlet Laplacian below sigma: sums of 2 - 2 cos(m pi/(N + 1)). */
static long count_below(int N1, int N2, int N3, double sigma)
{
    long count = 0;
    for (int i = 1; i <= N1; i++)
        for (int j = 1; j <= (N2 > 1 ? N2 : 1); j++)
            for (int l = 1; l <= (N3 > 1 ? N3 : 1); l++) {
                double lam = 2 - 2 * cos(i * M_PI / (N1 + 1));
                if (N2 > 1)
                    lam += 2 - 2 * cos(j * M_PI / (N2 + 1));
                if (N3 > 1)
                    lam += 2 - 2 * cos(l * M_PI / (N3 + 1));
                assert_true(fabs(lam - sigma) > 1e-7); /* the shift is not an eigenvalue */
                count += lam < sigma;
            }
    return count;
}

/* Largest |A x - b| over |b| for the full symmetric matrix a. */
static double residual(const csc *a, const double *x, const double *b)
{
    double *r = calloc(a->n, sizeof(double));
    assert_non_null(r);
    for (size_t c = 0; c < a->n; c++)
        for (int k = a->p[c]; k < a->p[c + 1]; k++)
            r[a->i[k]] += a->x[k] * x[c];
    double worst = 0, bmax = 0;
    for (size_t e = 0; e < a->n; e++) {
        worst = fmax(worst, fabs(r[e] - b[e]));
        bmax = fmax(bmax, fabs(b[e]));
    }
    free(r);
    return worst / bmax;
}

static void check_inertia_and_solve(int N1, int N2, int N3, double sigma, int expect_ldlt)
{
    csc a = laplacian(N1, N2, N3, sigma);
    cf_sparse_chol *ch = NULL;
    cf_error err = {0};
    assert_int_equal(cf_sparse_chol_create(&ch, a.n, a.p, a.i, &err), CF_OK);
    cf_chol_info info;
    cf_status st = cf_sparse_chol_factor(ch, a.x, &info, &err);
    if (st != CF_OK)
        fail_msg("factor %dx%dx%d sigma %g: %s", N1, N2, N3, sigma, err.msg);
    long expect = count_below(N1, N2, N3, sigma);
    if (info.neg_pivots != expect)
        fail_msg("%dx%dx%d, sigma %g: %ld negative pivots, %ld eigenvalues below sigma", N1, N2,
                 N3, sigma, info.neg_pivots, expect);
    if (expect_ldlt >= 0)
        assert_int_equal(info.ldlt, expect_ldlt);
    assert_true(info.fill >= 1.0);
    double *b = malloc(a.n * sizeof(double)), *x = malloc(a.n * sizeof(double));
    assert_non_null(b);
    assert_non_null(x);
    for (size_t e = 0; e < a.n; e++)
        b[e] = sin(0.37 * (double)e) + 0.5;
    assert_int_equal(cf_sparse_chol_solve(ch, b, x, &err), CF_OK);
    double r = residual(&a, x, b);
    if (!(r < 1e-9))
        fail_msg("%dx%dx%d sigma %g: relative residual %.3g", N1, N2, N3, sigma, r);
    assert_true(cf_sparse_chol_peak_bytes(ch) > 0);
    free(b);
    free(x);
    cf_sparse_chol_free(ch);
    csc_free(&a);
}

static void positive_definite_matrix_has_no_negative_pivots(void **state)
{
    (void)state;
    check_inertia_and_solve(200, 1, 1, 0.0, -1);
    check_inertia_and_solve(20, 20, 20, 0.0, 0); /* supernodal LL^T */
}

static void shifted_laplacian_counts_its_eigenvalues_below_the_shift(void **state)
{
    (void)state;
    /* shifts that fall between eigenvalues (none within 1e-6 of one) */
    const double s1[] = {0.5, 1.3, 2.9, 3.7};
    for (size_t k = 0; k < sizeof s1 / sizeof s1[0]; k++)
        check_inertia_and_solve(200, 1, 1, s1[k], -1);
    const double s3[] = {0.61, 2.05, 5.5, 9.1};
    for (size_t k = 0; k < sizeof s3 / sizeof s3[0]; k++)
        check_inertia_and_solve(20, 20, 20, s3[k], 1);
}

static void zero_pivot_is_reported_as_singular(void **state)
{
    (void)state;
    /* diag(1, 2, 0, 3) */
    int p[5] = {0, 1, 2, 3, 4}, i[4] = {0, 1, 2, 3};
    double x[4] = {1, 2, 0, 3};
    cf_sparse_chol *ch = NULL;
    cf_error err = {0};
    assert_int_equal(cf_sparse_chol_create(&ch, 4, p, i, &err), CF_OK);
    cf_chol_info info;
    assert_int_equal(cf_sparse_chol_factor(ch, x, &info, &err), CF_E_NOCONV);
    assert_int_equal(info.singular, 1);
    assert_int_equal(info.neg_pivots, -1);
    assert_non_null(strstr(err.msg, "singular"));
    double b[4] = {1, 1, 1, 1}, sol[4];
    assert_int_equal(cf_sparse_chol_solve(ch, b, sol, &err), CF_E_INTERNAL);
    /* the same object factors a regular matrix afterwards */
    x[2] = -4;
    assert_int_equal(cf_sparse_chol_factor(ch, x, &info, &err), CF_OK);
    assert_int_equal(info.neg_pivots, 1);
    assert_int_equal(cf_sparse_chol_solve(ch, b, sol, &err), CF_OK);
    assert_close(sol[2], -0.25, 1e-15);
    cf_sparse_chol_free(ch);
}

/* Factorisations on several threads at once, as fits of several tables do: an indefinite matrix
** (MUMPS, whose shared module state crashed such runs) and a positive definite one large enough
** for CHOLMOD's supernodes (through the BLAS, whose races changed results in their last bits).
** Every thread must find the inertia and the very bits of the solution that one thread finds
** alone (one process, one instruction set). Checked inside the threads without cmocka (its
** failures jump), counted for the main thread. */
enum { CONCURRENT_THREADS = 4, CONCURRENT_ROUNDS = 8 };

typedef struct concurrent_case {
    csc a;
    long neg;    /* negative pivots expected */
    double *b;   /* right-hand side */
    double *ref; /* the solution found by one thread alone */
} concurrent_case;

/* Factors and solves c once; 0 when it matches ref (or fills ref when it is NULL). */
static int factor_once(concurrent_case *c, double *x)
{
    cf_sparse_chol *ch = NULL;
    cf_error err = {0};
    cf_chol_info info;
    if (cf_sparse_chol_create(&ch, c->a.n, c->a.p, c->a.i, &err) != CF_OK)
        return 1;
    int bad = cf_sparse_chol_factor(ch, c->a.x, &info, &err) != CF_OK || info.neg_pivots != c->neg ||
              cf_sparse_chol_solve(ch, c->b, x, &err) != CF_OK;
    cf_sparse_chol_free(ch);
    return bad || memcmp(x, c->ref, c->a.n * sizeof *x) != 0;
}

static void *factor_repeatedly(void *arg)
{
    concurrent_case *cases = arg;
    long bad = 0;
    double *x = malloc(cases[1].a.n * sizeof(double)); /* the larger case */
    for (int r = 0; x && r < CONCURRENT_ROUNDS; r++)
        bad += factor_once(&cases[r % 2], x);
    free(x);
    return (void *)(intptr_t)(x ? bad : 1);
}

static void factorisations_on_several_threads(void **state)
{
    (void)state;
    concurrent_case cases[2] = {{laplacian(10, 10, 10, 2.05), 0, NULL, NULL},
                                {laplacian(20, 20, 20, 0.0), 0, NULL, NULL}};
    cases[0].neg = count_below(10, 10, 10, 2.05);
    assert_true(cases[0].neg > 0);
    for (int k = 0; k < 2; k++) { /* read only from here on: shared by the threads */
        concurrent_case *c = &cases[k];
        c->b = malloc(c->a.n * sizeof(double));
        c->ref = malloc(c->a.n * sizeof(double));
        assert_non_null(c->b);
        assert_non_null(c->ref);
        for (size_t e = 0; e < c->a.n; e++)
            c->b[e] = cos(0.11 * (double)e);
        cf_sparse_chol *ch = NULL;
        cf_error err = {0};
        assert_int_equal(cf_sparse_chol_create(&ch, c->a.n, c->a.p, c->a.i, &err), CF_OK);
        assert_int_equal(cf_sparse_chol_factor(ch, c->a.x, NULL, &err), CF_OK);
        assert_int_equal(cf_sparse_chol_solve(ch, c->b, c->ref, &err), CF_OK);
        cf_sparse_chol_free(ch);
        assert_true(residual(&c->a, c->ref, c->b) < 1e-9);
    }
    pthread_t th[CONCURRENT_THREADS];
    for (int t = 0; t < CONCURRENT_THREADS; t++)
        assert_int_equal(pthread_create(&th[t], NULL, factor_repeatedly, cases), 0);
    long bad = 0;
    for (int t = 0; t < CONCURRENT_THREADS; t++) {
        void *ret;
        assert_int_equal(pthread_join(th[t], &ret), 0);
        bad += (long)(intptr_t)ret;
    }
    assert_int_equal(bad, 0);
    for (int k = 0; k < 2; k++) {
        free(cases[k].b);
        free(cases[k].ref);
        csc_free(&cases[k].a);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(positive_definite_matrix_has_no_negative_pivots),
        cmocka_unit_test(shifted_laplacian_counts_its_eigenvalues_below_the_shift),
        cmocka_unit_test(zero_pivot_is_reported_as_singular),
        cmocka_unit_test(factorisations_on_several_threads),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
