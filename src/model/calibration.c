/*
** Family weights of the cubic lattice from its Cauchy-Born elastic constants (see calibration.h).
*/
#include "model/calibration.h"

#include <math.h>
#include <string.h>

/* Axial stiffness per unit k0 of one spring of each family: the strain form of the law divides
** the stiffness by L0 / H (sqrt 2 for a face diagonal, sqrt 3 for a body diagonal). */
static void family_stiffness(const double w[CF_FAMILY_COUNT], double *ke, double *kf, double *kb)
{
    *ke = w[CF_FAMILY_EDGE];
    *kf = w[CF_FAMILY_FACE] / sqrt(2.0);
    *kb = w[CF_FAMILY_BODY] / sqrt(3.0);
}

cf_cubic_moduli cf_cubic_moduli_of(const double w[CF_FAMILY_COUNT])
{
    double ke, kf, kb;
    family_stiffness(w, &ke, &kf, &kb);
    cf_cubic_moduli m;
    m.C11 = ke + 2 * kf + 4 * kb / 3;
    m.C12 = m.C44 = kf + 4 * kb / 3;
    m.E = (m.C11 - m.C12) * (m.C11 + 2 * m.C12) / (m.C11 + m.C12);
    m.nu = m.C12 / (m.C11 + m.C12);
    m.zener = m.C11 > m.C12 ? 2 * m.C44 / (m.C11 - m.C12) : INFINITY;
    return m;
}

double cf_cubic_q_of_zener(double zener)
{
    /* weights {1, q, q}: ke = 1, kf = q/sqrt 2, kb = q/sqrt 3, so with C11 - C12 = ke + kf and
    ** C44 = kf + 4 kb/3 the ratio is a q/(1 + q/sqrt 2), a = 2 (1/sqrt 2 + 4/(3 sqrt 3)) */
    double ke, kf, kb;
    family_stiffness((const double[CF_FAMILY_COUNT]){1, 1, 1}, &ke, &kf, &kb);
    const double a = 2 * (kf + 4 * kb / 3), q = zener * ke / (a - zener * kf);
    return zener > 0 && q > 0 && isfinite(q) ? q : NAN;
}

cf_status cf_calibration_weights(cf_calibration c, double w[CF_FAMILY_COUNT], cf_error *err)
{
    if (c == CF_CAL_ISOTROPIC) {
        /* Face = body = 1 gives the shape; k_e = k_f + 8 k_b / 3 makes it isotropic; then scale. */
        double u[CF_FAMILY_COUNT] = {0, 1, 1};
        double ke, kf, kb;
        family_stiffness(u, &ke, &kf, &kb);
        u[CF_FAMILY_EDGE] = kf + 8 * kb / 3;
        double E = cf_cubic_moduli_of(u).E;
        for (int f = 0; f < CF_FAMILY_COUNT; f++)
            w[f] = u[f] / E;
        return CF_OK;
    }
    if (c == CF_CAL_AXIAL) {
        double u[CF_FAMILY_COUNT] = {1, 1, 1};
        double E = cf_cubic_moduli_of(u).E;
        for (int f = 0; f < CF_FAMILY_COUNT; f++)
            w[f] = 1 / E;
        return CF_OK;
    }
    return cf_error_set(err, CF_E_DATA,
                        "calibration '%s' has no weights of its own (they are fitted or given)",
                        cf_calibration_name(c));
}

cf_status cf_calibration_check(const double w[CF_FAMILY_COUNT], cf_error *err)
{
    for (int f = 0; f < CF_FAMILY_COUNT; f++)
        if (!isfinite(w[f]) || !(w[f] >= 0))
            return cf_error_set(err, CF_E_DATA,
                                "lattice.weights.%s = %g: must be finite and >= 0",
                                cf_family_name(f), w[f]);
    if (!(w[CF_FAMILY_EDGE] > 0) && !(w[CF_FAMILY_FACE] > 0) && !(w[CF_FAMILY_BODY] > 0))
        return cf_error_set(err, CF_E_DATA, "lattice.weights: every family has weight 0");
    return CF_OK;
}

const char *cf_calibration_name(cf_calibration c)
{
    switch (c) {
    case CF_CAL_ISOTROPIC: return "isotropic";
    case CF_CAL_AXIAL: return "axial";
    case CF_CAL_FITTED: return "fitted";
    case CF_CAL_CUSTOM: return "custom";
    }
    return "?";
}

cf_status cf_calibration_parse(const char *name, cf_calibration *c, cf_error *err)
{
    static const cf_calibration all[] = {CF_CAL_ISOTROPIC, CF_CAL_AXIAL, CF_CAL_FITTED};
    for (size_t i = 0; name && i < sizeof all / sizeof all[0]; i++)
        if (strcmp(name, cf_calibration_name(all[i])) == 0) {
            *c = all[i];
            return CF_OK;
        }
    return cf_error_set(err, CF_E_DATA, "calibration '%s': expected isotropic, axial or fitted",
                        name ? name : "(not a string)");
}

const char *cf_family_name(int family)
{
    static const char *const names[CF_FAMILY_COUNT] = {"edge", "face", "body"};
    return family >= 0 && family < CF_FAMILY_COUNT ? names[family] : "?";
}

double cf_cubic_kappa_of_nu(const double w[CF_FAMILY_COUNT], double k0_over_H, double nu)
{
    const cf_cubic_moduli cm = cf_cubic_moduli_of(w);
    return (nu * (cm.C11 + cm.C12) - cm.C12) / (1 - 2 * nu) * k0_over_H;
}

double cf_cubic_nu_of_kappa(const double w[CF_FAMILY_COUNT], double k0_over_H, double kappa)
{
    const cf_cubic_moduli cm = cf_cubic_moduli_of(w);
    const double k = kappa / k0_over_H;
    return (cm.C12 + k) / (cm.C11 + cm.C12 + 2 * k);
}
