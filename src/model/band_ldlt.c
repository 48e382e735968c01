/*
** L D L^T of a small symmetric band matrix without pivoting, and its solve (see band_ldlt.h).
*/
#include "model/band_ldlt.h"

#include "model/law_simd.h"

/* The factorisation, one copy per instruction set (law_simd.h's dispatch). The copies differ only
** in the width of the rank-one update's vectors; each entry gets the same operations in the same
** order (no contraction into fused multiply-adds: this file is compiled without it), so every
** copy gives the same factors to the bit. */
#define BAND_FACTOR(attr, sfx, unused)                                                             \
    attr static int band_factor##sfx(double *ab, size_t n, size_t bw, long *neg)                   \
    {                                                                                              \
        const size_t ld = bw + 1;                                                                  \
        long nneg = 0;                                                                             \
        for (size_t j = 0; j < n; j++) {                                                           \
            double *restrict cj = ab + j * ld;                                                     \
            const double d = cj[0];                                                                \
            if (d == 0.0)                                                                          \
                return -1;                                                                         \
            nneg += d < 0;                                                                         \
            const size_t len = bw < n - 1 - j ? bw : n - 1 - j;                                    \
            const double inv = 1.0 / d;                                                            \
            for (size_t i = 1; i <= len; i++)                                                      \
                cj[i] *= inv;                                                                      \
            /* the trailing band: A(j + i, j + k) -= d l_k l_i, i >= k (column j + k from its  \
            ** diagonal) */                                                                        \
            for (size_t k = 1; k <= len; k++) {                                                    \
                double *restrict ck = ab + (j + k) * ld;                                           \
                const double t = -d * cj[k];                                                       \
                const double *restrict l = cj + k;                                                 \
                const size_t m = len - k;                                                          \
                _Pragma("omp simd") for (size_t i = 0; i <= m; i++) ck[i] += t * l[i];             \
            }                                                                                      \
        }                                                                                          \
        *neg = nneg;                                                                               \
        return 0;                                                                                  \
    }
CF_SIMD_COPIES(BAND_FACTOR, 0)

int cf_band_ldlt_factor(double *ab, size_t n, size_t bw, long *neg)
{
    long nneg = 0;
    const int r = CF_SIMD_CALL(band_factor, (ab, n, bw, &nneg));
    if (neg)
        *neg = nneg;
    return r;
}

void cf_band_ldlt_solve(const double *ab, size_t n, size_t bw, double *x)
{
    const size_t ld = bw + 1;
    for (size_t j = 0; j < n; j++) { /* L y = x, by columns */
        const double *cj = ab + j * ld;
        const size_t len = bw < n - 1 - j ? bw : n - 1 - j;
        const double xj = x[j];
        for (size_t i = 1; i <= len; i++)
            x[j + i] -= cj[i] * xj;
    }
    for (size_t j = 0; j < n; j++)
        x[j] /= ab[j * ld];
    for (size_t j = n; j-- > 0;) { /* L^T x = y, by rows of L^T (columns of L) */
        const double *cj = ab + j * ld;
        const size_t len = bw < n - 1 - j ? bw : n - 1 - j;
        double sum = x[j];
        for (size_t i = 1; i <= len; i++)
            sum -= cj[i] * x[j + i];
        x[j] = sum;
    }
}
