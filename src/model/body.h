/*
** Tissue bodies: a tetrahedral volume mesh whose every edge carries the fitted spring law, scaled
** per edge so that the network is the fitted material at small strain, plus a volume term; regions
** fixed, a rigid probe pressed into it, static equilibria solved by Newton's
** method with the sparse solver of the lattice. Schema and physics: src/notes/simulate.md, "Bodies".
**
** The material. The cubic lattice with its isotropic calibration (calibration.h) is a material of
** Young's modulus E0 = k0/H and nu = 1/4, so shear modulus mu = E0/2.5 (k0 the law's linear
** stiffness, H its free length). A body is the same material: every edge of rest length L0 carries
** the law in strain form (the compression u = H (L0 - L)/L0, as the lattice's diagonals do) times
** a factor c, so that its axial stiffness at small strain is k = c k0 H/L0. The edge stiffnesses
** come from matching, tetrahedron by tetrahedron, the tangent of its six springs to the isotropic
** tangent with Lame constants lambda = mu (the one isotropic tensor central springs can give,
** the Cauchy relation): a linear tetrahedron deforms affinely, so its spring stiffness matrix is
** V B^T C_s B with C_s = (1/V) sum_e k_e L_e^2 n_e n_e n_e n_e, and matching C_s to the isotropic
** C in the least-squares sense (over the 15 independent components of a fully symmetric tensor,
** k_e >= 0) matches the element's stiffness matrix to the linear finite element's V B^T C B in a
** norm of the tensors (Lloyd, Szekely & Harders 2007, IEEE TVCG 13:1081-1094, match the 12 x 12
** matrices themselves; San-Vicente, Aguinaga & Celiguieta 2012 fit the same kind of per-element
** constants). An edge's stiffness is the sum of its tetrahedra's shares. Since a single
** tetrahedron's six directions cannot be isotropic, the mesh's volume-averaged tensor is then
** projected on the isotropic tensors and every c scaled once so that its shear modulus is mu.
**
** The volume term. W = V0 (kappa/2)(J - 1)^2 per unit reference volume V0, J its volume ratio,
** the same term as the homogenised cell's: it adds kappa to lambda and nothing to mu, so
** nu = (mu + kappa)/(2 (2 mu + kappa)). J is taken per node (a quarter of the volume of every
** tetrahedron around it; Bonet & Burton 1998), so that linear tetrahedra do not lock as nu nears
** 1/2; each tetrahedron's own J is reported. A scene gives kappa ("volume_modulus_MPa") or nu
** ("poisson_ratio", 0.25 <= nu < 0.5, kappa = mu (4 nu - 1)/(1 - 2 nu)).
**
** Units: mm, N, MPa. Sign: the probe's force is positive pushing into the body.
*/
#ifndef CF_BODY_H
#define CF_BODY_H

#include <stddef.h>
#include <stdint.h>

#include "conifit/error.h"
#include "model/fibre.h"
#include "model/law_internal.h"
#include "model/net.h"

/* A tetrahedral mesh: nodes (mm) and elements of four node indices each, every element positively
** oriented (its signed volume (x1-x0).((x2-x0)x(x3-x0))/6 > 0). */
/* A physical group of the mesh's file (Gmsh's named or numbered sets of elements): the mesh's
** nodes on its elements. */
typedef struct cf_mesh_group {
    int dim, tag;       /* Gmsh's dimension (0 to 3) and number of the group */
    char name[128];     /* its name, "" when it has none */
    size_t nnodes;
    uint32_t *nodes;    /* nnodes indices into the mesh's nodes, sorted */
} cf_mesh_group;

typedef struct cf_mesh {
    size_t nn, nt;
    double *X;      /* 3 nn coordinates, mm */
    uint32_t *tet;  /* 4 nt node indices */
    uint32_t *id;   /* nn node numbers of the file (1-based for a generated block) */
    uint64_t *eid;  /* nt element numbers of the file (a hexahedron's six tetrahedra share one) */
    size_t ngroups;
    cf_mesh_group *groups; /* the file's physical groups (none for a generated mesh) */
} cf_mesh;

void cf_mesh_free(cf_mesh *m);

/* A block of tetrahedra on the grid xs[0..nx] x ys[0..ny] x zs[0..nz] (mm, each strictly
** increasing, at least two values), every cell split into six tetrahedra around one of its body
** diagonals (Kuhn's subdivision), the cell mirrored along each axis where its index is odd, so
** that neighbouring cells' faces match and the block holds both diagonals of every face.
** A graded grid refines where the coordinates are dense. CF_E_DATA for a bad grid. */
cf_status cf_mesh_block(cf_mesh *m, const double *xs, int nx, const double *ys, int ny,
                        const double *zs, int nz, cf_error *err);

/* Checks m and orients it: every coordinate finite, every node index in range, every element of
** volume above 1e-12 of the cube of its longest edge (else "degenerate"), all elements of one
** orientation (an element whose orientation differs from the majority's is "inverted"); a mesh
** whose elements are all negatively oriented is renumbered. `name` is used in messages, which
** name the element by its number in the file. CF_E_DATA. */
cf_status cf_mesh_check(cf_mesh *m, const char *name, cf_error *err);

/* A region of a body: the nodes a selector picks. A new kind of selector is a row of the table
** in body_region.c (its name and its test of a node) and a case of the scene's reader. */
typedef enum cf_select_kind {
    CF_SELECT_BELOW = 0,  /* n . X <= value_mm */
    CF_SELECT_ABOVE = 1,  /* n . X >= value_mm */
    CF_SELECT_BOX = 2,    /* lo_mm <= X <= hi_mm, every component */
    CF_SELECT_SPHERE = 3, /* |X - center_mm| <= radius_mm */
    CF_SELECT_GROUP = 4   /* the nodes of the mesh's physical groups of that name or number */
} cf_select_kind;

typedef struct cf_select {
    cf_select_kind kind;
    double n[3];          /* below, above: unit normal of the plane */
    double value_mm;      /* below, above: n . X of the plane */
    double lo_mm[3], hi_mm[3];        /* box */
    double center_mm[3], radius_mm;   /* sphere */
    int group_tag;        /* group: its number, or -1 to go by name */
    int group_dim;        /* group: its dimension, or -1 for groups of any dimension */
    char group_name[128]; /* group: its name when group_tag is -1 */
} cf_select;

/* The name of a selector kind as a scene writes it ("below", "above", "box", "sphere", "group"). */
const char *cf_select_name(cf_select_kind kind);

/* Sets mark[i] = 1 for every node i of m that s selects (mark has m->nn entries; other entries
** are left as they are) and returns how many it selects. A node on a selector's boundary is
** selected (the comparisons allow 1e-9 of the mesh's extent, so that nodes on a plane given by
** their coordinate are in). */
size_t cf_mesh_select(const cf_mesh *m, const cf_select *s, uint8_t *mark);

/* Where a scene's regions, probe and outputs come from. */
typedef enum cf_probe_shape { CF_PROBE_SPHERE = 0, CF_PROBE_PUNCH = 1 } cf_probe_shape;

typedef struct cf_probe {
    cf_probe_shape shape;
    double radius_mm;
    double center_mm[3]; /* sphere centre, or the centre of the punch's flat face, at depth 0 */
    double dir[3];       /* unit direction of travel */
    double depth_mm;     /* travel at the last step */
    int steps;           /* equal steps from 0 to depth_mm (or to force_N) */
    double force_N;      /* > 0: the probe is driven by force instead, to this force at the last
                         ** step (depth_mm unused); 0: by depth (last, so that an initialiser of
                         ** the fields above in order still holds) */
} cf_probe;

/* Most spring groups of a body (cf_body_set_groups). */
#define CF_BODY_MAX_GROUPS 8

/* The body: the mesh's nodes and tetrahedra, its edges as springs. */
typedef struct cf_body {
    const cf_law *law;     /* not owned */
    cf_law_method method;
    size_t nn, ns, nt;
    double *X, *x;         /* 3 nn reference and current positions, mm */
    uint8_t *fix;          /* per node: bit c (1, 2, 4) set = component c held where it is */
    uint32_t *tet;         /* 4 nt */
    double *V0;            /* nt reference volumes, mm^3 */
    uint32_t *si, *sj;     /* ns spring end nodes */
    double *L0;            /* ns rest lengths, mm */
    double *c;             /* ns factors on the law force, - */
    double mu_MPa;         /* shear modulus the calibration aims at, E0/2.5 */
    double kappa_MPa;      /* volume modulus of the volume term */
    double E_MPa, nu;      /* the body's small-strain E and nu (isotropic part of its tangent) */
    double mean_edge_mm;   /* mean rest length of the springs */
    double *f_ext;         /* 3 nn external forces on the nodes (N), or NULL for none; the solves
                           ** balance them. Set by the caller, released by cf_body_free */
    double *reaction;      /* 3 nn, or NULL: when the caller allocates it, each solve leaves there
                           ** the force the supports apply at every held component (N; 0 at free
                           ** ones). Released by cf_body_free */
    double *contact;       /* 3 nn, or NULL: when the caller allocates it, each solve leaves there
                           ** the probe's contact force on every node (N; 0 off the contact set).
                           ** Released by cf_body_free */
    void *work;            /* the solver's pattern, factors and vectors (NULL until the first
                           ** solve; cf_body_free releases them). Not thread-safe: one solve of a
                           ** body at a time */
    /* spring groups (cf_body_set_groups): */
    size_t ngroups;        /* groups with a law of their own (0: every spring takes law) */
    uint8_t *group;        /* ns: the spring's group, 0 for law's, g for group g; NULL: none */
    const cf_law *glaw[CF_BODY_MAX_GROUPS + 1]; /* glaw[0] = law, glaw[g] = gown + g - 1 */
    cf_law *gown;          /* the groups' laws (owned) */
    /* fibre groups (cf_body_add_fibres; src/notes/simulate.md, "Fibres in a body"): */
    size_t nfibre;         /* 0: none */
    cf_law *flaw;          /* CF_FIBRE_MAX laws (owned), group k's in flaw[k] */
    double fdensity[CF_FIBRE_MAX]; /* springs per lattice cell of edge law->p.H_mm */
    double fslack[CF_FIBRE_MAX];   /* each group's recruitment strain (fibre.h), - */
    double *fdir;          /* 3 nt CF_FIBRE_MAX: group k's reference unit direction in
                           ** tetrahedron t at fdir[3 (CF_FIBRE_MAX t + k)] */
    double *fgrad;         /* 12 nt: each tetrahedron's reference shape-function gradients, its
                           ** four corners' (1/mm) */
    double *elem;          /* 36 nt, or NULL (none): per tetrahedron the element term's tensor in
                           ** Voigt form (cf_body_match_elements), MPa. Released by cf_body_free */
} cf_body;

/* The law of spring s (its group's). */
static inline const cf_law *cf_body_spring_law(const cf_body *b, size_t s)
{
    return b->group ? b->glaw[b->group[s]] : b->law;
}

/* Gives the springs of n regions (n <= CF_BODY_MAX_GROUPS) laws of their own (body_groups.c):
** group g (1..n) is every spring with both ends among the nodes sel[g - 1] selects in mesh m (the
** body's), taking the law of spring[g - 1] (with its table, of table_intervals, for the table
** method), of the body law's free length H to CF_GROUP_H_REL; the spring's calibration factor
** is kept (it does not depend on the law), so the region's material has that law's modulus.
** CF_E_DATA naming key[g - 1] for a group that holds no spring, for a spring two groups hold
** (overlapping regions), for another H; CF_E_INTERNAL when memory runs out. */
cf_status cf_body_set_groups(cf_body *b, const cf_mesh *m, size_t n, const cf_select *sel,
                             const cf_spring *spring, const char *const *key,
                             size_t table_intervals, cf_error *err);

/* Adds a fibre group to b (at most CF_FIBRE_MAX; body_fibres.c): in every tetrahedron t a
** tension-only spring along the reference unit direction dir[3 t .. 3 t + 2] (copied) with the
** law of spring (its table built for the table method), density springs per cell of the lattice
** of edge H = the body law's free length, whose energy per reference volume is that of the
** homogenised cell's fibre group (fibre.h) at the tetrahedron's deformation gradient F (constant
** in a linear tetrahedron): density E(|F a|)/H^3. Its forces and tangent enter every solve.
** CF_E_DATA naming key for a bad direction (tetrahedron t), density or law, or a fifth group;
** CF_E_INTERNAL when memory runs out. */
cf_status cf_body_add_fibres(cf_body *b, const cf_spring *spring, double density, double slack,
                             const double *dir, size_t table_intervals, const char *key,
                             cf_error *err);

/* The helix rule of a left-ventricular wall (Streeter et al. 1969, Circ Res 24:339-347): per
** tetrahedron of b, into dir (3 nt), the unit direction in the plane normal to the unit normal n
** at the angle from_deg + s (to_deg - from_deg) from reference's projection on that plane
** (turning toward n x reference), s = (n . c - lo)/(hi - lo) the tetrahedron's centroid c's
** position through the body's thickness along n (lo, hi the least and greatest n . X of its
** nodes). CF_E_DATA when n is not finite and nonzero, reference is parallel to it, or the body
** has no thickness along n. */
cf_status cf_body_helix_dirs(const cf_body *b, const double normal[3], const double reference[3],
                             double from_deg, double to_deg, double *dir, cf_error *err);

/* Every component of a node held. */
#define CF_BODY_FIX_ALL 7

/* Builds the body of mesh m (checked by cf_mesh_check) with law and the volume modulus kappa
** (MPa, >= 0). The law must outlive the body; with CF_LAW_TABLE its table must be built.
** CF_E_DATA for a bad kappa, CF_E_INTERNAL when memory runs out. */
cf_status cf_body_create(cf_body *b, const cf_mesh *m, const cf_law *law, cf_law_method method,
                         double kappa_MPa, cf_error *err);
void cf_body_free(cf_body *b);

/* Gives every tetrahedron of b the element term that makes its small-strain tensor, with its
** share of its six springs', the isotropic one of shear modulus mu and lambda = mu exactly (the
** volume term adding kappa as before): the body becomes the linear tetrahedron of the
** isotropic material, which converges to the continuum under refinement where the springs
** alone relax below their calibration (src/notes/contact-study.md, "The element term"). At
** finite strain the term is Saint Venant-Kirchhoff's in the Green-Lagrange strain. Not done by
** cf_body_create: a body without it keeps its springs' response. CF_E_DATA for a body with
** spring groups or a double-acting law (two stiffnesses at rest), CF_E_INTERNAL when memory
** runs out. */
cf_status cf_body_match_elements(cf_body *b, cf_error *err);

/* kappa of the volume term that gives the calibrated body (shear modulus mu) Poisson's ratio nu
** (0.25 <= nu < 0.5). */
double cf_body_kappa_for_nu(double mu_MPa, double nu);

/* The shear modulus mu = E0/2.5 of the law's material (E0 = k0/H), MPa. */
double cf_body_mu_of_law(const cf_law *law);

/* Per-state quantities of the body (cf_body_measure). */
typedef struct cf_body_state {
    double *strain;   /* ns engineering strains (L - L0)/L0 of the springs, tension positive */
    uint8_t *solid;   /* ns: 1 where the spring's law is at solid */
    double *J;        /* nt volume ratios */
} cf_body_state;

/* Fills st (arrays of the sizes above, caller's) at the current positions; returns the smallest
** J and sets *max_u_over_travel (if not NULL) to the largest |u| / travel over the springs. */
double cf_body_measure(const cf_body *b, cf_body_state *st, double *max_u_over_travel);

/* The stress and strain fields of a body's state (cf_body_fields_at; derivation in
** src/notes/simulate.md, "Fields"). Symmetric tensors as six numbers in VTK's order xx, yy, zz,
** xy, yz, xz; stresses Cauchy's, MPa, tension positive. */
typedef struct cf_body_fields {
    double *node_stress; /* 6 nn: the virial of each node's dual cell (a quarter of every
                         ** tetrahedron around it, current volume): half of every spring at the
                         ** node, T l n n, and a quarter of each tetrahedron's fibres and
                         ** element term, over the cell's volume, plus the volume term's
                         ** pressure kappa (J_a - 1) of the node */
    double *stress;      /* 6 nt: each tetrahedron's, the mean of its four corners' (so that the
                         ** tetrahedra's stresses times their volumes sum to the nodes') */
    double *mises;       /* nt: von Mises stress of it, MPa */
    double *strain;      /* 6 nt: Green-Lagrange strain (F^T F - I)/2 of the tetrahedron's
                         ** deformation gradient F, - */
    double *force;       /* ns: spring forces, N, tension positive */
} cf_body_fields;

/* Fills f (arrays of the sizes above, caller's) at positions x (3 nn). Over the whole body (or
** any set of nodes' dual cells) the stress times the volume is the virial sum_i x_i (x) g_i of
** the elastic nodal forces g, so its volume average is the stress the boundary's forces carry.
** Never writes a non-finite value (0 instead). CF_E_INTERNAL when memory runs out. */
cf_status cf_body_fields_at(const cf_body *b, const double *x, cf_body_fields *f,
                            cf_error *err);

/* One probe step's result. */
typedef struct cf_body_step {
    double depth_mm;
    double force_N;       /* reaction along dir, positive pushing into the body */
    int contacts;         /* nodes in contact */
    int newton_iters;
    double min_J;
    double max_u_over_travel;
    long neg_pivots;      /* negative eigenvalues of the last tangent the static solve factored
                             (0: a stable equilibrium), -1 when none was factored or the count is
                             unknown */
} cf_body_step;

/* Solves the static equilibrium of b with the probe at depth (probe->dir times depth from its
** start), starting from the current positions (the previous step's), with the held components kept
** where they are (at their reference positions unless the caller moved them). A probe with
** radius 0 touches nothing. Contact is frictionless, by a penalty on each node inside the probe
** (stiffness penalty_N_per_mm; 0 = automatic, 1e4 E times the mean edge). CF_E_NOCONV when Newton
** does not converge or every step back would still invert a tetrahedron or take a spring to
** solid (message: the depth). */
cf_status cf_body_solve(cf_body *b, const cf_probe *probe, double depth_mm,
                        double penalty_N_per_mm, cf_body_step *out, cf_error *err);

/* The depth at which the probe's reaction is force_N (> 0) and the equilibrium there: the depth
** found by bracketing from the current one (or, without contact yet, from where the probe first
** touches a node) and regula falsi (Illinois), each trial a cf_body_solve started from the nearer
** end of the bracket, until the force is within 1e-6 of force_N (or the bracket narrower than
** 1e-12 of the mean edge). *depth_mm holds the current depth on entry (0 at rest) and the depth
** found on return. CF_E_NOCONV when a trial solve fails before the force is reached (the body
** cannot carry it: the message names the force and the depth), else as cf_body_solve. */
cf_status cf_body_solve_force(cf_body *b, const cf_probe *probe, double force_N, double *depth_mm,
                              double penalty_N_per_mm, cf_body_step *out, cf_error *err);

/* One update of the probe loop at haptic rate: the probe moved to depth, then at most max_iters
** chord iterations from the current positions, each with the exact residual (springs, volume
** term, penalty contact) and a step with the tangent of the body without contact, assembled and
** factored at the first call and kept, corrected for the nodes in contact by Woodbury's identity
** (a rank-one term per node, its three columns of the inverse computed once at its first contact),
** so that contact changes need no new factorisation. Stops early when the residual is below
** 1e-8 E h^2 (h the mean edge). The force is that of the positions returned: the last
** assembly's when the residual stopped the update, else the body's internal forces at the nodes
** in contact along the probe's direction where the last step left the body (an estimate of the
** equilibrium force whose error scales with the body's stiffness, not the penalty's; those
** forces are kept for the next update's residual); repeated at one depth the updates converge to
** cf_body_solve's equilibrium. The kept
** columns grow by 9 nn numbers per node that has ever touched the probe (cf_body_free releases
** them). Same errors as cf_body_solve. */
cf_status cf_body_haptic_step(cf_body *b, const cf_probe *probe, double depth_mm,
                              double penalty_N_per_mm, int max_iters, cf_body_step *out,
                              cf_error *err);

/* The motion of a body in a dynamic run (cf_body_dynamic_step): lumped masses, mass-proportional
** damping, and the state of Newmark's average-acceleration scheme. */
typedef struct cf_body_motion {
    double *mass;          /* nn lumped masses (t): density times a quarter of the volume of
                           ** every tetrahedron around the node */
    double damping_per_s;  /* c of the damping force c m v on each node (s^-1), >= 0 */
    double *v, *a;         /* 3 nn velocities (mm/s) and accelerations (mm/s^2) */
    double *xprev;         /* 3 nn positions at the end of the last step */
    double t_s;            /* time of the last step (0 at the start) */
    double gamma;          /* Newmark's gamma, 1/2 (0 is read as 1/2: average acceleration, no
                           ** numerical damping) to 1; above 1/2, with beta = (gamma + 1/2)^2/4,
                           ** the step damps the highest frequencies (a penalty contact's
                           ** node-on-probe vibration) and is first-order accurate */
} cf_body_motion;

/* Starts b's motion at rest at its current positions, which must be an equilibrium with the
** loads at time 0 (so the accelerations are 0): masses from the density rho (t/mm^3, > 0).
** CF_E_DATA for a bad rho or damping, CF_E_INTERNAL when memory runs out. */
cf_status cf_body_motion_init(const cf_body *b, double rho_t_per_mm3, double damping_per_s,
                              cf_body_motion *m, cf_error *err);
void cf_body_motion_free(cf_body_motion *m);

/* One implicit step of dt_s (> 0) of the body's motion m, by Newmark's scheme (m->gamma; at the
** default, gamma 1/2 and beta 1/4, the average acceleration: unconditionally stable, no numerical
** damping; the formulas below are that case's): with the held
** components and f_ext already set to their values at the step's end, the positions x solve
** M a + c M v + g(x) = f_ext + contact, a = 4 (x - x_n - dt v_n)/dt^2 - a_n,
** v = v_n + dt (a_n + a)/2, by cf_body_solve's Newton iteration and active set with the inertia's
** (4/dt^2 + 2c/dt) M on the tangent's diagonal: the volume term's stiffness, which limits an
** explicit step, does not limit this one. out as for cf_body_solve (the force is the probe's
** contact force). Same errors as cf_body_solve. */
cf_status cf_body_dynamic_step(cf_body *b, cf_body_motion *m, const cf_probe *probe,
                               double depth_mm, double dt_s, double penalty_N_per_mm,
                               cf_body_step *out, cf_error *err);

/* The body's elastic forces on its nodes at the current positions (the gradient of its energy,
** N; g has 3 nn entries; the external forces f_ext are not in it). CF_E_INTERNAL when
** memory runs out. */
cf_status cf_body_internal_force(const cf_body *b, double *g, cf_error *err);

/* Spreads the total force F (N) over the marked nodes of b into f (3 nn, added to): a traction
** on the part of the body's boundary whose triangles have all three corners marked, each node
** taking a third of the area of its triangles there; where the marked nodes hold no boundary
** triangle, in proportion to their nodal volumes (a quarter of each tetrahedron around them).
** Returns the number of nodes that received a share (0 also when memory runs out). */
size_t cf_body_spread_force(const cf_body *b, const uint8_t *mark, const double F[3], double *f);

/* Index of a node inside the probe at depth 0 (the probe starts inside the body), or -1. */
long cf_body_probe_inside(const cf_body *b, const cf_probe *probe);

/* The contact set of the last static solve (cf_body_solve, cf_body_solve_force): mark[i] = 1 for
** every node the probe pushed at the equilibrium (its penalty in the force), 0 for the others
** (mark has nn entries). Returns how many are marked (0 before the first solve). */
size_t cf_body_contact_set(const cf_body *b, uint8_t *mark);

/* The penalty stiffness of a contact node that the solves take when given 0: 1e4 E times the mean
** edge (N/mm). */
double cf_body_penalty(const cf_body *b);

/* The body's spring network (net_mesh.c, body.c). */

/* The net of the tetrahedral mesh m (checked by cf_mesh_check): its nodes, none held; its edges
** as springs in the order of their end nodes, rest length the edge's, weight the calibration of
** body.h for law (per tetrahedron the edge stiffnesses that best match an isotropic tensor, the
** whole network scaled to the shear modulus cf_body_mu_of_law); its tetrahedra. CF_E_DATA when
** the calibration finds no stiffness, CF_E_INTERNAL when memory runs out. */
cf_status cf_net_mesh(cf_net *n, const cf_mesh *m, const cf_law *law, cf_error *err);

/* A net that views b's arrays (nodes, fixity, springs, tetrahedra; nothing owned: not for
** cf_net_free), for the exports. */
cf_net cf_net_of_body(const cf_body *b);

#endif
