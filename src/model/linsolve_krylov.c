/*
** Krylov steps on a stale factorisation (see linsolve.h). Along the uniaxial curve the chord steps
** reuse the factors of an earlier tangent; they converge as long as the current tangent differs
** from it by a small relative change in every mode. Past the lattice's stability limit a few modes
** change much from one load step to the next (eigenvalues near zero move across it as springs
** stiffen), and the chord steps stall on those modes while the rest of the residual is long gone.
** GMRES on the current tangent, right-preconditioned by the old factors, removes those few modes
** in a few steps, each one solve with the old factors and one product with the new tangent: far
** cheaper than a new factorisation (at 24^3 cells one factorisation costs about 30 solves).
*/
#include "model/linsolve_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* GMRES steps before the factors count as too stale, the range of the linear solve's residual
** relative to its right-hand side aimed at (a tenth of the reduction the Newton step needs), and
** the largest one taken after KRYLOV_MAX steps short of the aim (the caller refactors beyond). */
#define KRYLOV_MAX 16
#define KRYLOV_ETA_MIN 1e-10
#define KRYLOV_ETA_MAX 0.1
#define KRYLOV_TAKE_MAX 0.5

/* y = A x for the matrix with C's pattern and the values v (both triangles stored). */
static void pattern_mul(const gsl_spmatrix *C, const double *v, const double *x, double *y,
                        size_t n)
{
    memset(y, 0, n * sizeof *y);
    for (size_t col = 0; col < n; col++) {
        const double xc = x[col];
        for (int k = C->p[col]; k < C->p[col + 1]; k++)
            y[C->i[k]] += v[k] * xc;
    }
}

static double dot(const double *a, const double *b, size_t n)
{
    double t = 0;
    for (size_t e = 0; e < n; e++)
        t += a[e] * b[e];
    return t;
}

/* Workspace: the current tangent's values and the two bases, kept between calls. */
static int workspace(cf_linsolve *s)
{
    const size_t n = s->n, nnz = (size_t)s->C->p[n];
    if (!s->kval)
        s->kval = malloc((nnz ? nnz : 1) * sizeof(double));
    if (!s->kbasis)
        s->kbasis = malloc((2 * KRYLOV_MAX + 1) * n * sizeof(double));
    return s->kval && s->kbasis;
}

int cf_linsolve_krylov(cf_linsolve *s, const double *b, double *x, double need, int *fatal,
                       cf_error *err)
{
    const double eta = fmin(fmax(0.1 * need, KRYLOV_ETA_MIN), KRYLOV_ETA_MAX);
    const double take = fmin(fmax(need, KRYLOV_ETA_MAX), KRYLOV_TAKE_MAX);
    const size_t n = s->n, m = KRYLOV_MAX;
    *fatal = 0;
    if (!s->chol || !s->C || n == 0)
        return 0;
    if (!workspace(s)) {
        *fatal = 1;
        cf_error_set(err, CF_E_INTERNAL, "out of memory for the Krylov steps");
        return 0;
    }
    s->fill(s->ctx, s->kval); /* the current matrix, scaled as the factored one */
    cf_linsolve_scale(s, s->kval);
    double *V = s->kbasis, *Z = s->kbasis + (m + 1) * n; /* V: m + 1 vectors, Z = M^-1 V: m */
    double H[KRYLOV_MAX + 1][KRYLOV_MAX], cs[KRYLOV_MAX], sn[KRYLOV_MAX], g[KRYLOV_MAX + 1];
    for (size_t e = 0; e < n; e++)
        V[e] = b[e] / s->D[e];
    const double beta = sqrt(dot(V, V, n));
    if (!(beta > 0) || !isfinite(beta))
        return 0;
    for (size_t e = 0; e < n; e++)
        V[e] /= beta;
    g[0] = beta;
    size_t k = 0;
    int conv = 0;
    for (size_t j = 0; j < m && !conv; j++) {
        double *vj = V + j * n, *zj = Z + j * n, *w = V + (j + 1) * n;
        cf_error lerr = {0};
        if (cf_sparse_chol_solve(s->chol, vj, zj, &lerr) != CF_OK)
            return 0; /* as a chord step's failed solve: the caller refactors */
        pattern_mul(s->C, s->kval, zj, w, n);
        for (size_t i = 0; i <= j; i++) { /* modified Gram-Schmidt */
            const double h = dot(w, V + i * n, n);
            H[i][j] = h;
            for (size_t e = 0; e < n; e++)
                w[e] -= h * V[i * n + e];
        }
        const double hn = sqrt(dot(w, w, n));
        H[j + 1][j] = hn;
        if (hn > 0)
            for (size_t e = 0; e < n; e++)
                w[e] /= hn;
        for (size_t i = 0; i < j; i++) { /* the earlier Givens rotations, then a new one */
            const double t = cs[i] * H[i][j] + sn[i] * H[i + 1][j];
            H[i + 1][j] = -sn[i] * H[i][j] + cs[i] * H[i + 1][j];
            H[i][j] = t;
        }
        const double den = hypot(H[j][j], H[j + 1][j]);
        if (!(den > 0) || !isfinite(den))
            return 0;
        cs[j] = H[j][j] / den;
        sn[j] = H[j + 1][j] / den;
        H[j][j] = den;
        H[j + 1][j] = 0;
        g[j + 1] = -sn[j] * g[j];
        g[j] = cs[j] * g[j];
        k = j + 1;
        conv = fabs(g[j + 1]) <= eta * beta || hn == 0;
    }
    /* short of eta after KRYLOV_MAX steps: still an inexact Newton step when it cuts the linear
    ** residual by 10x, or by what the Newton step needs (at most 2x), which the caller's line
    ** search and rate check judge */
    if (!conv && !(fabs(g[k]) <= take * beta))
        return 0;
    double y[KRYLOV_MAX];
    for (size_t i = k; i-- > 0;) { /* H y = g, upper triangular */
        double t = g[i];
        for (size_t l = i + 1; l < k; l++)
            t -= H[i][l] * y[l];
        y[i] = t / H[i][i];
    }
    int ok = 1;
    for (size_t e = 0; e < n && ok; e++) {
        double t = 0;
        for (size_t i = 0; i < k; i++)
            t += y[i] * Z[i * n + e];
        x[e] = t / s->D[e];
        ok = isfinite(x[e]);
    }
    return ok;
}
