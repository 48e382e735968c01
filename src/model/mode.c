/*
** The test modes as a table (mode.h).
*/
#include "model/mode.h"

#include <stdio.h>
#include <string.h>

#define YEOH_TAIL "(C1 + 2 C2 (I1 - 3) + 3 C3 (I1 - 3)^2), "

static const cf_mode_row rows[CF_MODE_COUNT] = {
    [CF_MODE_UNIAXIAL] = {
        .name = "uniaxial",
        .deformation = "stretched along z, free to contract along x and y",
        .strain_mask = 4u, .free_mask = 3u, .shear_i = -1, .shear_j = -1,
        .zero = 0, .si = 2, .sj = 2, .any_sign = 0, .spring_curve = 1,
        .cauchy_over_stretch = 1, .cauchy_words = "P = sigma / (1 + strain), incompressible uniaxial",
        .q = 0.5,
        .yeoh = "y = 2 (l - l^-2) " YEOH_TAIL "I1 = l^2 + 2/l, l = 1 + x",
        .ogden = "y = (2 mu / alpha) (l^(alpha - 1) - l^(-alpha/2 - 1)), l = 1 + x",
        .x_quantity = "engineering strain", .x_short = "strain"},
    [CF_MODE_SHEAR] = {
        .name = "shear",
        .deformation = "simple shear: x displaced by the amount of shear times z",
        .strain_mask = 0u, .free_mask = 0u, .shear_i = 0, .shear_j = 2,
        .zero = -1, .si = 0, .sj = 2, .any_sign = 1, .spring_curve = 0,
        .cauchy_over_stretch = 0,
        .cauchy_words = "(simple shear: P12 = sigma12, the sheared face keeps its area)",
        .q = 1.0,
        .yeoh = "y = 2 x (C1 + 2 C2 x^2 + 3 C3 x^4)",
        .ogden = "y = (2 mu / alpha) sinh(alpha a) / cosh(a), a = asinh(x/2)",
        .x_quantity = "amount of shear", .x_short = "amount of shear"},
    [CF_MODE_PLANAR] = {
        .name = "planar",
        .deformation = "pure shear: stretched along x, held along y, free along z",
        .strain_mask = 1u, .free_mask = 4u, .shear_i = -1, .shear_j = -1,
        .zero = 2, .si = 0, .sj = 0, .any_sign = 0, .spring_curve = 0,
        .cauchy_over_stretch = 1, .cauchy_words = "P = sigma / (1 + strain), incompressible planar",
        .q = 1.0,
        .yeoh = "y = 2 (l - l^-3) " YEOH_TAIL "I1 = l^2 + 1 + l^-2, l = 1 + x",
        .ogden = "y = (2 mu / alpha) (l^(alpha - 1) - l^(-alpha - 1)), l = 1 + x",
        .x_quantity = "engineering strain", .x_short = "strain"},
    [CF_MODE_EQUIBIAXIAL] = {
        .name = "equibiaxial",
        .deformation = "stretched equally along x and y, free along z",
        .strain_mask = 3u, .free_mask = 4u, .shear_i = -1, .shear_j = -1,
        .zero = 2, .si = 0, .sj = 0, .any_sign = 0, .spring_curve = 0,
        .cauchy_over_stretch = 1,
        .cauchy_words = "P = sigma / (1 + strain), incompressible equibiaxial",
        .q = 2.0,
        .yeoh = "y = 2 (l - l^-5) " YEOH_TAIL "I1 = 2 l^2 + l^-4, l = 1 + x",
        .ogden = "y = (2 mu / alpha) (l^(alpha - 1) - l^(-2 alpha - 1)), l = 1 + x",
        .x_quantity = "engineering strain", .x_short = "strain"},
    [CF_MODE_CONFINED] = {
        .name = "confined",
        .deformation = "confined compression: stretched along z, held along x and y",
        .strain_mask = 4u, .free_mask = 0u, .shear_i = -1, .shear_j = -1,
        .zero = -1, .si = 2, .sj = 2, .any_sign = 0, .spring_curve = 0,
        .cauchy_over_stretch = 0,
        .cauchy_words = "(confined: P = sigma, the lateral stretches are 1)",
        .q = 0.0,
        .no_incompressible = "confined compression holds the lateral stretches, which an "
                             "incompressible solid cannot follow",
        .x_quantity = "engineering strain", .x_short = "strain"},
    [CF_MODE_BIAXIAL] = {
        .name = "biaxial",
        .deformation = "stretched along x and y at a fixed ratio of strains, free along z",
        .strain_mask = 3u, .free_mask = 4u, .shear_i = -1, .shear_j = -1,
        .zero = 2, .si = 0, .sj = 0, .any_sign = 0, .spring_curve = 0,
        .cauchy_over_stretch = 1,
        .cauchy_words = "P = sigma / (1 + strain) along each direction, incompressible biaxial",
        .q = 0.0,
        .no_incompressible = "a biaxial test at a ratio other than 1:1 has two loaded stretches, "
                             "which the one-stretch incompressible forms do not follow",
        .x_quantity = "engineering strain", .x_short = "strain"},
};

const cf_mode_row *cf_mode_row_of(cf_mode m)
{
    return (int)m >= 0 && m < CF_MODE_COUNT ? &rows[m] : NULL;
}

const char *cf_mode_name(cf_mode m)
{
    const cf_mode_row *r = cf_mode_row_of(m);
    return r ? r->name : "?";
}

cf_status cf_mode_parse(const char *name, cf_mode *m, cf_error *err)
{
    for (int k = 0; name && k < CF_MODE_COUNT; k++)
        if (strcmp(name, rows[k].name) == 0) {
            *m = (cf_mode)k;
            return CF_OK;
        }
    return cf_error_set(err, CF_E_DATA, "mode '%s': expected %s", name ? name : "(none)",
                        cf_mode_list());
}

const char *cf_mode_list(void)
{
    /* the rows' names in order (tests/unit/test_cell.c checks it against the rows) */
    return "uniaxial, shear, planar, equibiaxial, confined or biaxial";
}

void cf_mode_place(cf_mode m, double e, double a, double F[9])
{
    cf_mode_place_k(m, e, a, 1.0, F);
}

void cf_mode_place_k(cf_mode m, double e, double a, double k, double F[9])
{
    memset(F, 0, 9 * sizeof(double));
    F[0] = F[4] = F[8] = 1;
    const cf_mode_row *r = cf_mode_row_of(m);
    if (!r)
        return;
    for (int i = 0; i < 3; i++) {
        if (r->free_mask & (1u << i))
            F[4 * i] = a;
        if (r->strain_mask & (1u << i))
            F[4 * i] = 1 + e;
    }
    if (r->shear_i >= 0)
        F[3 * r->shear_i + r->shear_j] = e;
    if (m == CF_MODE_BIAXIAL)
        F[4] = 1 + k * e;
}
