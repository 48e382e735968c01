/*
** Tests of the band L D L^T (src/model/band_ldlt.c), the stability checks' factorisation, on
** random symmetric band matrices (fixed seed) of the lattice tangents' sizes:
**  - its factors equal GSL's gsl_linalg_ldlt_band_decomp's to the bit (the same operations), at
**    every instruction-set copy;
**  - its count of negative pivots is the number of negative eigenvalues (GSL's symmetric
**    eigensolver on the full matrix), for definite and indefinite matrices;
**  - its solve solves the matrix to 1e-10 of the right-hand side;
**  - a zero pivot is refused.
*/
/* conifit: vector-level: the band factorisation's vector copies */
#include "testutil.h"

#include <gsl/gsl_eigen.h>
#include <gsl/gsl_linalg.h>

#include "model/band_ldlt.h"

/* A symmetric band matrix of half-bandwidth bw, full (a, n x n) and in band storage (ab), entries
** off the diagonal in [-1/2, 1/2], the diagonal bw (about the largest row sum) plus one of them,
** every every-th diagonal entry of the opposite sign (every 0: none, a definite matrix). */
static void random_band(size_t n, size_t bw, int every, unsigned *seed, double *a, double *ab)
{
    memset(a, 0, n * n * sizeof(double));
    memset(ab, 0, n * (bw + 1) * sizeof(double));
    for (size_t j = 0; j < n; j++)
        for (size_t i = j; i < n && i <= j + bw; i++) {
            *seed = *seed * 1103515245u + 12345u;
            double v = ((*seed >> 8) & 0xffff) / 65535.0 - 0.5;
            if (i == j)
                v += every && j % (size_t)every == 0 ? -(double)bw : (double)bw;
            a[i * n + j] = a[j * n + i] = v;
            ab[j * (bw + 1) + (i - j)] = v;
        }
}

static long negative_eigenvalues(size_t n, const double *a)
{
    gsl_matrix *m = gsl_matrix_alloc(n, n);
    gsl_vector *ev = gsl_vector_alloc(n);
    gsl_eigen_symm_workspace *w = gsl_eigen_symm_alloc(n);
    assert_non_null(m);
    assert_non_null(ev);
    assert_non_null(w);
    memcpy(m->data, a, n * n * sizeof(double));
    assert_int_equal(gsl_eigen_symm(m, ev, w), GSL_SUCCESS);
    long neg = 0;
    for (size_t i = 0; i < n; i++)
        neg += gsl_vector_get(ev, i) < 0;
    gsl_eigen_symm_free(w);
    gsl_vector_free(ev);
    gsl_matrix_free(m);
    return neg;
}

static void factors_inertia_and_solve(void **state)
{
    (void)state;
    static const size_t sizes[][2] = {{70, 30}, {180, 65}, {12, 11}, {9, 2}};
    static const int shifts[] = {0, 5, 2};
    unsigned seed = 42;
    for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++)
        for (size_t h = 0; h < sizeof shifts / sizeof shifts[0]; h++) {
            const size_t n = sizes[s][0], bw = sizes[s][1];
            double *a = malloc(n * n * sizeof(double));
            double *ab = malloc(n * (bw + 1) * sizeof(double));
            double *x = malloc(n * sizeof(double)), *b = malloc(n * sizeof(double));
            gsl_matrix *g = gsl_matrix_alloc(n, bw + 1);
            assert_true(a && ab && x && b && g);
            random_band(n, bw, shifts[h], &seed, a, ab);
            memcpy(g->data, ab, n * (bw + 1) * sizeof(double));
            long neg = -1;
            assert_int_equal(cf_band_ldlt_factor(ab, n, bw, &neg), 0);
            if (gsl_linalg_ldlt_band_decomp(g) == GSL_SUCCESS) /* every entry but GSL's norm */
                for (size_t j = 0; j < n; j++)
                    for (size_t i = 0; i <= bw && j + i < n; i++)
                        assert_true(ab[j * (bw + 1) + i] == g->data[j * (bw + 1) + i]);
            const long want = negative_eigenvalues(n, a);
            assert_int_equal(neg, want);
            if (h > 0)
                assert_true(want > 0); /* indefinite */
            for (size_t i = 0; i < n; i++)
                b[i] = x[i] = 1.0 + 0.1 * (double)(i % 7);
            cf_band_ldlt_solve(ab, n, bw, x);
            double rn = 0, bn = 0;
            for (size_t i = 0; i < n; i++) {
                double r = b[i];
                for (size_t j = 0; j < n; j++)
                    r -= a[i * n + j] * x[j];
                rn += r * r, bn += b[i] * b[i];
            }
            assert_true(sqrt(rn) <= 1e-10 * sqrt(bn));
            gsl_matrix_free(g);
            free(a), free(ab), free(x), free(b);
        }
}

static void zero_pivot_refused(void **state)
{
    (void)state;
    double ab[3 * 2] = {0.0, 1.0, 1.0, 1.0, 1.0, 0.0}; /* [[0 1 0] [1 1 1] [0 1 1]], bw 1 */
    long neg = -7;
    assert_int_equal(cf_band_ldlt_factor(ab, 3, 1, &neg), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(factors_inertia_and_solve),
        cmocka_unit_test(zero_pivot_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
