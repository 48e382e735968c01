/*
** L D L^T of a small symmetric band matrix without pivoting, and its solve (band_ldlt.c), for the
** inertia of the lattice tangents at a homogeneous state (linsolve.c's banded_only path, which
** cf_msm_homogeneous_inertias takes many thousand times in a joint fit's stability checks). The
** same right-looking algorithm and the same operations as GSL's gsl_linalg_ldlt_band_decomp, but
** with the rank-one update of the trailing band written as contiguous loops the compiler
** vectorises (GSL calls gslcblas's strided dsyr for it). Private to the model layer.
**
** Storage: the lower band by columns, ab[j * (bw + 1) + i] = A(j + i, j), i = 0 .. bw (GSL's
** band layout, AB(j, i - j) = A(i, j), row-major with bw + 1 columns); entries past the matrix's
** last row are ignored.
*/
#ifndef CF_MODEL_BAND_LDLT_H
#define CF_MODEL_BAND_LDLT_H

#include <stddef.h>

/* Factors the n x n band matrix ab (half-bandwidth bw) in place: D on the diagonal (ab[j (bw + 1)]),
** L's columns below it. Returns 0, or -1 at a zero pivot (the factors then incomplete). *neg (may
** be NULL) is the number of negative pivots: the matrix's negative eigenvalues (Sylvester). */
int cf_band_ldlt_factor(double *ab, size_t n, size_t bw, long *neg);

/* x <- A^-1 x from the factors of cf_band_ldlt_factor. */
void cf_band_ldlt_solve(const double *ab, size_t n, size_t bw, double *x);

#endif
