/*
** Tests of the Newton driver over a mechanical system (src/model/mech.h, mech_newton.c) on a
** system that is no body's: a chain of N unknowns with the energy
**   E(x) = sum_i (a x_i^4 / 4 + b x_i^2 / 2) + sum_i k (x_{i+1} - x_i)^2 / 2 - f . x,
** x_0 held at 0, and the loads f made from a chosen equilibrium x* (f = the gradient of the rest of
** E at x*), so the solution is known. States with some x_i >= XMAX are not admissible.
**  - from rest the driver finds x* to rounding, every state it leaves is admissible though the
**    first full step jumps far past XMAX, and it reuses factors (fewer fresh tangents than steps);
**    with chord_rate 0 every step takes the tangent afresh;
**  - a double well (b < 0) at the hump: the tangent's negative eigenvalues are reported;
**  - a system that admits no step: the driver says so and leaves the state where it was.
*/
#include "testutil.h"

#include <math.h>

#include "model/mech.h"

enum { N = 40 };
#define XMAX 2.0

typedef struct chain {
    double a, b, k;
    double x[N], x0[N], f[N], xs[N];
    int never;       /* 1: no state but the origin is admissible */
} chain;

/* The gradient of E without the loads at x into g. */
static void grad(const chain *c, const double *x, double *g)
{
    for (int i = 0; i < N; i++) {
        g[i] = c->a * x[i] * x[i] * x[i] + c->b * x[i];
        if (i > 0)
            g[i] += c->k * (x[i] - x[i - 1]);
        if (i < N - 1)
            g[i] += c->k * (x[i] - x[i + 1]);
    }
}

static cf_status residual(void *ctx, double *r, cf_error *err)
{
    (void)err;
    chain *c = ctx;
    grad(c, c->x, r);
    for (int i = 0; i < N; i++)
        r[i] -= c->f[i];
    r[0] = 0; /* held */
    return CF_OK;
}

/* The tridiagonal pattern: column j holds rows j - 1, j, j + 1 (those in range). */
static void pattern(int *p, int *rows)
{
    int k = 0;
    for (int j = 0; j < N; j++) {
        p[j] = k;
        for (int i = j - 1; i <= j + 1; i++)
            if (i >= 0 && i < N)
                rows[k++] = i;
    }
    p[N] = k;
}

static void tangent(void *ctx, double *v)
{
    const chain *c = ctx;
    int k = 0;
    for (int j = 0; j < N; j++)
        for (int i = j - 1; i <= j + 1; i++) {
            if (i < 0 || i >= N)
                continue;
            double t;
            if (i != j)
                t = -c->k;
            else
                t = 3 * c->a * c->x[j] * c->x[j] + c->b + c->k * ((j > 0) + (j < N - 1));
            if (i == 0 || j == 0) /* the held component: row and column zero, diagonal 1 */
                t = i == j;
            v[k++] = t;
        }
}

static void project(void *ctx, double *dx)
{
    (void)ctx;
    dx[0] = 0;
}

static void save(void *ctx)
{
    chain *c = ctx;
    memcpy(c->x0, c->x, sizeof c->x);
}

static int admissible(const chain *c)
{
    for (int i = 0; i < N; i++)
        if (!(c->x[i] < XMAX))
            return 0;
    return 1;
}

static int trial(void *ctx, const double *dx, double alpha)
{
    chain *c = ctx;
    for (int i = 0; i < N; i++)
        c->x[i] = c->x0[i] - alpha * dx[i];
    if (c->never)
        return alpha == 0;
    return admissible(c);
}

static const cf_mech_ops ops = {residual, tangent, project, save, trial, NULL};

/* A chain with its equilibrium x*_i = 1 + 0.4 sin(i) (x*_0 = 0, held) and the loads that make it. */
static void make(chain *c, double a, double b, double k)
{
    memset(c, 0, sizeof *c);
    c->a = a, c->b = b, c->k = k;
    for (int i = 1; i < N; i++)
        c->xs[i] = 1 + 0.4 * sin(i);
    grad(c, c->xs, c->f);
}

static cf_mech setup_mech(chain *c)
{
    int p[N + 1], rows[3 * N];
    pattern(p, rows);
    cf_mech m;
    cf_error err = {0};
    assert_int_equal(cf_mech_create(&m, N, 0, &ops, c, p, rows, 0, &err), CF_OK);
    m.tol = 1e-12;
    m.step_tol = 1e-15;
    return m;
}

/* One call of the driver (asserted to return CF_OK), and when conv, x* found to 1e-10. */
static cf_mech_result newton(cf_mech *m, chain *c, int conv)
{
    double r[N], dx[N];
    cf_mech_result res;
    cf_error err = {0};
    assert_int_equal(cf_mech_newton(m, r, dx, &res, &err), CF_OK);
    assert_int_equal(res.conv, conv);
    for (int i = 0; conv && i < N; i++)
        assert_true(fabs(c->x[i] - c->xs[i]) <= 1e-10);
    return res;
}

static void finds_the_known_equilibrium_through_admissible_states(void **state)
{
    (void)state;
    for (int chord = 1; chord >= 0; chord--) {
        chain c;
        make(&c, 1, 0.01, 0.5);
        /* from rest the first full step is x = K^-1 f with K of the springs and b alone: far
        ** past XMAX, so the driver must halve it */
        cf_mech m = setup_mech(&c);
        if (!chord)
            m.chord_rate = 0;
        cf_mech_result res = newton(&m, &c, 1);
        assert_int_equal(res.inadmissible, 0);
        assert_true(admissible(&c));
        assert_int_equal(res.neg_pivots, 0); /* a stable equilibrium */
        print_message("chord rate %s: %d steps, %d fresh tangents\n", chord ? "1/4" : "0",
                      res.iters, res.factorizations);
        assert_true(res.iters > 3);
        if (chord)
            assert_true(res.factorizations < res.iters);
        else
            assert_int_equal(res.factorizations, res.iters);
        /* a second call from the equilibrium converges at once */
        res = newton(&m, &c, 1);
        assert_int_equal(res.iters, 0);
        cf_mech_free(&m);
    }
}

static void reports_the_inertia_of_an_unstable_state(void **state)
{
    (void)state;
    chain c;
    make(&c, 1, -1, 0.1); /* a double well per unknown, weakly coupled */
    for (int i = 1; i < N; i++)
        c.x[i] = 0.05; /* near the hump: every free unknown's curvature about -1 */
    cf_mech m = setup_mech(&c);
    m.max_iter = 1;
    cf_mech_result res = newton(&m, &c, 0);
    assert_int_equal(res.factorizations, 1);
    /* the held unknown's diagonal 1 is the one positive eigenvalue: -1 + 0.0075 + 0.1 (2 - 2 cos)
    ** stays below 0 for the others */
    assert_int_equal(res.neg_pivots, N - 1);
    /* from near the well's bottom the driver finds x* and sees it stable */
    for (int i = 1; i < N; i++)
        c.x[i] = c.xs[i] + 0.2;
    m.max_iter = 200;
    m.fresh = 1;
    res = newton(&m, &c, 1);
    assert_int_equal(res.neg_pivots, 0);
    cf_mech_free(&m);
}

static void a_system_that_admits_no_step_is_left_where_it_was(void **state)
{
    (void)state;
    chain c;
    make(&c, 1, 0.01, 0.5);
    c.never = 1;
    for (int i = 1; i < N; i++)
        c.x[i] = 0.5;
    double start[N];
    memcpy(start, c.x, sizeof start);
    cf_mech m = setup_mech(&c);
    cf_mech_result res = newton(&m, &c, 0);
    assert_int_equal(res.inadmissible, 1);
    assert_int_equal(res.iters, 1);
    assert_memory_equal(c.x, start, sizeof start);
    cf_mech_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(finds_the_known_equilibrium_through_admissible_states),
        cmocka_unit_test(reports_the_inertia_of_an_unstable_state),
        cmocka_unit_test(a_system_that_admits_no_step_is_left_where_it_was),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
