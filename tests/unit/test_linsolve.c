/*
** Tests of the linear solver behind its matrix interface (src/model/linsolve.c, linsolve_krylov.c),
** on matrices that are no lattice's: a 3-D Laplacian of Dirichlet ends, scaled unevenly (S L S,
** so that the solver's own Jacobi scale matters) and shifted to make it indefinite:
**  - the cascade solves it (sparse factorisation, and the banded LDL^T when the sparse one is
**    turned off), counts one linear solve, and reports the negative pivots that the known
**    eigenvalues predict;
**  - a chord step solves the matrix last factored, not the current one;
**  - a Krylov step on those factors solves the current matrix;
**  - cf_linsolve_factor and cf_linsolve_solve: one assembly, then many right-hand sides solved with
**    the kept factors (definite and indefinite), their inertia, and a clear refusal without
**    factors.
*/
#include "testutil.h"

#include "model/linsolve.h"

enum { N1 = 7, N2 = 6, N3 = 5, NU = N1 * N2 * N3 };

/* The pattern (rows increasing within a column) and the matrix the fill callback writes:
** S (L - sigma I) S with S = diag(s), L the 7-point Laplacian. */
typedef struct problem {
    int p[NU + 1], i[7 * NU];
    double s[NU];
    double sigma;
    int fills; /* calls of the callback */
} problem;

static int index_of(int q, int b, int c)
{
    return q + N1 * (b + N2 * c);
}

static void build(problem *pb, double sigma)
{
    memset(pb, 0, sizeof *pb);
    pb->sigma = sigma;
    int k = 0;
    /* the neighbours in increasing order of index: -z, -y, -x, itself, +x, +y, +z */
    static const int nb[7][3] = {{0, 0, -1}, {0, -1, 0}, {-1, 0, 0}, {0, 0, 0},
                                 {1, 0, 0},  {0, 1, 0},  {0, 0, 1}};
    for (int c = 0; c < N3; c++)
        for (int b = 0; b < N2; b++)
            for (int q = 0; q < N1; q++) {
                const int col = index_of(q, b, c);
                pb->p[col] = k;
                pb->s[col] = 1.0 + 0.37 * ((col * 7) % 11); /* uneven: 1 to 4.7 */
                for (int m = 0; m < 7; m++) {
                    const int q2 = q + nb[m][0], b2 = b + nb[m][1], c2 = c + nb[m][2];
                    if (q2 >= 0 && q2 < N1 && b2 >= 0 && b2 < N2 && c2 >= 0 && c2 < N3)
                        pb->i[k++] = index_of(q2, b2, c2);
                }
            }
    pb->p[NU] = k;
}

static void fill(void *ctx, double *v)
{
    problem *pb = ctx;
    pb->fills++;
    for (int col = 0; col < NU; col++)
        for (int k = pb->p[col]; k < pb->p[col + 1]; k++) {
            const int row = pb->i[k];
            const double l = row == col ? 6.0 - pb->sigma : -1.0;
            v[k] = pb->s[row] * l * pb->s[col];
        }
}

/* Largest |A x - b| over largest |b|, A as the callback writes it now. */
static double residual(problem *pb, const double *x, const double *b)
{
    double *v = malloc((size_t)pb->p[NU] * sizeof *v), r[NU] = {0};
    assert_non_null(v);
    const int fills = pb->fills;
    fill(pb, v);
    pb->fills = fills;
    for (int col = 0; col < NU; col++)
        for (int k = pb->p[col]; k < pb->p[col + 1]; k++)
            r[pb->i[k]] += v[k] * x[col];
    double worst = 0, bmax = 0;
    for (int e = 0; e < NU; e++) {
        worst = fmax(worst, fabs(r[e] - b[e]));
        bmax = fmax(bmax, fabs(b[e]));
    }
    free(v);
    return worst / bmax;
}

/* Eigenvalues of L below sigma: sums of 2 - 2 cos(m pi / (N + 1)) over the three axes. */
static long count_below(double sigma)
{
    long count = 0;
    for (int i = 1; i <= N1; i++)
        for (int j = 1; j <= N2; j++)
            for (int l = 1; l <= N3; l++) {
                const double lam = 6 - 2 * cos(i * M_PI / (N1 + 1)) -
                                   2 * cos(j * M_PI / (N2 + 1)) - 2 * cos(l * M_PI / (N3 + 1));
                assert_true(fabs(lam - sigma) > 1e-6); /* the shift is not an eigenvalue */
                count += lam < sigma;
            }
    return count;
}

static void rhs(double *b)
{
    for (int e = 0; e < NU; e++)
        b[e] = sin(0.7 * e) + 0.1 * e / NU;
}

/* The cascade on the matrix shifted by sigma: solution, one linear solve, inertia. */
static void check_direction(double sigma, int banded_only)
{
    problem *pb = malloc(sizeof *pb);
    assert_non_null(pb);
    build(pb, sigma);
    cf_linsolve *ls = NULL;
    cf_error err = {0};
    assert_int_equal(cf_linsolve_create(&ls, NU, pb->p, pb->i, fill, pb, banded_only, &err),
                     CF_OK);
    double b[NU], x[NU];
    rhs(b);
    size_t solves = 0;
    if (cf_linsolve_direction(ls, b, x, &solves, &err) != CF_OK)
        fail_msg("sigma %g, banded_only %d: %s", sigma, banded_only, err.msg);
    assert_int_equal(pb->fills, 1);
    assert_int_equal(solves, 1);
    const double res = residual(pb, x, b);
    if (!(res < 1e-10))
        fail_msg("sigma %g, banded_only %d: residual %g", sigma, banded_only, res);
    const long expect = count_below(sigma);
    if (cf_linsolve_neg_pivots(ls) != expect)
        fail_msg("sigma %g, banded_only %d: %ld negative pivots, %ld eigenvalues below", sigma,
                 banded_only, cf_linsolve_neg_pivots(ls), expect);
    /* only the sparse factorisation keeps factors for chord steps */
    assert_int_equal(cf_linsolve_factored(ls), !banded_only);
    cf_linsolve_free(ls);
    free(pb);
}

static void solves_definite_matrix(void **state)
{
    (void)state;
    check_direction(0.5, 0);
    check_direction(0.5, 1);
}

static void solves_indefinite_matrix_and_counts_its_inertia(void **state)
{
    (void)state;
    check_direction(3.1, 0);
    check_direction(3.1, 1);
}

/* After a factorisation the matrix changes (a larger shift, still positive definite): a chord step
** still solves the old one, a Krylov step on the old factors solves the new one. */
static void chord_and_krylov_steps(void **state)
{
    (void)state;
    problem *pb = malloc(sizeof *pb);
    assert_non_null(pb);
    build(pb, 0.3);
    cf_linsolve *ls = NULL;
    cf_error err = {0};
    assert_int_equal(cf_linsolve_create(&ls, NU, pb->p, pb->i, fill, pb, 0, &err), CF_OK);
    double b[NU], x[NU];
    rhs(b);
    assert_int_equal(cf_linsolve_direction(ls, b, x, NULL, &err), CF_OK);
    assert_true(cf_linsolve_factored(ls));
    pb->sigma = 0.35;
    int fatal = 0;
    assert_int_equal(cf_linsolve_chord(ls, b, x, &fatal, &err), 1);
    assert_int_equal(fatal, 0);
    const double res_new_chord = residual(pb, x, b);
    pb->sigma = 0.3;
    assert_true(residual(pb, x, b) < 1e-10); /* the factored matrix */
    pb->sigma = 0.35;
    assert_true(res_new_chord > 1e-3);        /* not the current one */
    const int fills = pb->fills;
    assert_int_equal(cf_linsolve_krylov(ls, b, x, 1e-9, &fatal, &err), 1);
    assert_int_equal(fatal, 0);
    assert_int_equal(pb->fills, fills + 1); /* it assembled the current matrix */
    const double res = residual(pb, x, b);
    if (!(res < 1e-8))
        fail_msg("Krylov step: residual %g against the current matrix", res);
    cf_linsolve_free(ls);
    free(pb);
}

/* Factors once, solves several right-hand sides with the kept factors (each solves the factored
** matrix, no assembly between), for a definite and an indefinite shift; a solve before any
** factorisation is refused. */
static void factor_once_and_solve_many(void **state)
{
    (void)state;
    problem *pb = malloc(sizeof *pb);
    assert_non_null(pb);
    const double sigmas[2] = {0.5, 3.1};
    for (int t = 0; t < 2; t++) {
        build(pb, sigmas[t]);
        cf_linsolve *ls = NULL;
        cf_error err = {0};
        assert_int_equal(cf_linsolve_create(&ls, NU, pb->p, pb->i, fill, pb, 0, &err), CF_OK);
        double b[NU], x[NU];
        rhs(b);
        assert_int_equal(cf_linsolve_solve(ls, b, x, &err), CF_E_NOCONV);
        assert_non_null(strstr(err.msg, "no factors"));
        if (cf_linsolve_factor(ls, &err) != CF_OK)
            fail_msg("sigma %g: %s", sigmas[t], err.msg);
        assert_int_equal(pb->fills, 1);
        assert_true(cf_linsolve_factored(ls));
        assert_int_equal(cf_linsolve_neg_pivots(ls), count_below(sigmas[t]));
        for (int r = 0; r < 4; r++) {
            for (int e = 0; e < NU; e++)
                b[e] = r == 0 ? b[e] : cos(0.3 * (r + 1) * e) - 0.2 * r;
            assert_int_equal(cf_linsolve_solve(ls, b, x, &err), CF_OK);
            const double res = residual(pb, x, b);
            if (!(res < 1e-10))
                fail_msg("sigma %g, right-hand side %d: residual %g", sigmas[t], r, res);
        }
        assert_int_equal(pb->fills, 1); /* the solves assembled nothing */
        cf_linsolve_free(ls);
    }
    free(pb);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(solves_definite_matrix),
        cmocka_unit_test(solves_indefinite_matrix_and_counts_its_inertia),
        cmocka_unit_test(chord_and_krylov_steps),
        cmocka_unit_test(factor_once_and_solve_many),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
