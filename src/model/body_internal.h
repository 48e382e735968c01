/*
** What the files of the tissue body share (body.c: the springs, their calibration and the probe's
** geometry; body_assemble.c: the tangent's pattern, the forces and tangent; body_work.c: the
** solvers' workspace and the body as a mechanical system (mech.h); body_solve.c: the static probe
** solve; body_haptic.c: the probe loop at haptic rate). Private to
** the model layer.
*/
#ifndef CF_MODEL_BODY_INTERNAL_H
#define CF_MODEL_BODY_INTERNAL_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "model/body.h"
#include "model/mech.h"
#include "model/linsolve.h"

/* Six times the signed volume of the tetrahedron a, b, c, d. */
static inline double body_vol6(const double *a, const double *b, const double *c, const double *d)
{
    double u[3], v[3], w[3];
    for (int k = 0; k < 3; k++) {
        u[k] = b[k] - a[k];
        v[k] = c[k] - a[k];
        w[k] = d[k] - a[k];
    }
    return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
           u[2] * (v[0] * w[1] - v[1] * w[0]);
}

/* A spring's length, unit axis (from i to j) and law compression at positions x. */
static inline double body_spring_geom(const cf_body *b, const double *x, size_t s, double n[3], double *u)
{
    const double *p = x + 3 * b->si[s], *q = x + 3 * b->sj[s];
    double d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
    double L = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int k = 0; k < 3; k++)
        n[k] = d[k] / L;
    *u = b->law->p.H_mm * (b->L0[s] - L) / b->L0[s];
    return L;
}

/* The element term of tetrahedron t at positions x (body_elem.c): its energy's gradient f
** (node m, component i at 3 m + i) and, when K is not NULL, its Hessian K (row 3 m + i, column
** 3 q + j at 12 (3 m + i) + 3 q + j). Returns 0 for a flat reference tetrahedron. */
int body_elem_tet(const cf_body *b, const double *x, size_t t, double f[12], double K[144]);
/* Adds the element term's share of each node's virial (6 per node, VTK's order) to sn. */
void body_elem_virial(const cf_body *b, const double *x, double *sn);

static inline double body_norm_inf(const double *v, size_t n)
{
    double m = 0;
    for (size_t i = 0; i < n; i++)
        m = fmax(m, fabs(v[i]));
    return m;
}

/* The sparse pattern of the tangent in 3 x 3 blocks: column node j holds the blocks of the nodes
** in nb[nbp[j] .. nbp[j + 1]) (sorted, j among them): the nodes of the tetrahedra around j (its
** springs' other ends), and with a volume term those of the tetrahedra around each of these (the
** nodal volume couples every pair of nodes around one node). */
typedef struct pattern {
    size_t n;              /* 3 nn */
    int *colptr, *rowidx;  /* the linear solver's copy (cf_linsolve_pattern) once it is made */
    int borrowed;          /* 1: colptr and rowidx are the linear solver's, not freed here */
    int aug;               /* 1: the augmented form (n = 4 nn): a pressure unknown per node for the
                              nodal volume term (volume_coupling in body_assemble.c), the
                              neighbours of each node alone in the pattern */
    double *val;           /* the tangent's values for the haptic loop, made at its first
                              assembly (the static solve writes into the linear solver's) */
    size_t *nbp;           /* nn + 1 */
    uint32_t *nb;
    size_t *tp;            /* tetrahedra around each node: tl[tp[a] .. tp[a + 1]) */
    uint32_t *tl;
    /* block indices found once (a search per block at every assembly cost more than the rest):
    ** per spring (i, j): (i in i), (j in j), (i in j), (j in i); per tetrahedron: (row m in
    ** column q) for its 16 corner pairs; per node a with a volume term: its ring (the nodes of
    ** the tetrahedra around it, in the order the assembly meets them) and the blocks of every
    ** pair of ring nodes */
    uint32_t *sblk, *tblk;
    size_t *rp;            /* nn + 1: ring of a in rn[rp[a] .. rp[a + 1]) */
    uint32_t *rn;
    size_t *bp;            /* nn + 1: blocks of a's ring pairs in rblk[bp[a] ..), row-major */
    uint32_t *rblk;
} pattern;

/* Adds the 3 x 3 block B (row-major) to block `blk` of node col's columns. */
static inline void body_add_block(pattern *P, size_t col, size_t blk, const double B[9])
{
    for (int c = 0; c < 3; c++) {
        double *v = P->val + P->colptr[3 * col + c] + 3 * blk;
        for (int a = 0; a < 3; a++)
            v[a] += B[3 * a + c];
    }
}

/* body_fibres.c */
/* Adds the fibre groups' energy gradient at positions x to g (3 nn) and, when P is not NULL,
** their tangent (the blocks of each tetrahedron's corners, P->tblk). A fibre at solid adds
** nothing (cf_body_admissible refuses such positions). */
void cf_body_fibre_forces(const cf_body *b, const double *x, double *g, pattern *P);
/* Adds to the virial sn (6 nn, VTK's order) of each corner a quarter of each tetrahedron's fibre
** virial V0 F P^T = V0 sum_groups phi (F a)(F a)^T (fibre.h; tension positive, N mm), at x. */
void cf_body_fibre_virial(const cf_body *b, const double *x, double *sn);
/* The largest compression over travel of the fibre springs at positions x (>= 1 at solid). */
double cf_body_fibre_umax(const cf_body *b, const double *x);

struct body_work;

/* The body as a mechanical system (mech.h) for the static solve: the probe at c with penalty kp
** on the contact set w->active, and what the last residual found. */
typedef struct body_sys {
    cf_body *b;
    struct body_work *w;
    pattern *P;         /* the pattern of the linear systems: w->Pa with a volume term, else w->P */
    const cf_probe *probe;
    const double *c;
    double kp;
    double force;       /* the reaction along the probe's direction, N */
    int contacts;
} body_sys;

/* The body as the haptic loop's mechanical system (body_haptic.c) during one update: the probe at
** c with penalty kp on the contact set held through the update (m nodes in list[], their normals
** nv[3 m]; M and rhs the Woodbury system's room, all of cap entries, kept between updates), and
** the force read last (from the residual's contact, or from the body's side after a step). */
typedef struct haptic_sys {
    cf_body *b;
    struct body_work *w;
    const cf_probe *probe;
    const double *c;
    double kp;
    size_t *list;
    double *nv, *M, *rhs;
    size_t m, cap;
    double force;       /* N, along the probe's direction */
    int contacts;
    int evaluated;      /* a residual evaluated in this update (the next renews the normals) */
    int stepped;        /* a step taken since the last residual (its reaction not read yet) */
} haptic_sys;

/* What the solves of a body keep between calls: the pattern, the body as a mechanical system with
** its linear solver (mech.h, linsolve.h: the analysed factorisation and the last factors, reused as
** chord steps while they converge fast enough), and work vectors. */
typedef struct body_work {
    pattern P;          /* the condensed tangent's (with a volume term the neighbours of
                           neighbours): the haptic loop's, made by cf_body_work_get; without a
                           volume term also the static solve's */
    pattern Pa;         /* with a volume term, the static solve's augmented form (pattern.aug) */
    body_sys sys;
    cf_mech mech;
    double *g, *dx, *xt; /* g and dx: 3 nn + the augmented form's nn */
    double *gt;         /* 3 nn: the gradient while the tangent is written */
    uint8_t *active;
    uint8_t *touch;     /* nn: 1 = a node on the body's surface, which a probe can touch */
    double *xs;         /* 3 nn: the body at the last converged part of a static solve's move */
    double c_last[3];   /* the probe's reference point at the last converged static solve */
    double depth_last;  /* and its depth, mm */
    int has_last;       /* 0 before the first */
    long neg_last;      /* negative eigenvalues of the static solve's last fresh tangent, -1 none */
    int factored;       /* the linear solver holds the factors of a tangent of this body (the
                           haptic loop clears it) */
    /* the haptic loop (cf_body_haptic_step): the body as its mechanical system, solved by the
    ** Newton driver in chord-only mode on a linear solver with the condensed pattern P holding
    ** the factors of the tangent without contact, taken once, and per node that has touched the
    ** probe the three columns of its inverse at that node (slot[i] + 1 indexes Z, 0 = none yet) */
    haptic_sys hsys;
    cf_mech hmech;      /* hmech.ls: that linear solver (NULL before the loop's first use) */
    int hfactored;
    uint8_t *hactive;
    uint32_t *slot;
    double *Z;          /* 9 nn per slot: columns 3 nn each */
    size_t nslot, capslot;
    double *hrhs;
    double *hgi, *hxg;  /* 3 nn: the internal forces (no contact) where the last update left the
                           body, and those positions (the next update starts from them when the
                           body has not moved since) */
    /* an implicit dynamic step (body_dynamic.c) while it solves: the inertia (and mass-
    ** proportional damping) of a Newmark step as a term mcoef m_i (x - xstar)
    ** in the residual and mcoef m_i on the tangent's diagonal; mcoef 0 = a static solve */
    const double *mass; /* nn lumped masses, t */
    const double *xstar;
    double mcoef;       /* 1/s^2 */
} body_work;

/* body.c */
/* Penetration of the node at p into the probe whose reference point is at c, and the unit
** direction in which the probe pushes it. With signed = 0: 0 when the node is outside. With
** signed = 1 (a node of the active set): the signed depth along that direction, negative when the
** node has left the probe's surface. */
double cf_body_penetration(const cf_probe *pr, const double *c, const double *p, double nrm[3],
                           int sgn);

/* Marks (mark[i] = 1, nn entries; 0 elsewhere) the nodes a probe can touch: those on the body's
** surface (of a face that only one tetrahedron has). An interior node
** inside a probe is not touched by it: it is where it is because the surface above it has not
** yet moved, and pushing it out would flatten the tetrahedra between it and the surface.
** Returns 0 when memory runs out. */
int cf_body_touchable(const cf_body *b, uint8_t *mark);

/* body_assemble.c */
/* Energy gradient g (3 nn) and, when P is not NULL, the tangent at positions x; contact forces of
** the probe at c added (as -f to g) with their tangent. Returns the reaction along the probe's
** direction and the number of nodes in contact; NAN when memory runs out. */
double cf_body_assemble(const cf_body *b, const double *x, const cf_probe *pr, const double *c,
                        double kp, const uint8_t *active, double *g, pattern *P, int *contacts);
/* Adds the inertia of an implicit dynamic step (w->mcoef > 0) at positions x to g and, when P is
** not NULL, to the tangent's diagonal blocks. */
void cf_body_add_inertia(const cf_body *b, const body_work *w, const double *x, double *g,
                         pattern *P);
/* The residual g (before cf_body_apply_fixed) at the held components into b->reaction. */
void cf_body_keep_reaction(const cf_body *b, const double *g);
/* The contact forces of the probe at c (penalty kp, nodes of the set active) on every node into
** b->contact (when there is one), N. */
void cf_body_keep_contact(const cf_body *b, const cf_probe *pr, const double *c, double kp,
                          const uint8_t *active);
/* Zeroes the rows and columns of fixed components (diagonal 1) and their gradient entries (g of
** 3 nn entries; P's pressure columns, in the augmented form, lose their rows of fixed
** components). */
void cf_body_apply_fixed(const cf_body *b, pattern *P, double *g);
/* 1 when positions x invert no tetrahedron and take no spring to solid. */
int cf_body_admissible(const cf_body *b, const double *x);
/* The tangent's pattern of b (colptr, rowidx and the block indices; val left NULL), and its
** release. aug = 1 with a volume term: the augmented form (pattern.aug). 0 when memory runs out. */
int cf_body_pattern_build(const cf_body *b, pattern *P, int aug);
void cf_body_pattern_free(pattern *P);

/* body_work.c */
/* The body's workspace (made at the first call: the body as a mechanical system with its linear
** solver and the pattern of its systems): cf_body_work_static for the static and dynamic solves;
** cf_body_work_get (the haptic loop's) also makes the condensed pattern w->P when there is a
** volume term (the neighbours of neighbours: the augmented form's systems do without it). And its
** release. */
cf_status cf_body_work_static(cf_body *b, body_work **out, cf_error *err);
cf_status cf_body_work_get(cf_body *b, body_work **out, cf_error *err);
void cf_body_work_free(body_work *w);

#endif
