/*
** A conical spring's law from its design parameters (law.h): the parameters checked, the cone's
** and the tail's derived quantities, every one of them checked representable; and the names of
** the evaluation methods. The evaluators themselves are in law.c.
*/
#include "model/law_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- parameter checks and derived quantities ---------------------------------------------- */

static cf_status check_positive(const char *name, double v, cf_error *err)
{
    if (!isfinite(v))
        return cf_error_set(err, CF_E_DATA, "parameter %s = %g is not a finite number", name, v);
    if (v <= 0)
        return cf_error_set(err, CF_E_DATA, "parameter %s = %.17g must be > 0", name, v);
    return CF_OK;
}

/* The design parameters' own checks: each > 0 (check_positive), a tail's coils and height
** consistent, D1 <= D2 and at least two active coils. */
static cf_status check_params(const cf_spring *p, int tail, cf_error *err)
{
    cf_status st;
    for (int k = 0; k < CF_P_COUNT; k++)
        if ((st = check_positive(cf_spring_param_info(k)->key, cf_spring_get(p, k), err)) !=
            CF_OK)
            return st;
    if (tail) {
        if (!isfinite(p->n_tail) || p->n_tail < 0)
            return cf_error_set(err, CF_E_DATA,
                                "parameter n_tail = %.17g must be a finite number >= 0", p->n_tail);
        if (!isfinite(p->H_tail_mm) || p->H_tail_mm < 0)
            return cf_error_set(err, CF_E_DATA,
                                "parameter H_tail_mm = %.17g must be a finite number >= 0",
                                p->H_tail_mm);
        if (p->n_tail == 0)
            return cf_error_set(err, CF_E_DATA,
                                "parameter H_tail_mm = %.17g is given for a spring with no tail "
                                "coils (n_tail = 0)",
                                p->H_tail_mm);
        if (!(p->H_tail_mm > p->n_tail * p->d_mm))
            return cf_error_set(err, CF_E_DATA,
                                "parameter H_tail_mm = %.17g leaves no room for the tail's solid "
                                "length n_tail d = %.17g mm",
                                p->H_tail_mm, p->n_tail * p->d_mm);
    }
    if (p->D1_mm > p->D2_mm)
        return cf_error_set(err, CF_E_DATA,
                            "parameter D1_mm = %.17g must not exceed D2_mm = %.17g", p->D1_mm,
                            p->D2_mm);
    if (p->n < 2)
        return cf_error_set(err, CF_E_DATA, "parameter n = %.17g must be >= 2 active coils",
                            p->n);
    return CF_OK;
}

/* The cone: its type, lengths, loads and the closed form's constants (law.md). */
static cf_status init_cone(cf_law *law, const cf_spring *p, int tail, cf_error *err)
{
    law->p = *p;
    const double dD = p->D2_mm - p->D1_mm; /* exact when D1 and D2 are close (Sterbenz) */
    const double nd = p->n * p->d_mm;
    law->type = (0.5 * dD >= nd) ? CF_TELESCOPING : CF_NON_TELESCOPING;
    law->L_min_mm = (law->type == CF_TELESCOPING) ? p->d_mm : nd;
    law->travel_mm = p->H_mm - p->H_tail_mm - law->L_min_mm;
    if (tail && !(law->travel_mm > 0))
        return cf_error_set(err, CF_E_DATA,
                            "parameter H_tail_mm = %.17g leaves the cone no travel: H - H_tail - "
                            "L_min = %.17g - %.17g - %.17g mm must be > 0",
                            p->H_tail_mm, p->H_mm, p->H_tail_mm, law->L_min_mm);
    if (!(law->travel_mm > 0))
        return cf_error_set(err, CF_E_DATA,
                            "travel to solid H - L_min = %.17g - %.17g = %.17g mm must be > 0 "
                            "(%s spring, H_mm too short)",
                            p->H_mm, law->L_min_mm, law->travel_mm,
                            cf_spring_type_name(law->type));
    law->L_max_mm = p->H_mm + law->travel_mm;

    const double s = law->travel_mm;
    const double rho = p->D1_mm / p->D2_mm;
    const double c1 = p->D1_mm / p->d_mm; /* spring index */
    const double c2 = p->D2_mm / p->d_mm;
    law->rho = rho;
    law->rho_inv_m1 = dD / p->D1_mm;
    law->index_c = c1;
    /* F_C = G d^4 s/(8 n D1^3) written as G s d/(8 n c^3) so that d^4 cannot overflow. */
    law->F_C_N = p->G_MPa * s * p->d_mm / (8.0 * p->n * c1 * c1 * c1);
    law->F_T_N = p->G_MPa * s * p->d_mm / (8.0 * p->n * c2 * c2 * c2);
    const double shape = (1.0 + rho) * (1.0 + rho * rho); /* (D1+D2)(D1^2+D2^2)/D2^3 */
    law->k0_N_per_mm = p->G_MPa * p->d_mm / (2.0 * p->n * c2 * c2 * c2 * shape);
    law->u_T_mm = fmin(s * shape * 0.25, s);
    law->inv_travel = 1.0 / s;
    law->k_scale = 4.0 * law->F_C_N * law->rho_inv_m1 / s;
    /* 1 - u_T/s = (1 - rho)(3 + 2 rho + rho^2)/4 with 1 - rho = (D2 - D1)/D2 */
    law->w_T = sqrt((dD / p->D2_mm) * (3.0 + 2.0 * rho + rho * rho) * 0.25);

    law->cone_travel_mm = s;
    law->u_C_mm = s;
    law->F_solid_N = law->F_C_N;
    return CF_OK;
}

/* The tail in series with the cone (law.md): its stiffness, the law's new ends and constants. */
static cf_status init_tail(cf_law *law, const cf_spring *p, cf_error *err)
{
    const double s = law->travel_mm, rho = law->rho, dD = p->D2_mm - p->D1_mm;
    const double c1 = law->index_c;
    /* the tail: k_t = G d^4/(8 n_t D1^3) = G d/(8 n_t c^3), in series with the cone */
    const double nt = p->n_tail, s_t = p->H_tail_mm - nt * p->d_mm;
    if (!(s_t / nt > s / p->n))
        return cf_error_set(err, CF_E_DATA,
                            "parameter H_tail_mm = %.17g closes the tail before the cone: its "
                            "gap per coil (H_tail - n_tail d)/n_tail = %.17g mm must exceed "
                            "the cone's s/n = %.17g mm",
                            p->H_tail_mm, s_t / nt, s / p->n);
    const double kc = law->k0_N_per_mm;
    law->tail = 1;
    law->k_tail_N_per_mm = p->G_MPa * p->d_mm / (8.0 * nt * c1 * c1 * c1);
    law->tau = nt / p->n;
    law->beta = law->rho_inv_m1 * law->tau;
    law->u_C_mm = s + law->F_C_N / law->k_tail_N_per_mm;
    law->F_solid_N = law->k_tail_N_per_mm * s_t;
    law->k0_N_per_mm = kc * law->k_tail_N_per_mm / (kc + law->k_tail_N_per_mm);
    law->u_T_mm += law->F_T_N / law->k_tail_N_per_mm;
    law->L_min_mm += nt * p->d_mm;
    law->travel_mm = s + s_t;
    law->L_max_mm = p->H_mm + law->travel_mm;
    /* (u_C - u_T)/s = (1 - rho)(3 + 2 rho + rho^2)/4 + tau (1 - rho)(1 + rho + rho^2) */
    const double omr = dD / p->D2_mm;
    law->w_T = sqrt(omr * ((3.0 + 2.0 * rho + rho * rho) * 0.25 +
                           law->tau * (1.0 + rho + rho * rho)));
    return CF_OK;
}

/* Every derived quantity must be a finite number (and > 0 but for three that may be 0): named
** in the refusal, never shown as NaN or Inf. */
static cf_status check_derived(const cf_law *law, const cf_spring *p, cf_error *err)
{
    const struct {
        const char *name;
        double v;
        int may_be_zero;
    } derived[] = {{"rho = D1/D2", law->rho, 0},
                   {"1/rho - 1", law->rho_inv_m1, 1},
                   {"the spring index D1/d", law->index_c, 0},
                   {"L_max (full stretch, mm)", law->L_max_mm, 0},
                   {"F_C (the cone's solid load, N)", law->F_C_N, 0},
                   {"F_T (the transition load, N)", law->F_T_N, 0},
                   {"k0 (the linear stiffness, N/mm)", law->k0_N_per_mm, 0},
                   {"u_T (the end of the linear region, mm)", law->u_T_mm, 0},
                   {"1/travel (1/mm)", law->inv_travel, 0},
                   {"the stiffness scale 4 F_C (1/rho - 1)/s (N/mm)", law->k_scale, 1},
                   {"w_T", law->w_T, 1},
                   {"u_C (mm)", law->u_C_mm, 0},
                   {"F_solid (N)", law->F_solid_N, 0},
                   {"the travel to solid (mm)", law->travel_mm, 0}};
    char sp[160];
    for (size_t i = 0; i < sizeof derived / sizeof derived[0]; i++) {
        const double v = derived[i].v;
        if (isfinite(v) && (v > 0 || (derived[i].may_be_zero && v == 0)))
            continue;
        char what[64];
        if (isnan(v))
            snprintf(what, sizeof what, "cannot be computed in floating point");
        else if (isinf(v))
            snprintf(what, sizeof what, "overflows floating point");
        else if (v == 0)
            snprintf(what, sizeof what, "underflows to 0");
        else
            snprintf(what, sizeof what, "= %g, not > 0", v);
        return cf_error_set(err, CF_E_DATA,
                            "spring %s is outside the range where its loads can be "
                            "represented: %s %s",
                            cf_spring_text(p, 6, 1, sp, sizeof sp), derived[i].name, what);
    }
    return CF_OK;
}

cf_status cf_law_init(cf_law *law, const cf_spring *p, cf_error *err)
{
    cf_status st;
    memset(law, 0, sizeof *law);
    const int tail = p->n_tail != 0 || p->H_tail_mm != 0;
    if ((st = check_params(p, tail, err)) != CF_OK || (st = init_cone(law, p, tail, err)) != CF_OK ||
        (tail && (st = init_tail(law, p, err)) != CF_OK))
        return st;
    return check_derived(law, p, err);
}

cf_status cf_law_method_parse(const char *name, cf_law_method *method, cf_error *err)
{
    static const struct { const char *name; cf_law_method m; } map[] = {
        {"exact", CF_LAW_EXACT}, {"closed", CF_LAW_CLOSED},
        {"closed+newton", CF_LAW_CLOSED_NEWTON}, {"table", CF_LAW_TABLE}};
    for (size_t i = 0; i < sizeof map / sizeof map[0]; i++)
        if (name && strcmp(name, map[i].name) == 0) {
            *method = map[i].m;
            return CF_OK;
        }
    return cf_error_set(err, CF_E_DATA,
                        "unknown method '%s' (expected exact, closed, closed+newton or table)",
                        name ? name : "(null)");
}

const char *cf_law_method_name(cf_law_method method)
{
    switch (method) {
    case CF_LAW_EXACT: return "exact";
    case CF_LAW_CLOSED: return "closed";
    case CF_LAW_CLOSED_NEWTON: return "closed+newton";
    case CF_LAW_TABLE: return "table";
    }
    return "unknown";
}

