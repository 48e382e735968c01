/*
** The conical spring law: force and tangent stiffness of a constant-pitch conical compression
** spring as a function of its compression u. A pure scalar kernel: it knows nothing of meshes,
** fits or files.
**
** Law (derived from first principles in src/model/law.md; the paper's eqs. 3-12 encode it):
**   travel to solid  s   = H - L_min,  L_min = d (telescoping) or n d (non-telescoping)
**   telescoping      <=> (D2 - D1)/2 >= n d   (coils of successive radii fit inside each other)
**   transition load  F_T = G d^4 s / (8 n D2^3),  solid load F_C = G d^4 s / (8 n D1^3)
**   region 1 (|u| <= u_T): F = k0 u, k0 = G d^4 / (2 n (D1 + D2)(D1^2 + D2^2)),
**                          u_T = s (1 + rho)(1 + rho^2) / 4, rho = D1/D2
**   region 2 (u_T < |u| < s): F = F_C y^3 with y the root in [rho, 1] of y^4 - 4 c y + 3 = 0,
**                          c = 1/rho - (u/s)(1/rho - 1)
**   region 3 (|u| >= s): solid; the law reports F = +-F_C and the CF_LAW_SOLID flag.
**   F(-u) = -F(u): stretching mirrors compression (paper eqs. 20-21, L_max = 2H - L_min).
** The tail (law kind conical-tail, src/model/law.md): n_t coils of diameter D1 in series with the
** cone, stiffness k_t = G d^4/(8 n_t D1^3), tau = n_t/n = F_C/(k_t s), beta = (1/rho - 1) tau:
**   region 1: F = k0 u with k0 the series stiffness, up to u_T + F_T/k_t;
**   region 2: the cone's y and the tail's F/k_t add: with Delta = (1/rho - 1)(u_C - |u|)/s,
**             u_C = s (1 + tau), y solves delta(e) + beta (1 - y^3) = Delta (e = 1 - y), i.e.
**             (1 - 4 beta) y^4 - 4 c y + 3 = 0 with c = 1/rho - (u/s)(1/rho - 1);
**   region 3 (u_C <= |u| < s + s_t, cone solid): F = F_C + k_t (|u| - u_C), the CF_LAW_TAIL flag;
**   solid at s + s_t (s_t = H_tail - n_t d, the tail's own travel): F = +-k_t s_t.
** Without a tail every quantity and every evaluation is the plain law's, bit for bit.
** References: Rodriguez E, Paredes M, Sartor M (2006), Analytical behavior law for a constant pitch
** conical compression spring, J Mech Des 128:1352-1356; the conical-springs paper (eqs. 1-21).
**
** Units: lengths in mm, G in MPa = N/mm^2, forces in N, stiffness in N/mm.
** Sign: u > 0 compresses (shortens) the spring, u < 0 stretches it; F has the sign of u.
**
** Evaluators (chosen per call, all behind cf_law_force):
**   CF_LAW_EXACT   bracketed root finding (Brent) on the explicit deflection-of-load relation,
**                  converged until the bracket stops shrinking: accurate to the last bits, slowest.
**   CF_LAW_CLOSED  Ferrari's closed form of the quartic, written without cancellation near solid,
**                  in the near-cylindrical limit and for strongly conical springs.
**   CF_LAW_CLOSED_NEWTON  the closed form followed by one Newton step in the near-solid variable.
**   With a tail, CF_LAW_CLOSED and CF_LAW_CLOSED_NEWTON solve region 2 by Newton's method on the
**                  explicit relation, kept inside a bracket that the cone's closed form and the
**                  tail's cube root give (law.c, region2_tail): the y-quartic's leading
**                  coefficient 1 - 4 beta, which vanishes at beta = 1/4, never appears.
**   CF_LAW_TABLE   a precomputed cubic Hermite table (see cf_law_table_build) on a grid uniform in
**                  sqrt(1 - u/s), where the law is smooth; fastest, with a measured error bound.
*/
#ifndef CF_LAW_H
#define CF_LAW_H

#include <stddef.h>

#include "conifit/error.h"
#include "conifit/spring.h"

typedef enum cf_law_method {
    CF_LAW_EXACT = 0,
    CF_LAW_CLOSED = 1,
    CF_LAW_CLOSED_NEWTON = 2,
    CF_LAW_TABLE = 3
} cf_law_method;

/* Flags reported by an evaluation. */
enum {
    CF_LAW_LINEAR = 1, /* |u| <= u_T: region 1 */
    CF_LAW_SOLID = 2,  /* |u| >= travel: clamped at +-F_solid, stiffness reported as 0 */
    CF_LAW_TAIL = 4    /* cone solid, tail still deflecting: region 3 of a spring with a tail */
};

/* Default number of table intervals. Measured maximum force error of the table against exact at
** this size: 1.5e-12 of |F| at rho = 0.5, 2.3e-10 at rho = 0.1, 3e-9 at rho = 0.03, and 6.5e-7 of
** F_C at rho = 1e-3; the error falls as the fourth power of the size (tests/unit/test_law.c checks
** the bound, the benchmark reports the whole curve). A spring with a tail: at most 6.7e-8 of F_C
** over rho 0.03-0.9 and beta 1e-9-50 (tests/unit/test_law_tail.c). */
#define CF_LAW_TABLE_DEFAULT 256

struct cf_law_table; /* opaque; built by cf_law_table_build */

/* A spring prepared for evaluation: its parameters and every derived quantity, or a law of another
** kind (its kind's mechanics and quantities). Opaque: create with cf_law_create, release with
** cf_law_destroy. */
typedef struct cf_law cf_law;

/* A new law of the conical spring p (with its tail when p has one): the checks of the library's
** cf_law_init (non-finite or non-positive values, D1 > D2, n < 2, a travel <= 0 and a tail's room
** refused with CF_E_DATA naming the parameter and its value). NULL on error (CF_E_INTERNAL when
** memory runs out). */
cf_law *cf_law_create(const cf_spring *p, cf_error *err);

/* Releases law and its table. Safe on NULL. */
void cf_law_destroy(cf_law *law);

/* Joins the extension spring ext to law (a double-acting element: law for u >= 0, ext, which a
** stretch compresses, for u < 0): CF_E_DATA when their free lengths differ (the message gives
** both) or ext itself has an extension. ext is not owned and must outlive law's use. */
cf_status cf_law_pair(cf_law *law, const cf_law *ext, cf_error *err);

/* The travel to solid (mm, > 0) on the side of u: the extension spring's for u < 0 when there is
** one, a law kind's own travel on that side. */
double cf_law_travel(const cf_law *law, double u_mm);

/* Force at full travel on the side of u (N, with the sign of u; its F_solid). */
double cf_law_solid_force(const cf_law *law, double u_mm);

/* The spring of law: its design parameters (a law kind's buildable spring). */
cf_spring cf_law_spring(const cf_law *law);

/* The name of law's kind: "conical", "conical-tail", "double-acting" or a kind's own. */
const char *cf_law_kind_of(const cf_law *law);

/* Builds (or rebuilds) the table used by CF_LAW_TABLE with `intervals` intervals (>= 2) over
** region 2. CF_E_DATA for a bad size, CF_E_INTERNAL when memory runs out. */
cf_status cf_law_table_build(cf_law *law, size_t intervals, cf_error *err);

/* Force (N) at compression u (mm) with the chosen method; *k_N_per_mm (if not NULL) receives the
** tangent stiffness dF/du >= 0 and *flags (if not NULL) CF_LAW_LINEAR / CF_LAW_SOLID. A non-finite
** u is treated as solid with the sign of u (NaN as +0 force). CF_LAW_TABLE without a built table
** falls back to CF_LAW_CLOSED_NEWTON (for each spring of a pair, by its own table). With an
** extension spring, u < 0 is its law mirrored (law->extension). Never returns NaN or Inf for a law that cf_law_init accepted. */
double cf_law_force(const cf_law *law, cf_law_method method, double u_mm, double *k_N_per_mm,
                    int *flags);

/* The same for count displacements at once: F[i] and (if k is not NULL) k[i] for u[i]. The method
** is dispatched once, so the inner loop is the law alone. */
void cf_law_force_many(const cf_law *law, cf_law_method method, size_t count, const double *u_mm,
                       double *F_N, double *k_N_per_mm);

/* Compression (mm, >= 0 for F >= 0) at which the spring carries force F (N): the explicit inverse
** of the law, exact up to rounding; |F| >= F_solid gives +-travel. */
double cf_law_deflection(const cf_law *law, double F_N);

/* Parses "exact", "closed", "closed+newton" or "table"; CF_E_DATA for anything else. */
cf_status cf_law_method_parse(const char *name, cf_law_method *method, cf_error *err);
const char *cf_law_method_name(cf_law_method method);

#endif
