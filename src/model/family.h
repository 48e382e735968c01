/*
** The identifiable family of a conical spring. A measured table sees the law of a spring only
** through three combinations of its six design parameters: the diameter ratio, a length scale
** and a load scale. Every spring with the same three is one family: the fit determines the family
** from the data (stage A of fit.h) and then places one member of it under the design constraints;
** the time-dependent model (viscomodel.h) and the fits through the lattice (lattice_fit.h,
** joint.h) work in the family's space alone.
**
** This file owns the quantities and everything about them that does not depend on a table: their
** units, a spring's family, a buildable member of a family, the design limits seen in the family's
** space, and the family's curve. Adding a quantity is a change here (and where it is printed).
*/
#ifndef CF_FAMILY_H
#define CF_FAMILY_H

#include "conifit/error.h"
#include "model/law_internal.h"
#include "conifit/spring.h"

/* Index of each quantity in cf_ident.v. */
enum { CF_IDENT_RHO = 0, CF_IDENT_SOLID, CF_IDENT_SCALE, CF_IDENT_COUNT };

/* The most identifiable quantities a law kind has (lawkind.h; the double-acting pair has six),
** and the index of the tailed kind's fourth, its tail compliance, after the cone's three. */
enum { CF_Q_MAX = 8, CF_Q_TAIL = CF_IDENT_COUNT };

/* The identifiable quantities of one spring, by name or by index (v[CF_IDENT_*]). The length and
** load scales take the table's kind: a stress-strain table (sigma = F/H^2, epsilon = u/H) sees the
** solid strain and the stress scale, a force-displacement table the travel and the solid load. */
typedef union cf_ident {
    struct {
        double rho;   /* diameter ratio D1/D2, - (0 < rho <= 1) */
        double solid; /* solid strain s/H, - ; or travel s = H - L_min, mm */
        double scale; /* stress scale F_C/H^2, MPa ; or solid load F_C, N */
    };
    double v[CF_IDENT_COUNT];
} cf_ident;

/* The design constraints of a spring, as bits (cf_fit_result.active, .violated, .held, and the
** limits of the family's space below). */
enum {
    CF_C_INDEX_MIN = 1 << 0, /* c = D1/d >= 3 */
    CF_C_INDEX_MAX = 1 << 1, /* c <= index_max */
    CF_C_COILS = 1 << 2,     /* n >= 2 */
    CF_C_DIAMETERS = 1 << 3, /* D2 >= D1 */
    CF_C_TRAVEL = 1 << 4,    /* travel > (1 + margin) largest |u| */
    CF_C_TYPE = 1 << 5,      /* the geometry is of the type being fitted */
    CF_C_BOUNDS = 1 << 6,    /* a parameter at (or beyond) one of its other bounds */
    CF_C_RHO_MIN = 1 << 7,   /* rho = D1/D2 >= rho_min */
    CF_C_COILS_MAX = 1 << 8, /* n <= upper[CF_P_N] */
    CF_C_G_MAX = 1 << 9,     /* G <= upper[CF_P_G] */
    CF_C_D2_H = 1 << 10,     /* D2 <= D2_over_H_max H */
    CF_C_COUNT = 11
};

/* Lowest diameter ratio searched: rho = 1e-3 is a spring whose largest coil is a thousand times
** its smallest, far beyond any wound spring. */
#define CF_IDENT_RHO_LO 1e-3

/* rho_min is met within this relative tolerance, so that a table made from a spring at exactly
** rho_min is fitted to rounding (its optimum then lies inside the searched range, not on its
** edge). */
#define CF_IDENT_RHO_MIN_TOL 1e-6

/* (A spring with a cylindrical tail gives its cone's three quantities: the tail's compliance is
** a fourth, cf_fit_result.e_tail.) */

/* The family of spring p counted as a spring of the given type (the type being fitted, not
** necessarily the one its geometry has: its solid length is d for telescoping, n d otherwise);
** force_displacement chooses the scales' kind. */
cf_ident cf_ident_of_type(const cf_spring *p, cf_spring_type type, int force_displacement);

/* The family of spring p, counted as the type its geometry has. */
cf_ident cf_ident_of(const cf_spring *p, int force_displacement);

/* A spring of free length 1 mm of the family q of a stress-strain table (non-telescoping, n = 2);
** the lattice's nominal stress depends on nothing else. */
cf_spring cf_ident_member(const cf_ident *q);

/* The same with a cylindrical tail of tau = n_tail/n coils per cone coil (the conical-tail law,
** fit.h): cone travel s/H = q->solid and solid load F_C = q->scale at free length 1 mm, tail
** compliance F_C/(k_t H) = tau s/H; the solid lengths take CF_IDENT_TAIL_SOLIDS of the length left
** past the cone's closing strain s/H (1 + tau) < 1, the tail's travel the rest. */
#define CF_IDENT_TAIL_SOLIDS 0.01
cf_spring cf_ident_member_tail(const cf_ident *q, double tau);

/* The wire modulus G (MPa) that gives a spring of n coils, smallest coil D1, wire d and travel s
** (mm) the solid load F_C (N): F_C = G d^4 s / (8 n D1^3). */
double cf_ident_G_of_FC(double F_C_N, double n, double D1_mm, double d_mm, double s_mm);

/* Largest diameter ratio of a spring type: telescoping needs n <= c (1 - rho)/(2 rho) with
** n >= 2 and c <= index_max, so rho <= index_max/(index_max + 4) (less a hair); non-telescoping
** reaches the cylinder, 1. */
double cf_ident_rho_hi(cf_spring_type type, double index_max);

/* The design limits that bound a family (fit.h, cf_fit_options, gives them). */
typedef struct cf_ident_design {
    double n_min, n_max;   /* coil count, - */
    double G_max_MPa;      /* stiffest wire in shear, MPa */
    double D2_over_H_max;  /* largest outer diameter per free length, - */
    double index_max;      /* largest spring index D1/d, - */
    double rho_min;        /* smallest diameter ratio, - */
} cf_ident_design;

/* The design limits of a type in the family space of a stress-strain table at (rho, B = s/H),
** with no fixed design parameter (then H is a pure scale and the limits have a closed form):
**   margin  <= 0 where a spring of the type can be placed within them (log units);
**   A_max   the largest stress scale F_C/H^2 (MPa) such a spring carries there, less the
**           fraction `inside`;
**   lo_bit, hi_bit  the CF_C_* bits of the two limits that meet at the edge. */
typedef struct cf_ident_region {
    double margin;
    double A_max;
    unsigned lo_bit, hi_bit;
} cf_ident_region;

cf_ident_region cf_ident_region_at(const cf_ident_design *o, cf_spring_type type, double rho,
                                   double B, double inside);

/* The family's curve. The canonical spring of diameter ratio rho has travel 1 mm and solid load
** 1 N; every spring of the family is it scaled: F(u) = F_C g(u/s), g the canonical law. */
cf_status cf_ident_canon_law(double rho, cf_law *law);

/* The canonical law's transition t_T = min((1 + rho)(1 + rho^2)/4, 1), its u_T_mm: the law is
** linear (region 1) for |t| <= t_T, and a table of largest |x| <= B t_T sees only that line. */
double cf_ident_canon_transition(double rho);

/* The family's reduced model at x: A g(x/B) for the canonical law canon (of rho), with A the load
** scale and B the length scale; *dB (if not NULL) receives its derivative in B. */
double cf_ident_reduced(const cf_law *canon, double A, double B, double x, double *dB);

/* The canonical law canon (of rho) at t = x[i]/B for count points, vectorised: g[i] = g(t) and,
** when dg_dt and dg_drho are both given, its derivatives in t and in rho (region 1 linear,
** region 3 constant, NaN gives 0). The closed form of the lattice's step (law_simd.h): g agrees
** with cf_law_force(canon, CF_LAW_CLOSED, t) to a few ulps, not bit for bit. g may not alias x. */
void cf_ident_canon_many(const cf_law *canon, double B, size_t count, const double *x, double *g,
                         double *dg_dt, double *dg_drho);

/* cf_ident_canon_many for the canonical law of rho without building it: the same values, bit for
** bit, as cf_ident_canon_law(rho) followed by cf_ident_canon_many (the lanes need four of its
** constants, derived here by the same operations; the fits' searches call this for every point
** they try). CF_E_DATA, and nothing written, where cf_ident_canon_law has no law for rho. */
cf_status cf_ident_canon_many_rho(double rho, double B, size_t count, const double *x, double *g,
                                  double *dg_dt, double *dg_drho);

#endif
