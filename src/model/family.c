/*
** The identifiable family of a conical spring (see family.h).
*/
#include "model/family.h"

#include <math.h>

cf_ident cf_ident_of_type(const cf_spring *p, cf_spring_type type, int force_displacement)
{
    const double lmin = type == CF_TELESCOPING ? p->d_mm : p->n * p->d_mm;
    const double s = p->H_mm - p->H_tail_mm - lmin; /* the cone's travel (a tail's H_tail apart) */
    const double D1 = p->D1_mm, d = p->d_mm;
    const double FC = p->G_MPa * d * d * d * d * s / (8 * p->n * D1 * D1 * D1);
    cf_ident q;
    q.rho = D1 / p->D2_mm;
    q.solid = force_displacement ? s : s / p->H_mm;
    q.scale = force_displacement ? FC : FC / (p->H_mm * p->H_mm);
    return q;
}

cf_ident cf_ident_of(const cf_spring *p, int force_displacement)
{
    cf_law law;
    cf_spring_type type = CF_NON_TELESCOPING;
    if (cf_law_init(&law, p, NULL) == CF_OK)
        type = law.type;
    return cf_ident_of_type(p, type, force_displacement);
}

cf_spring cf_ident_member(const cf_ident *q)
{
    const double rho = q->rho, e = q->solid, A = q->scale;
    /* non-telescoping with n = 2, d = L_min/2 and D2 = L_min/(1 - rho), so that (D2 - D1)/2 =
    ** L_min/2 stays below n d = L_min */
    const double H = 1.0, Lmin = H * (1 - e), s = H * e, n = 2.0, dw = Lmin / n;
    const double D2 = rho < 1 ? Lmin / (1 - rho) : Lmin, D1 = rho * D2;
    cf_spring p = {D1, D2, n, dw, cf_ident_G_of_FC(A * H * H, n, D1, dw, s), H};
    return p;
}

cf_spring cf_ident_member_tail(const cf_ident *q, double tau)
{
    const double rho = q->rho, e = q->solid, A = q->scale, n = 2.0;
    /* the room past the cone's closing strain e (1 + tau): a small share holds the solid
    ** lengths n d (1 + tau), the tail's travel takes the rest, so its gap per coil exceeds the
    ** cone's and the whole travel nearly reaches the free length */
    const double room = 1.0 - e * (1 + tau), solids = CF_IDENT_TAIL_SOLIDS * room;
    const double dw = solids / (n * (1 + tau)), Lmin = n * dw;
    const double D2 = rho < 1 ? Lmin / (1 - rho) : Lmin, D1 = rho * D2;
    cf_spring p = {D1, D2, n, dw, cf_ident_G_of_FC(A, n, D1, dw, e), 1.0};
    p.n_tail = tau * n;
    p.H_tail_mm = p.n_tail * dw + (1.0 - e - solids);
    return p;
}

double cf_ident_G_of_FC(double F_C_N, double n, double D1_mm, double d_mm, double s_mm)
{
    const double d2 = d_mm * d_mm;
    return 8 * n * D1_mm * D1_mm * D1_mm * F_C_N / (d2 * d2 * s_mm);
}

double cf_ident_rho_hi(cf_spring_type type, double index_max)
{
    return type == CF_TELESCOPING ? index_max / (index_max + 4) * (1 - 1e-6) : 1.0;
}

/* ---- the design limits in the family's space ------------------------------------------------- */

/* With c = D1/d and H a pure scale:
**   non-telescoping (d = (1 - B) H/n): G = 8 n^2 c^3 A/(B (1 - B)), D2/H = c (1 - B)/(n rho),
**     type n > c (1 - rho)/(2 rho): every limit is easiest at c = 3, so the family can be placed
**     iff n_lo = max(n_min, 3 (1 - rho)/(2 rho), 3 (1 - B)/(D2max rho)) <= n_max, and then carries
**     at most A_max = G_max B (1 - B)/(8 * 27 n_lo^2);
**   telescoping (d = (1 - B) H): G = 8 n c^3 A/(B (1 - B)), D2/H = c (1 - B)/rho, type
**     n <= c (1 - rho)/(2 rho): easiest at n = n_min, so iff
**     c_lo = max(3, 2 n_min rho/(1 - rho)) <= c_hi = min(index_max, D2max rho/(1 - B)), and then
**     A_max = G_max B (1 - B)/(8 n_min c_lo^3). */
cf_ident_region cf_ident_region_at(const cf_ident_design *o, cf_spring_type type, double rho,
                                   double B, double inside)
{
    cf_ident_region r = {-1.0, INFINITY, 0, 0};
    if (!(rho > 0 && rho < 1 && B > 0 && B < 1)) {
        r.margin = 50;
        return r;
    }
    const double nmin = o->n_min, nmax = o->n_max, Gmax = o->G_max_MPa;
    const double Dr = o->D2_over_H_max, cmin = 3.0, cmax = o->index_max;
    if (type == CF_TELESCOPING) {
        double c_type = 2 * nmin * rho / (1 - rho), c_D = Dr * rho / (1 - B);
        double c_lo = fmax(cmin, c_type), c_hi = fmin(cmax, c_D);
        r.lo_bit = c_type > cmin ? CF_C_TYPE : CF_C_INDEX_MIN;
        r.hi_bit = c_D < cmax ? CF_C_D2_H : CF_C_INDEX_MAX;
        r.margin = log(c_lo) - log(c_hi);
        r.A_max = Gmax * B * (1 - B) / (8 * nmin * c_lo * c_lo * c_lo);
    } else {
        double n_type = cmin * (1 - rho) / (2 * rho) * (1 + 1e-6);
        double n_D = cmin * (1 - B) / (Dr * rho);
        double n_lo = fmax(nmin, fmax(n_type, n_D));
        r.lo_bit = n_lo == nmin ? CF_C_COILS : n_lo == n_type ? CF_C_TYPE : CF_C_D2_H;
        r.hi_bit = CF_C_COILS_MAX;
        r.margin = log(n_lo) - log(nmax);
        r.A_max = Gmax * B * (1 - B) / (8 * cmin * cmin * cmin * n_lo * n_lo);
    }
    r.A_max *= 1 - inside;
    double m_rho = log(o->rho_min * (1 - CF_IDENT_RHO_MIN_TOL)) - log(rho);
    if (m_rho > r.margin) {
        r.margin = m_rho;
        r.lo_bit = CF_C_RHO_MIN;
        r.hi_bit = 0;
    }
    if (!isfinite(r.margin))
        r.margin = 50;
    return r;
}

/* ---- the family's curve --------------------------------------------------------------------- */

/* The canonical spring: D1 = rho, D2 = 1, n = 2, d = 0.5 (non-telescoping, L_min = 1), H = 2,
** G = 256 rho^3. */
cf_status cf_ident_canon_law(double rho, cf_law *law)
{
    cf_spring p = {rho, 1.0, 2.0, 0.5, 256.0 * rho * rho * rho, 2.0};
    return cf_law_init(law, &p, NULL);
}

double cf_ident_canon_transition(double rho)
{
    /* as cf_law_init: u_T = min(s shape/4, s) with s = 1 */
    return fmin((1.0 + rho) * (1.0 + rho * rho) * 0.25, 1.0);
}

double cf_ident_reduced(const cf_law *canon, double A, double B, double x, double *dB)
{
    double k;
    double t = x / B;
    double g = cf_law_force(canon, CF_LAW_CLOSED, t, &k, NULL);
    if (dB)
        *dB = -A * k * t / B;
    return A * g;
}
