/*
** The joint fit's working state and what its files share (joint.c: the context, the conical and
** tailed searches, the run and the public calls; joint_pair.c: the double-acting element's and
** the volume term's search; joint_stable.c: the full lattice's stability and each table's
** verification). Private to the fit layer: none of these names is in a public header.
*/
#ifndef CF_FIT_JOINT_CTX_H
#define CF_FIT_JOINT_CTX_H

#include <stddef.h>

#include "model/cell.h"
#include "model/family.h"
#include "fit/joint.h"
#include "model/law_internal.h"
#include "fit/cell_problem.h"

/* BOBYQA's relative step tolerance (each curve a few tens of microseconds). */
#define XTOL_REL 1e-7
/* Diagonal-to-edge weight ratio searched when the weights are fitted. */
#define Q_LO 0.02
#define Q_HI 5.0
/* The box of ln q: [ln Q_LO, ln Q_HI], within opt->anisotropy_max's Zener ratios when given. */
void cf_joint_q_box(const cf_fit_options *opt, double *lb, double *ub);
/* BOBYQA's initial step in ln q: 0.2 (fine 0.05), at most 0.4 of the box. */
double cf_joint_q_step(double lb, double ub, int fine);
/* relative step of the tailed law's errors' central differences, as its single fit through the
** lattice takes (lattice_tail.c); the pair's errors take it too */
#define TAIL_FD_STEP 1e-4

typedef struct jctx {
    const cf_table *const *t;
    size_t n;
    const cf_fit_options *opt;
    const cf_validate_setup *lat;
    cf_spring_type type;
    int fit_weights;
    double weight[CF_FAMILY_COUNT]; /* the fixed weights (or the last tried) */
    double *sw[CF_JOINT_MAX];       /* per-row residual weights 1/(s_k sqrt n_k) */
    double *curve[CF_JOINT_MAX];    /* scratch: each table's cell curve at unit scale */
    cf_cell_problem pr;             /* every table's rows in order, with their weights */
    int tail;                       /* 1: the conical-tail law's members, their tail tau */
    double tau;
    double need;                    /* the largest spring strain with the travel margin */
    /* the double-acting element and the volume term (cf_joint_fit_pair) */
    int pair;                       /* 1: every curve's law has the extension spring ext */
    double ext[3];                  /* its rho, s/H and stress scale over the compression one's */
    int kappa_mode;                 /* the cell's kappa: KAPPA_* */
    double kappa;                   /* KAPPA_REL: over the compression spring's k0/H; KAPPA_UNIT:
                                    ** over its stress scale; KAPPA_NU: the declared nu */
    /* the pair's search keeps to lattices stable over the uniaxial tables' ranges: a point that
    ** would lower the best objective of the current start (stab_best) counts only when its full
    ** lattice is stable there (joint_stable_at; the pair's search reports such a point mirrored
    ** above stab_best, joint_pair.c); stab_on 0: no such check */
    int stab_on;
    double stab_best;
    /* the springs' reach over every table, which the placement honours: with it set, the pair's
    ** stability wall also asks both springs to be buildable (NULL: stability alone) */
    const cf_table *reach;
    /* a fitted kappa's bound over the compression spring's k0/H (CF_JOINT_NU_MAX; 0: none) */
    double kappa_rel_max;
} jctx;

/* How a curve's volume modulus is set (jctx.kappa_mode): none; kappa/(k0/H) of the compression
** spring (the fit's search variable); kappa per unit stress scale (a declared kappa over the
** stress scale held, or the errors' Jacobian); from a declared nu. */
enum { KAPPA_NONE = 0, KAPPA_REL, KAPPA_UNIT, KAPPA_NU };

/* The cell's volume modulus for a curve whose compression law (at stress scale 1) is law. */
double cf_joint_curve_kappa(const jctx *c, const cf_law *law);
/* Family weights of ratio q (face = body = q edge), scaled to the law's small-strain modulus. */
void cf_joint_weights_of(double q, double w[CF_FAMILY_COUNT]);
/* Every table's cell curve at stress scale 1 for (rho, B), the tables one after another (the
** cell problem's curve; ctx a jctx). 0, or 1 where a curve fails. */
int cf_joint_curve(void *ctx, double rho, double B, double *out);
/* 1 when the full lattices of the context's law at (rho, B) are stable over every uniaxial
** table's range at the search's strains (joint_stable.c). */
int cf_joint_stable_at(const jctx *c, double rho, double B);
/* Each table in the lattice of the placed spring r->fit (joint_stable.c). */
cf_status cf_joint_verify_tables(const jctx *c, cf_joint_result *r, cf_error *err);
/* The double-acting element's (and the volume term's) search (joint_pair.c). */
cf_status cf_joint_search_pair(jctx *c, const cf_table *reach, double xmax,
                               const cf_joint_result *plain, cf_joint_result *r, cf_error *err);

/* The eight (at most) quantities v = rho_c, B_c, A_c, rho_e, B_e, A_e, kappa, tau (the
** compression spring's tail) into the context for a curve at stress scale 1 (kappa over A_c). */
enum { PQ_RC = 0, PQ_BC, PQ_AC, PQ_RE, PQ_BE, PQ_AE, PQ_K, PQ_T, PQ_COUNT };

/* The pair's least-squares problem (joint_pair_lsq.c): the largest compression stress scale at
** (rho, B) with the context's extension spring (0 where either spring cannot be placed); the
** compression spring of v at stress scale 1; v polished by Levenberg-Marquardt over the used
** quantities inside box (returns the RSS at v); the standard errors of the used quantities (se -1
** where not determined; 0, or -1 when memory runs out or a curve fails); the lattice's
** small-strain E and nu in tension and compression into r. */
double cf_joint_pair_A_max(void *ctx, double rho, double B);
cf_spring cf_joint_compression_member(const jctx *c, const double v[PQ_COUNT]);
double cf_joint_pair_polish(jctx *c, double v[PQ_COUNT], const int used[PQ_COUNT],
                            const double box[4]);
int cf_joint_pair_errors(jctx *c, const double v0[PQ_COUNT], const int used[PQ_COUNT],
                         double rss, double se[PQ_COUNT], double *cov_bt);
void cf_joint_small_strain_moduli(jctx *c, const double v[PQ_COUNT], cf_joint_result *r);
/* Both springs of the quantities v placed into r (the extension spring at the compression
** spring's H; fit.feasible says whether both are buildable). */
cf_status cf_joint_pair_place(const jctx *c, const cf_table *reach, const double v[PQ_COUNT],
                              cf_joint_result *r, cf_error *err);
/* 1 when both springs of the context's law at (rho, B) and compression stress scale A can be
** built (cf_joint_pair_place over c->reach; 1 when the context has no reach). */
int cf_joint_pair_buildable(const jctx *c, double rho, double B, double A);
/* The fitted kappa of a law a search contains over its compression spring's k0/H (KAPPA_REL);
** 0 when it has none. */
double cf_joint_nest_kappa_rel(const cf_joint_result *plain);

/* the tailed compression spring's tau (its tail's coils over the cone's): the search's range */
#define TAU_LO 1e-3
#define TAU_HI 30.0
/* The pair's and the volume term's search variables, in order: ln rho, s/H of the compression
** spring; with the pair ln rho, s/H of the extension spring and ln of its stress scale over the
** compression one's; with kappa fitted ln (kappa/(k0/H)); with kappa declared ln of the stress
** scale (held, kappa over it then known); with fitted weights ln q; with a tailed compression
** spring ln tau, its tail's coils over the cone's. */
typedef struct pvars {
    int n;                         /* variables */
    int ie, ik, iA, iq, it;        /* index of the extension's first, kappa's, A's, q's, tau's;
                                   ** -1 none */
    double lb[8], ub[8];
} pvars;
/* The search's variables and their box into pv and the context's problem (joint_pair_lsq.c);
** xmax the tables' farthest strain. */
cf_status cf_joint_pair_box(jctx *c, double xmax, pvars *pv, cf_error *err);

#endif
