/*
** The law's structure, private to the library (the public header src/include/conifit/law.h keeps
** cf_law opaque): the conical spring's derived quantities, its tail, the double-acting pair's
** extension spring, and a law of another kind (model/lawmech.h) as its mechanics row and its
** quantities. Every evaluation goes through law.h's entry points (cf_law_force, cf_law_force_many,
** cf_law_deflection, cf_law_travel), which dispatch to the row for a law of another kind; the
** conical fields below are read directly only by the conical law's own fast paths.
*/
#ifndef CF_MODEL_LAW_INTERNAL_H
#define CF_MODEL_LAW_INTERNAL_H

#include "conifit/law.h"

#include "model/lawmech.h"

/* The law's table of region 2 (cf_law_table_build, law.c), evaluated by law.c and by the lanes
** (law_simd.h). */
struct cf_law_table {
    size_t intervals;  /* number of grid intervals */
    double w_max;      /* grid spans w in [z0, w_max], w = sqrt((s - |u|)/s) (plain law) */
    double inv_h;      /* intervals / (w_max - z0) */
    double h;          /* (w_max - z0) / intervals */
    double z0, kappa2; /* with a tail the grid variable is z = sqrt((u_C - |u|)/s + kappa^2) from
                       ** z0 = kappa (0 and 0 without a tail). Phi has a minimum at e* < 0
                       ** (y*^4 = 1/(1 - 4 beta)) whose value Phi(e*) ~ -3 beta^2/2 is a branch
                       ** point of e(w) at distance ~ beta from the grid's end: e bends over
                       ** w ~ beta. With kappa^2 = -Phi(e*) / r (r = 1/rho - 1) the branch point sits
                       ** at z = 0 and e(z) is analytic on the grid (Morse's lemma). From
                       ** beta = 0.2 on the minimum lies far away (y* > 1.49) and the grid
                       ** keeps w (kappa = 0): a large kappa would make it uniform in Delta,
                       ** too coarse where y is small */
    double *y;         /* y at the nodes, intervals + 1 values */
    double *dy;        /* dy/dw at the nodes, times h (scaled for the Hermite basis) */
    double *coef;      /* per interval, the Hermite cubic as y0 + q (m0 + q (a + q b)): y0, m0,
                          a, b (4 intervals values; law_simd.h evaluates it) */
};

/* A spring prepared for evaluation: its parameters and every derived quantity. Plain data apart
** from the optional table; build with cf_law_init, release with cf_law_free. */
struct cf_law {
    cf_spring p;
    cf_spring_type type;
    double rho;          /* D1/D2, dimensionless, in (0, 1] */
    double rho_inv_m1;   /* 1/rho - 1 = (D2 - D1)/D1, formed without cancellation */
    double index_c;      /* spring index D1/d, dimensionless */
    double L_min_mm;     /* solid length, mm (the cone's and the tail's n_t d) */
    double L_max_mm;     /* length at full stretch, 2H - L_min, mm */
    double travel_mm;    /* compression to solid, H - L_min, mm (s + s_t with a tail) */
    double F_T_N;        /* transition load (end of region 1), N */
    double F_C_N;        /* load at which the cone is solid (the whole spring without a tail), N */
    double k0_N_per_mm;  /* stiffness of region 1, N/mm (cone and tail in series) */
    double u_T_mm;       /* compression at the transition, mm */
    double inv_travel;   /* 1/s, 1/mm (s the cone's travel) */
    double k_scale;      /* 4 F_C (1/rho - 1)/s, N/mm: region-2 stiffness is k_scale y^4/(1-y^4)
                         ** (k_scale y^4/(1 - y^4 + 4 beta y^4) with a tail) */
    double w_T;          /* sqrt((u_C - u_T)/s): where region 2 starts in the table variable */
    /* the cylindrical tail: without one tail = 0, beta = tau = k_tail = 0, u_C = s and
    ** F_solid = F_C */
    int tail;              /* 1 when the spring has a tail */
    double cone_travel_mm; /* s, the cone's travel: (H - H_tail) - its solid length, mm */
    double k_tail_N_per_mm;/* tail stiffness G d^4/(8 n_t D1^3), N/mm */
    double tau;            /* n_t/n = F_C/(k_tail s), dimensionless */
    double beta;           /* (1/rho - 1) tau, dimensionless */
    double u_C_mm;         /* compression at which the cone closes, s (1 + tau), mm */
    double F_solid_N;      /* force when the whole spring is solid, k_tail s_t (F_C), N */
    struct cf_law_table *table; /* NULL until cf_law_table_build */
    /* The double-acting element (law kind double-acting): a cage of two springs sharing the free
    ** length H, the compression spring (this law) for u >= 0 and the extension spring, which a
    ** stretch compresses, for u < 0: F(u) = -F_e(-u) there, k(u) = k_e(-u). NULL (cf_law_init's
    ** value) for the odd law F(-u) = -F(u). Not owned; its H must be this law's (cf_law_pair).
    ** A pair of equal springs gives the odd law's values bit for bit. */
    const struct cf_law *extension;
    /* A law of another kind (lawmech.h): its mechanics row and quantities; NULL for the conical
    ** laws (conical, conical-tail, double-acting), whose fast paths above are unchanged. For such a
    ** law p is its buildable spring, type its type, travel_mm its compression travel,
    ** travel_stretch_mm its stretch travel, k0_N_per_mm its tangent at u = 0, F_C_N = F_solid_N
    ** its force at the compression travel; u_T_mm = 0, u_C_mm = travel_mm, tail = 0; the other
    ** conical quantities are those of its buildable spring. */
    const cf_law_mech *mech;
    double q[CF_LAW_Q_MAX];
    double travel_stretch_mm;
};

/* The travel to solid on the side of u: the extension spring's for u < 0 when there is one, a
** law kind's stretch travel for u < 0. */
static inline double cf_law_travel_at(const cf_law *law, double u_mm)
{
    if (u_mm < 0 && law->mech)
        return law->travel_stretch_mm;
    return u_mm < 0 && law->extension ? law->extension->travel_mm : law->travel_mm;
}

/* The smaller travel of the two sides (the law's own without an extension spring). */
static inline double cf_law_travel_min(const cf_law *law)
{
    if (law->mech)
        return law->travel_stretch_mm < law->travel_mm ? law->travel_stretch_mm : law->travel_mm;
    return law->extension && law->extension->travel_mm < law->travel_mm
               ? law->extension->travel_mm
               : law->travel_mm;
}

/* Validates p and fills law with the derived quantities (law->table = NULL, law->mech = NULL).
** Refuses non-finite or non-positive values, D1 > D2, n < 2 and a travel <= 0 with CF_E_DATA and a
** message naming the parameter and its value. D1 == D2 (a cylindrical spring) is valid: linear up
** to solid. A tail (n_tail > 0) must leave room for its solid length (H_tail > n_tail d) and the
** cone's (the cone's travel > 0), and close after the cone: its gap per coil
** (H_tail - n_tail d)/n_tail exceeds the cone's s/n; n_tail < 0, a non-finite tail value, or
** H_tail without n_tail is refused. */
cf_status cf_law_init(cf_law *law, const cf_spring *p, cf_error *err);

/* A law of kind mech (lawmech.h) with quantities q[0 .. mech->nq - 1] for a spring of free length
** H_mm: its buildable spring mech->spring(q, H) checked by cf_law_init (its conical quantities
** fill the fields the law kind does not set), then the kind's own travel, tangent and solid force.
** CF_E_DATA naming the kind and the quantity for a non-finite or non-positive quantity, a travel
** that is not in (0, H) or a force that is not finite. */
cf_status cf_law_init_kind(cf_law *law, const cf_law_mech *mech, const double *q, double H_mm,
                           cf_error *err);

/* A law kind's evaluations (law_kind.c), behind cf_law_force, cf_law_force_many and
** cf_law_deflection when law->mech is set: its row's force clamped past each side's travel (flags
** CF_LAW_SOLID there, 0 otherwise), its batch (the row's force_many, or force point by point), and
** the compression at force F by bisection on the row's force (monotone by its tangent >= 0). */
double cf_law_kind_force(const cf_law *law, double u_mm, double *k_N_per_mm, int *flags);
void cf_law_kind_force_many(const cf_law *law, size_t count, const double *u_mm, double *F_N,
                            double *k_N_per_mm);
double cf_law_kind_deflection(const cf_law *law, double F_N);

/* e = 1 - y of region 2 at delta >= 0 from the exact solver (law.c); with a tail delta is the
** tailed relation's Delta = (1/rho - 1)(u_C - |u|)/s. Used by the polynomial's fit (law_poly.c). */
double cf_law_region2_e(const cf_law *law, double delta);

/* The scalar law over many points with the method given (law.c): what cf_law_force_many runs for
** the stiffness, the exact method and the laws the lanes do not carry (law_simd.h). */
void cf_law_force_scalar_many(const cf_law *law, cf_law_method method, size_t count,
                              const double *u_mm, double *F_N, double *k_N_per_mm);

/* Releases the table of law, if any. Safe on a zeroed law and on NULL. */
void cf_law_free(cf_law *law);

#endif
