/*
** Yeoh's and one-term Ogden's nominal stress in the test modes (see hyperelastic.h).
*/
#include "fit/hyperelastic.h"
#include "model/mode.h"

#include <math.h>

const char *cf_hyper_unfit(const cf_table *t)
{
    if (t->kind == CF_TABLE_FORCE_DISPLACEMENT)
        return "a force-displacement table has no stretch (x is a displacement, and the "
               "specimen's length and section are not known)";
    const cf_mode_row *row = cf_mode_row_of(t->mode);
    if (row && !(row->q > 0))
        return row->no_incompressible;
    int strained = 0;
    for (size_t i = 0; i < t->count; i++) {
        if (!cf_hyper_in_domain(t->mode, t->x[i]))
            return "a strain at or below -1 has no positive stretch";
        strained = strained || t->x[i] != 0;
    }
    return strained ? NULL : "no row is strained";
}

int cf_hyper_in_domain(cf_mode m, double x)
{
    return isfinite(x) && (cf_mode_row_of(m)->any_sign || x > -1);
}

void cf_yeoh_basis(cf_mode m, double x, double g[3])
{
    const double l = 1 + x;
    double s, j; /* s: P per unit W'(I1); j = I1 - 3, both factored to keep small strains exact */
    switch (m) {
    case CF_MODE_SHEAR:
        s = 2 * x;
        j = x * x;
        break;
    case CF_MODE_PLANAR: {
        const double d = x * (2 + x); /* lambda^2 - 1 */
        s = 2 * d * (l * l + 1) / (l * l * l);
        j = (d / l) * (d / l);
        break;
    }
    case CF_MODE_EQUIBIAXIAL: {
        const double d = x * (2 + x), l2 = l * l;
        s = 2 * x * (l2 + l + 1) * (l2 * l + 1) / (l2 * l2 * l);
        j = (d / l2) * (d / l2) * (2 * l2 + 1);
        break;
    }
    default: /* uniaxial */
        s = 2 * x * (l * l + l + 1) / (l * l);
        j = x * x * (3 + x) / l;
        break;
    }
    g[0] = s;
    g[1] = 2 * s * j;
    g[2] = 3 * s * j * j;
}

double cf_ogden_log_stretch(cf_mode m, double x)
{
    return cf_mode_row_of(m)->any_sign ? asinh(0.5 * x) : log1p(x);
}

double cf_ogden_basis(cf_mode m, double L, double alpha)
{
    if (cf_mode_row_of(m)->any_sign) /* (2/alpha) sinh(alpha a) / cosh(a) */
        return (alpha != 0 ? 2 * sinh(alpha * L) / alpha : 2 * L) / cosh(L);
    /* (2/alpha) (lambda^(alpha - 1) - lambda^(-q alpha - 1)) with the mode's q: 1/2, 1, 2 */
    const double q = cf_mode_row_of(m)->q;
    const double a = (-q * alpha - 1) * L, b = (1 + q) * alpha * L;
    if (alpha == 0)
        return 2 * (1 + q) * L * exp(-L);
    if (fabs(b) <= 1) /* the two powers close: their difference as exp(a) expm1(b) */
        return 2 * exp(a) * expm1(b) / alpha;
    return 2 * (exp(a + b) - exp(a)) / alpha;
}
