/*
** The homogenised cell of the cubic lattice (see cell.h): nominal stress of one cell under a
** homogeneous deformation, its tangent along the free stretch of a test mode, and the
** safeguarded Newton solve of that stretch.
*/
#include "model/cell.h"
#include "model/mode.h"

#include <float.h>
#include <math.h>
#include <string.h>

/* A spring closer to solid than this fraction of the travel is refused (the law's stiffness grows
** like (s - u)^(-1/2) there, and the full lattice stops at the same margin). */
#define SOLID_MARGIN (1.0 - 1e-9)
/* Newton iterations for a free stretch. */
#define MAX_ITER 100

/* The 13 directions, each unordered pair of neighbours once: offsets with dz > 0, or dz = 0 and
** dy > 0, or dz = dy = 0 and dx > 0, in the order z, y, x from -1 to 1. */
static const int dirs[CF_CELL_DIRS][3] = {
    {1, 0, 0},
    {-1, 1, 0},
    {0, 1, 0},
    {1, 1, 0},
    {-1, -1, 1},
    {0, -1, 1},
    {1, -1, 1},
    {-1, 0, 1},
    {0, 0, 1},
    {1, 0, 1},
    {-1, 1, 1},
    {0, 1, 1},
    {1, 1, 1}};

/* The rest length of each direction over the cell edge, sqrt(N . N) (correctly rounded, so the
** same double as the square root computed at run time), and its family: the spring loop takes
** them from here instead of recomputing them per spring and per evaluation. */
#define SQRT2 1.41421356237309504880
#define SQRT3 1.73205080756887729353
static const double dir_len[CF_CELL_DIRS] = {1,     SQRT2, 1, SQRT2, SQRT3, SQRT2, SQRT3,
                                             SQRT2, 1,     SQRT2, SQRT3, SQRT2, SQRT3};
static const int dir_family[CF_CELL_DIRS] = {0, 1, 0, 1, 2, 1, 2, 1, 0, 1, 2, 1, 2};
/* The first direction whose offsets differ from d's in sign only: under a diagonal F it has d's
** length to the bit, so the search for a spring alike tries it first. */
static const int dir_mirror[CF_CELL_DIRS] = {0, 1, 2, 1, 4, 5, 4, 7, 8, 7, 4, 5, 4};

void cf_cell_direction(int d, int N[3], int *family)
{
    if (d < 0 || d >= CF_CELL_DIRS) {
        N[0] = N[1] = N[2] = 0;
        *family = CF_FAMILY_EDGE;
        return;
    }
    N[0] = dirs[d][0], N[1] = dirs[d][1], N[2] = dirs[d][2];
    *family = (N[0] != 0) + (N[1] != 0) + (N[2] != 0) - 1;
}

cf_status cf_cell_init(cf_cell *c, const cf_law *law, cf_law_method method,
                       const double weight[CF_FAMILY_COUNT], cf_error *err)
{
    cf_status st = cf_calibration_check(weight, err);
    if (st != CF_OK)
        return st;
    c->law = law;
    c->method = method;
    c->law_scale = 1.0;
    c->law_scale_strain = 0.0;
    c->stretch_hint = 0.0;
    c->linear_finish = 0;
    c->biaxial_k = 1.0;
    c->volume_modulus_MPa = 0.0;
    for (int f = 0; f < CF_FAMILY_COUNT; f++)
        c->family_law[f] = NULL;
    c->fibre = NULL;
    c->nfibre = 0;
    for (int i = 0; i < 9; i++)
        c->frame[i] = i % 4 == 0;
    memcpy(c->weight, weight, sizeof c->weight);
    return CF_OK;
}

/* The law of family fam's springs. */
static inline const cf_law *fam_law(const cf_cell *c, int fam)
{
    return c->family_law[fam] ? c->family_law[fam] : c->law;
}

/* 1 when spring d carries what the earlier spring e carries: the same squared length (so the
** same length, to the bit), the same weight and the same extra terms. Springs that a
** deformation maps alike (the four body diagonals under a diagonal F, the lateral edges under
** uniaxial loading) then share one evaluation of the law instead of repeating it. */
static inline int same_spring(const cf_cell_extra *x, const double *L2, int d, int e)
{
    return L2[e] == L2[d] && dir_family[e] == dir_family[d] &&
           (!x || (x->T0_N[e] == x->T0_N[d] && x->k_N_per_mm[e] == x->k_N_per_mm[d] &&
                   x->Lref_mm[e] == x->Lref_mm[d]));
}

/* The tension of spring d at length L (s->T_N, s->L_mm, kT), or an error when it reaches solid;
** *r gets |u| over the travel. */
static cf_status spring_tension(const cf_cell *c, int d, double L, const cf_cell_extra *x,
                                cf_cell_state *s, double kT[CF_CELL_DIRS], double *r,
                                cf_error *err)
{
    const int *N = dirs[d], fam = dir_family[d];
    const cf_law *law = fam_law(c, fam);
    const double H = law->p.H_mm;
    double L0 = H * dir_len[d];
    double u = H * (L0 - L) / L0;
    const double travel = cf_law_travel_at(law, u); /* a pair: the side u loads */
    *r = fabs(u) / travel;
    if (!(*r < SOLID_MARGIN) || !(L > 0))
        return cf_error_set(err, CF_E_DATA,
                            "the cell's spring along (%d, %d, %d) reaches solid (stretch %.6g, "
                            "solid at %.6g)",
                            N[0], N[1], N[2], L / L0, 1 - copysign(travel / H, u));
    double k = 0;
    double f = cf_law_force(law, c->method, u, &k, NULL);
    double w = c->weight[fam] * c->law_scale, T, dT;
    if (c->law_scale_strain != 0) { /* factor law_scale + law_scale_strain |u| / H */
        const double phi = c->law_scale + c->law_scale_strain * fabs(u) / H;
        const double dphi = c->law_scale_strain * copysign(1.0, u) / H; /* d phi / du */
        T = -c->weight[fam] * phi * f;
        dT = c->weight[fam] * (phi * k + dphi * f) * H / L0;
    } else {
        T = -w * f;
        dT = w * k * H / L0;
    }
    if (x) {
        T += x->T0_N[d] + x->k_N_per_mm[d] * (L - x->Lref_mm[d]);
        dT += x->k_N_per_mm[d];
    }
    s->L_mm[d] = L;
    s->T_N[d] = T;
    kT[d] = dT;
    return CF_OK;
}

/* The cofactor matrix of F (cof F = J F^-T, row-major) and J = det F. */
static double cofactor(const double F[9], double C[9])
{
    C[0] = F[4] * F[8] - F[5] * F[7];
    C[1] = F[5] * F[6] - F[3] * F[8];
    C[2] = F[3] * F[7] - F[4] * F[6];
    C[3] = F[2] * F[7] - F[1] * F[8];
    C[4] = F[0] * F[8] - F[2] * F[6];
    C[5] = F[1] * F[6] - F[0] * F[7];
    C[6] = F[1] * F[5] - F[2] * F[4];
    C[7] = F[2] * F[3] - F[0] * F[5];
    C[8] = F[0] * F[4] - F[1] * F[3];
    return F[0] * C[0] + F[1] * C[1] + F[2] * C[2];
}

/* The volume term's nominal stress kappa (J - 1) cof F added to P. */
static void volume_stress(double kappa, const double F[9], double P[3][3])
{
    double C[9];
    const double J = cofactor(F, C), g = kappa * (J - 1);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            P[i][j] += g * C[3 * i + j];
}

/* The volume term's tangent dP_ij/dF_kl = kappa C_ij C_kl + kappa (J - 1)/J (C_ij C_kl - C_il C_kj),
** C = cof F (d cof F_ij / dF_kl = (C_ij C_kl - C_il C_kj)/J, dJ/dF = C). */
static double volume_tangent(double kappa, const double C[9], double J, int i, int j, int k,
                             int l)
{
    const double cc = C[3 * i + j] * C[3 * k + l];
    return kappa * cc + kappa * (J - 1) / J * (cc - C[3 * i + l] * C[3 * k + j]);
}

/* The state at F, and dT/dL of every spring (N/mm) for the tangent. */
static cf_status evaluate(const cf_cell *c, const double F[9], const cf_cell_extra *x,
                          cf_cell_state *s, double kT[CF_CELL_DIRS], cf_error *err)
{
    const double H = c->law->p.H_mm, H3 = H * H * H;
    double P[3][3] = {{0}}; /* summed here, not through s (no store and reload per term) */
    double L2[CF_CELL_DIRS], q[CF_CELL_DIRS], umax = 0, r;
    memset(s->P_MPa, 0, sizeof s->P_MPa);
    memcpy(s->F, F, sizeof s->F);
    s->max_u_over_travel = 0;
    for (int i = 0; i < 9; i++)
        if (!isfinite(F[i]))
            return cf_error_set(err, CF_E_DATA, "deformation gradient F[%d][%d] = %g is not "
                                "finite", i / 3, i % 3, F[i]);
    /* A diagonal F (every mode but shear places one) maps each offset axis by axis, x_i = F_ii X_i
    ** (the products with its zeros are zeros, which leave a sum as it is), and every term of P
    ** with X_i = 0 or X_j = 0 is a zero, not summed: the same state to the bit, with less work. */
    const int diag = F[1] == 0 && F[2] == 0 && F[3] == 0 && F[5] == 0 && F[6] == 0 && F[7] == 0;
    for (int d = 0; d < CF_CELL_DIRS; d++) {
        const int *N = dirs[d];
        double X[3] = {H * N[0], H * N[1], H * N[2]}, xv[3];
        for (int i = 0; i < 3; i++)
            xv[i] = diag ? F[4 * i] * X[i]
                         : F[3 * i] * X[0] + F[3 * i + 1] * X[1] + F[3 * i + 2] * X[2];
        L2[d] = xv[0] * xv[0] + xv[1] * xv[1] + xv[2] * xv[2];
        /* any earlier spring alike gives the same results, so which one is found does not matter */
        int e = dir_mirror[d];
        if (!(e < d && same_spring(x, L2, d, e)))
            for (e = 0; e < d && !same_spring(x, L2, d, e);)
                e++;
        if (e < d) { /* the same spring state as e: its results, bit for bit */
            s->L_mm[d] = s->L_mm[e];
            s->T_N[d] = s->T_N[e];
            kT[d] = kT[e];
            q[d] = q[e];
        } else {
            cf_status st = spring_tension(c, d, sqrt(L2[d]), x, s, kT, &r, err);
            umax = r > umax ? r : umax; /* as fmax: a NaN r leaves it */
            s->max_u_over_travel = umax;
            if (st != CF_OK)
                return st;
            q[d] = s->T_N[d] / (s->L_mm[d] * H3); /* one division per spring, not per term */
        }
        for (int i = 0; i < 3; i++) {
            if (diag && N[i] == 0)
                continue;
            const double qx = q[d] * xv[i];
            for (int j = 0; j < 3; j++)
                if (!diag || N[j] != 0)
                    P[i][j] += qx * X[j];
        }
    }
    if (c->volume_modulus_MPa != 0)
        volume_stress(c->volume_modulus_MPa, F, P);
    for (int g = 0; g < c->nfibre; g++) {
        double T;
        cf_status st = cf_fibre_add_stress(&c->fibre[g], c->law->p.H_mm, F, P, &T, &r, err);
        umax = r > umax ? r : umax;
        s->max_u_over_travel = umax;
        if (st != CF_OK)
            return st;
    }
    memcpy(s->P_MPa, P, sizeof P);
    return CF_OK;
}

cf_status cf_cell_stress(const cf_cell *c, const double F[9], const cf_cell_extra *extra,
                         cf_cell_state *s, cf_error *err)
{
    double kT[CF_CELL_DIRS];
    s->stress_MPa = 0;
    s->free_stretch = 1;
    return evaluate(c, F, extra, s, kT, err);
}

cf_status cf_cell_tangent(const cf_cell *c, const double F[9], const cf_cell_extra *extra,
                          cf_cell_state *s, double A[81], cf_error *err)
{
    double kT[CF_CELL_DIRS];
    s->stress_MPa = 0;
    s->free_stretch = 1;
    cf_status st = evaluate(c, F, extra, s, kT, err);
    if (st != CF_OK)
        return st;
    const double H = c->law->p.H_mm, H3 = H * H * H;
    memset(A, 0, 81 * sizeof(double));
    for (int d = 0; d < CF_CELL_DIRS; d++) {
        int N[3], fam;
        cf_cell_direction(d, N, &fam);
        double X[3] = {H * N[0], H * N[1], H * N[2]}, xv[3];
        for (int i = 0; i < 3; i++)
            xv[i] = F[3 * i] * X[0] + F[3 * i + 1] * X[1] + F[3 * i + 2] * X[2];
        const double L = s->L_mm[d], T = s->T_N[d], a = (kT[d] - T / L) / (L * L * H3);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                for (int k = 0; k < 3; k++)
                    for (int l = 0; l < 3; l++)
                        A[27 * i + 9 * j + 3 * k + l] +=
                            a * xv[i] * X[j] * xv[k] * X[l] +
                            (i == k ? T * X[j] * X[l] / (L * H3) : 0);
    }
    if (c->volume_modulus_MPa != 0) {
        double C[9];
        const double J = cofactor(F, C);
        for (int i = 0; i < 81; i++)
            A[i] += volume_tangent(c->volume_modulus_MPa, C, J, i / 27, (i / 9) % 3, (i / 3) % 3,
                                   i % 3);
    }
    for (int g = 0; g < c->nfibre; g++)
        if ((st = cf_fibre_add_tangent(&c->fibre[g], H, F, A, err)) != CF_OK)
            return st;
    return CF_OK;
}

/* dP[m][m] / dF[k][k] summed over the diagonal entries k whose bit is set in kmask, at state s:
** dP_ij/dF_kl = (1/H^3) sum_d [(dT/dL - T/L) x_i X_j x_k X_l / L^2 + T delta_ik X_j X_l / L].
** The terms of a direction with X_m = 0 or X_k = 0 are zeros (each has the factor X_m X_k) and are
** not summed: a zero added leaves the sum as it is. */
static double tangent(const cf_cell *c, const cf_cell_state *s, const double kT[CF_CELL_DIRS],
                      int m, unsigned kmask)
{
    const double H = c->law->p.H_mm, H3 = H * H * H;
    const double *F = s->F;
    const int diag = F[1] == 0 && F[2] == 0 && F[3] == 0 && F[5] == 0 && F[6] == 0 && F[7] == 0;
    double g = 0, t1[CF_CELL_DIRS][3], t2[CF_CELL_DIRS];
    for (int d = 0; d < CF_CELL_DIRS; d++) {
        const int *N = dirs[d];
        if (N[m] == 0)
            continue;
        double L = s->L_mm[d], T = s->T_N[d];
        /* under a diagonal F each term has x_i X_i, the same for a mirrored direction in the same
        ** state: its terms, bit for bit */
        const int e = dir_mirror[d];
        if (diag && e < d && s->L_mm[e] == L && s->T_N[e] == T && kT[e] == kT[d]) {
            memcpy(t1[d], t1[e], sizeof t1[d]);
            t2[d] = t2[e];
        } else {
            double X[3] = {H * N[0], H * N[1], H * N[2]}, xv[3];
            for (int i = 0; i < 3; i++)
                xv[i] = F[3 * i] * X[0] + F[3 * i + 1] * X[1] + F[3 * i + 2] * X[2];
            for (int k = 0; k < 3; k++)
                if ((kmask & (1u << k)) && N[k] != 0)
                    t1[d][k] = (kT[d] - T / L) * xv[m] * X[m] * xv[k] * X[k] / (L * L * H3);
            t2[d] = T * X[m] * X[m] / (L * H3);
        }
        for (int k = 0; k < 3; k++) {
            if (!(kmask & (1u << k)) || N[k] == 0)
                continue;
            g += t1[d][k];
            if (k == m)
                g += t2[d];
        }
    }
    if (c->volume_modulus_MPa != 0) {
        double C[9];
        const double J = cofactor(F, C);
        for (int k = 0; k < 3; k++)
            if (kmask & (1u << k))
                g += volume_tangent(c->volume_modulus_MPa, C, J, m, m, k, k);
    }
    return g;
}

/* How mode m places F at strain e and free stretch a; which diagonal entries a sets (mask), which
** diagonal stress it must zero (zero, or -1 for none) and which component is the stress read. */
typedef struct mode_form {
    unsigned free_mask;
    int zero;
    int si, sj;
} mode_form;

static mode_form form_of(cf_mode m)
{
    const cf_mode_row *r = cf_mode_row_of(m);
    return r ? (mode_form){r->free_mask, r->zero, r->si, r->sj} : (mode_form){0u, -1, 2, 2};
}

/* First guess of the free stretch from the small-strain constants of the weights: a free pair
** contracts by nu, a single free stretch by C12/C11 for each loaded one. */
static double guess(const cf_cell *c, cf_mode m, double e)
{
    const cf_mode_row *r = cf_mode_row_of(m);
    const int nf = __builtin_popcount(r->free_mask), nl = __builtin_popcount(r->strain_mask);
    cf_cubic_moduli cm = cf_cubic_moduli_of(c->weight);
    if (nf == 2)
        return 1 - cm.nu * e;
    if (nf == 1) /* biaxial: the two loaded strains are e and k e */
        return 1 - (m == CF_MODE_BIAXIAL ? 1 + c->biaxial_k : nl) * cm.C12 / cm.C11 * e;
    return 1;
}

/* The state once its free stretch a is found: the stress of the mode's loaded component. */
static cf_status settled(cf_cell_state *s, const mode_form *fm, double a)
{
    s->free_stretch = a;
    s->stress_MPa = s->P_MPa[fm->si][fm->sj];
    return CF_OK;
}

/* A last Newton step relative to the stretch up to which the solve may take it by linearisation
** (c->linear_finish): the state's second-order change over it is below 1e-20 of the state. */
#define LINEAR_STEP 1e-10

/* The state at free stretch a + da from s, evaluated at a, to first order in da (s->F diagonal, as
** every mode with a free stretch places it): each spring's length and tension move along dL/da
** and dT/dL, the diagonal stress along its tangent (as tangent() gives it). */
static cf_status settle_linear(const cf_cell *c, const mode_form *fm,
                               const double kT[CF_CELL_DIRS], cf_cell_state *s, double a,
                               double da)
{
    const double H = c->law->p.H_mm, H3 = H * H * H;
    double dP[3] = {0, 0, 0}, umax = 0;
    double t1[CF_CELL_DIRS][3], t2[CF_CELL_DIRS][3], Ln[CF_CELL_DIRS], Tn[CF_CELL_DIRS];
    for (int d = 0; d < CF_CELL_DIRS; d++) {
        const int *N = dirs[d];
        const double L = s->L_mm[d], T = s->T_N[d];
        const int e = dir_mirror[d]; /* every term has X_i X_i: a mirror in the same state's */
        if (e < d && s->L_mm[e] == L && s->T_N[e] == T && kT[e] == kT[d]) {
            memcpy(t1[d], t1[e], sizeof t1[d]);
            memcpy(t2[d], t2[e], sizeof t2[d]);
            Ln[d] = Ln[e];
            Tn[d] = Tn[e];
        } else {
            const double X[3] = {H * N[0], H * N[1], H * N[2]};
            double xX = 0; /* sum over the free entries of x_k X_k, which is L dL/da */
            for (int k = 0; k < 3; k++)
                if (fm->free_mask & (1u << k))
                    xX += s->F[4 * k] * X[k] * X[k];
            for (int m = 0; m < 3; m++) {
                t1[d][m] = (kT[d] - T / L) * s->F[4 * m] * X[m] * X[m] * xX / (L * L * H3);
                t2[d][m] = T * X[m] * X[m] / (L * H3);
            }
            const double dL = xX / L * da;
            Ln[d] = L + dL;
            Tn[d] = T + kT[d] * dL;
        }
        for (int m = 0; m < 3; m++) {
            dP[m] += t1[d][m];
            if (fm->free_mask & (1u << m))
                dP[m] += t2[d][m];
        }
    }
    for (int d = 0; d < CF_CELL_DIRS; d++) {
        s->L_mm[d] = Ln[d];
        s->T_N[d] = Tn[d];
        const double L0 = H * dir_len[d];
        const double uu = H * (L0 - s->L_mm[d]) / L0;
        const double ru = fabs(uu) / cf_law_travel_at(fam_law(c, dir_family[d]), uu);
        umax = ru > umax ? ru : umax;
    }
    for (int m = 0; m < 3; m++) {
        s->P_MPa[m][m] += dP[m] * da;
        if (fm->free_mask & (1u << m))
            s->F[4 * m] = a + da;
    }
    s->max_u_over_travel = umax;
    return settled(s, fm, a + da);
}

/* The rounding level of the lateral stress of state s: its largest term, MPa. */
static double lateral_rounding(const cf_cell *c, const cf_cell_state *s)
{
    double rs = 0;
    for (int d = 0; d < CF_CELL_DIRS; d++) {
        const double t = fabs(s->T_N[d]);
        rs = t > rs ? t : rs; /* as fmax, without its call */
    }
    rs /= c->law->p.H_mm * c->law->p.H_mm;
    if (c->volume_modulus_MPa != 0) { /* the volume term's stress, its largest entry */
        double C[9], cm = 0;
        const double J = cofactor(s->F, C);
        for (int i = 0; i < 9; i++)
            cm = fmax(cm, fabs(C[i]));
        rs = fmax(rs, fabs(c->volume_modulus_MPa * (J - 1)) * cm);
    }
    return rs * (8 * DBL_EPSILON);
}

/* What the search for the free stretch knows: r(lo) < 0 < r(hi) once have_lo and have_hi. */
typedef struct bracket {
    double lo, hi;
    int have_lo, have_hi;
} bracket;

/* The stretch after a, where the lateral stress is r and its slope g: Newton's step while it
** stays inside the bracket, else bisection, or a move toward the side not yet bracketed. */
static double next_stretch(bracket *b, double a, double r, double g)
{
    if (r < 0)
        b->lo = a, b->have_lo = 1;
    else
        b->hi = a, b->have_hi = 1;
    double an = a - r / g;
    if (g > 0 && fabs(an - a) <= 2 * DBL_EPSILON * fabs(a))
        return an; /* converged to rounding: a step that does not move a is no reason to bisect */
    if (!(g > 0) || !(an > b->lo && an < b->hi)) {
        if (b->have_lo && b->have_hi)
            an = 0.5 * (b->lo + b->hi);
        else /* expand toward the missing side */
            an = r > 0 ? 0.5 * (b->lo + a) : 0.5 * (a + b->hi);
    }
    return an;
}

/* ---- modes on the axes of a frame (cf_cell_load_state; every mode of a cell with fibres) ---- */

/* Where a load places F' (the frame's components): the base F' at free stretches 1, its free
** diagonal entries, and the stress read. */
typedef struct load_form {
    double F0[9];
    int nfree, fr[2];
    int si, sj;
} load_form;

static cf_status load_form_of(const cf_cell_load *ld, double e, load_form *f, cf_error *err)
{
    const int p = ld->axis[0], q = ld->axis[1];
    if (p < 0 || p > 2 || q < 0 || q > 2 || p == q)
        return cf_error_set(err, CF_E_DATA, "load axes (%d, %d): two different axes of 0 .. 2",
                            p, q);
    if ((int)ld->mode < 0 || ld->mode >= CF_MODE_COUNT)
        return cf_error_set(err, CF_E_DATA, "mode %d: unknown", (int)ld->mode);
    const int any_sign = cf_mode_row_of(ld->mode)->any_sign;
    if (!isfinite(e) || (!any_sign && !(e > -1)))
        return cf_error_set(err, CF_E_DATA, "%s strain %g: must be finite%s",
                            cf_mode_name(ld->mode), e, any_sign ? "" : " and > -1");
    const int r = 3 - p - q;
    for (int i = 0; i < 9; i++)
        f->F0[i] = i % 4 == 0;
    f->nfree = 0;
    f->si = f->sj = p;
    switch (ld->mode) {
    case CF_MODE_SHEAR:
        f->F0[3 * q + p] = e;
        f->si = q;
        break;
    case CF_MODE_UNIAXIAL:
        f->F0[4 * p] = 1 + e;
        f->fr[f->nfree++] = q;
        f->fr[f->nfree++] = r;
        break;
    case CF_MODE_CONFINED: f->F0[4 * p] = 1 + e; break;
    default: /* planar, equibiaxial, biaxial: q at 1, 1 + e or 1 + k e; r free */
        f->F0[4 * p] = 1 + e;
        f->F0[4 * q] = ld->mode == CF_MODE_PLANAR        ? 1
                       : ld->mode == CF_MODE_EQUIBIAXIAL ? 1 + e
                                                         : 1 + ld->k * e;
        f->fr[f->nfree++] = r;
        break;
    }
    if (!isfinite(f->F0[4 * q]) || !(f->F0[4 * q] > 0))
        return cf_error_set(err, CF_E_DATA, "biaxial strain %g at ratio %g: the other stretch "
                            "%g is not positive", e, ld->k, f->F0[4 * q]);
    return CF_OK;
}

/* F = R^T F' R (R's rows the frame's axes) with F' the form at free stretches v. */
static void load_place(const double R[9], const load_form *f, const double v[2], double F[9])
{
    double Fp[9];
    memcpy(Fp, f->F0, sizeof Fp);
    for (int k = 0; k < f->nfree; k++)
        Fp[4 * f->fr[k]] = v[k];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double x = 0;
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 3; b++)
                    x += R[3 * a + i] * Fp[3 * a + b] * R[3 * b + j];
            F[3 * i + j] = x;
        }
}

/* P'_ab = (R P R^T)_ab. */
static double frame_stress(const double R[9], const double *P, int a, int b)
{
    double x = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            x += R[3 * a + i] * P[3 * i + j] * R[3 * b + j];
    return x;
}

/* dP'_aa / dF'_bb from the lattice-frame tangent A. */
static double frame_tangent(const double R[9], const double A[81], int a, int b)
{
    double x = 0;
    for (int i = 0; i < 81; i++) {
        const int ii = i / 27, jj = (i / 9) % 3, kk = (i / 3) % 3, ll = i % 3;
        x += R[3 * a + ii] * R[3 * a + jj] * A[i] * R[3 * b + kk] * R[3 * b + ll];
    }
    return x;
}

/* Newton on the free stretches of f from v, each step halved while the state beyond it fails;
** the state at the end into s. */
static cf_status load_newton(const cf_cell *c, const double R[9], const load_form *f,
                             const cf_cell_extra *x, double v[2], cf_cell_state *s, cf_error *err)
{
    double F[9], A[81];
    load_place(R, f, v, F);
    cf_status st = cf_cell_tangent(c, F, x, s, A, err);
    for (int it = 0; st == CF_OK && it < MAX_ITER; it++) {
        double r[2], J[2][2], dv[2];
        for (int a = 0; a < f->nfree; a++) {
            r[a] = frame_stress(R, &s->P_MPa[0][0], f->fr[a], f->fr[a]);
            for (int b = 0; b < f->nfree; b++)
                J[a][b] = frame_tangent(R, A, f->fr[a], f->fr[b]);
        }
        if (f->nfree == 1)
            dv[0] = -r[0] / J[0][0];
        else {
            const double det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
            dv[0] = -(J[1][1] * r[0] - J[0][1] * r[1]) / det;
            dv[1] = -(J[0][0] * r[1] - J[1][0] * r[0]) / det;
        }
        double step = 0;
        for (int a = 0; a < f->nfree; a++)
            step = fmax(step, fabs(dv[a]));
        if (!isfinite(step))
            return cf_error_set(err, CF_E_NOCONV, "the free stretches' tangent is singular at "
                                "%.17g", v[0]);
        double vn[2] = {v[0], v[1]};
        for (int h = 0; h < 60; h++) {
            for (int a = 0; a < f->nfree; a++)
                vn[a] = v[a] + dv[a];
            load_place(R, f, vn, F);
            if (vn[0] > 0 && (f->nfree < 2 || vn[1] > 0) &&
                (st = cf_cell_tangent(c, F, x, s, A, NULL)) == CF_OK)
                break;
            dv[0] *= 0.5, dv[1] *= 0.5;
            st = CF_E_DATA;
        }
        if (st != CF_OK)
            break;
        v[0] = vn[0], v[1] = vn[1];
        if (step <= 1e-15 * fmax(1.0, fabs(v[0])))
            return CF_OK;
    }
    if (st != CF_OK)
        return cf_error_set(err, CF_E_DATA, "no free stretch near %.6g reachable: a spring of "
                            "the cell reaches solid", v[0]);
    return cf_error_set(err, CF_E_NOCONV, "no free stretch gives zero lateral stress (last "
                        "%.17g)", v[0]);
}

/* The state of ld at e on the axes of R (rows: unit axes in the lattice frame). */
static cf_status load_solve(const cf_cell *c, const double R[9], const cf_cell_load *ld,
                            double e, const cf_cell_extra *x, cf_cell_state *s, cf_error *err)
{
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) {
            double d = 0;
            for (int i = 0; i < 3; i++)
                d += R[3 * a + i] * R[3 * b + i];
            if (!(fabs(d - (a == b)) <= 1e-12))
                return cf_error_set(err, CF_E_DATA, "fibre frame: axes %d and %d have dot "
                                    "product %.17g (an orthonormal frame is needed)", a, b, d);
        }
    load_form f;
    cf_status st = load_form_of(ld, e, &f, err);
    if (st != CF_OK)
        return st;
    double v[2] = {1, 1}, F[9];
    if (f.nfree == 0) {
        load_place(R, &f, v, F);
        st = cf_cell_stress(c, F, x, s, err);
    } else {
        cf_error e1 = {0};
        const double lp = f.F0[4 * ld->axis[0]], lq = f.F0[4 * ld->axis[1]];
        v[0] = v[1] = f.nfree == 2 ? 1 / sqrt(lp) : 1 / (lp * lq); /* an incompressible guess */
        st = load_newton(c, R, &f, x, v, s, &e1);
        if (st != CF_OK) { /* from the reference stretches instead */
            v[0] = v[1] = 1;
            st = load_newton(c, R, &f, x, v, s, &e1);
        }
        if (st != CF_OK)
            return cf_error_set(err, st, "%s strain %g: %s", cf_mode_name(ld->mode), e, e1.msg);
    }
    if (st != CF_OK)
        return st;
    s->free_stretch = f.nfree ? v[0] : 1;
    s->stress_MPa = frame_stress(R, &s->P_MPa[0][0], f.si, f.sj);
    return CF_OK;
}

cf_status cf_cell_load_state(const cf_cell *c, const cf_cell_load *ld, double e,
                             cf_cell_state *s, cf_error *err)
{
    return load_solve(c, c->frame, ld, e, NULL, s, err);
}

/* cf_cell_mode of a cell with fibres: the mode on the lattice's axes, as cf_cell_load places it. */
static cf_status mode_with_fibres(const cf_cell *c, cf_mode m, double e, const cf_cell_extra *x,
                                  cf_cell_state *s, cf_error *err)
{
    static const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    cf_cell_load ld = {m, {0, 1}, c->biaxial_k};
    if (m == CF_MODE_UNIAXIAL || m == CF_MODE_CONFINED)
        ld.axis[0] = 2, ld.axis[1] = 0;
    else if (m == CF_MODE_SHEAR)
        ld.axis[0] = 2, ld.axis[1] = 0;
    return load_solve(c, I, &ld, e, x, s, err);
}

cf_status cf_cell_mode(const cf_cell *c, cf_mode m, double e, const cf_cell_extra *extra,
                       cf_cell_state *s, cf_error *err)
{
    if ((int)m < 0 || m >= CF_MODE_COUNT)
        return cf_error_set(err, CF_E_DATA, "mode %d: unknown", (int)m);
    /* a stretch must stay positive; simple shear has no stretch and takes any amount */
    const int any_sign = cf_mode_row_of(m)->any_sign;
    if (!isfinite(e) || (!any_sign && !(e > -1)))
        return cf_error_set(err, CF_E_DATA, "%s strain %g: must be finite%s", cf_mode_name(m), e,
                            any_sign ? "" : " and > -1");
    if (c->nfibre > 0)
        return mode_with_fibres(c, m, e, extra, s, err);
    const mode_form fm = form_of(m);
    double F[9], kT[CF_CELL_DIRS];
    cf_status st;
    if (fm.zero < 0) {
        cf_mode_place_k(m, e, 1, c->biaxial_k, F);
        if ((st = evaluate(c, F, extra, s, kT, err)) != CF_OK)
            return st;
        return settled(s, &fm, 1);
    }
    /* Safeguarded Newton on r(a) = P[zero][zero], increasing in a: a bracket [lo, hi] with
    ** r(lo) < 0 < r(hi) is kept once known; a step that leaves it, or the domain, bisects. */
    const cf_law *edge = fam_law(c, CF_FAMILY_EDGE); /* the free axis's edge */
    const double sH = edge->travel_mm / edge->p.H_mm; /* compression side */
    const double sHe = cf_law_travel_at(edge, -1) / edge->p.H_mm; /* extension side */
    bracket b = {1 - sH, 1 + sHe, 0, 0}; /* the edge along a free axis reaches solid there */
    double a = c->stretch_hint > 0 ? c->stretch_hint : guess(c, m, e);
    a = fmin(fmax(a, b.lo + 1e-3 * sH), b.hi - 1e-3 * sHe);
    cf_error e1 = {0};
    double newton_before = 0; /* the Newton step that led to a, 0 when a came otherwise */
    for (int it = 0; it < MAX_ITER; it++) {
        cf_mode_place_k(m, e, a, c->biaxial_k, F);
        st = evaluate(c, F, extra, s, kT, &e1);
        if (st != CF_OK) {
            newton_before = 0;
            /* outside the domain: move halfway back toward the bracket's inside */
            if (a > 1)
                b.hi = a;
            else
                b.lo = a;
            a = 0.5 * (b.lo + b.hi);
            if (b.hi - b.lo <= 4 * DBL_EPSILON * b.hi)
                break;
            continue;
        }
        double r = s->P_MPa[fm.zero][fm.zero];
        if (fabs(r) <= lateral_rounding(c, s))
            return settled(s, &fm, a);
        const double g = tangent(c, s, kT, fm.zero, fm.free_mask);
        double an = next_stretch(&b, a, r, g);
        if (fabs(an - a) <= 2 * DBL_EPSILON * fabs(a)) {
            if (an == a) /* the state just evaluated is the one it would place again */
                return settled(s, &fm, a);
            a = an;
            cf_mode_place_k(m, e, a, c->biaxial_k, F);
            if ((st = evaluate(c, F, extra, s, kT, &e1)) != CF_OK)
                break;
            return settled(s, &fm, a);
        }
        /* Newton's error after this step is about C da^2, with C = |da| / db^2 from the step db
        ** before it: when that is below rounding and da small enough for the state to be linear
        ** in it, the state at an comes from the linearisation at a */
        const double da = an - a;
        const int newton = g > 0 && an == a - r / g;
        if (c->linear_finish && c->volume_modulus_MPa == 0 && newton && newton_before != 0 &&
            fabs(da) <= LINEAR_STEP * fabs(a) &&
            fabs(da) * da * da <= DBL_EPSILON * fabs(a) * newton_before * newton_before)
            return settle_linear(c, &fm, kT, s, a, da);
        newton_before = newton ? da : 0;
        a = an;
    }
    if (st == CF_OK && s->P_MPa[fm.zero][fm.zero] == 0)
        return settled(s, &fm, a);
    if (st != CF_OK && (b.have_lo || b.have_hi))
        return cf_error_set(err, CF_E_DATA, "%s strain %g: %s", cf_mode_name(m), e, e1.msg);
    if (st != CF_OK)
        return cf_error_set(err, CF_E_DATA, "%s strain %g is beyond what the lattice reaches: %s",
                            cf_mode_name(m), e, e1.msg);
    return cf_error_set(err, CF_E_NOCONV,
                        "%s strain %g: no free stretch gives zero lateral stress (last %.17g)",
                        cf_mode_name(m), e, a);
}
