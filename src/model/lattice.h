/*
** The mass-spring lattice: a regular block of nx x ny x nz cubic cells of edge H (the spring's free
** length), point masses at the nodes, conical springs on the cell edges and optionally on the face
** and body diagonals. It sees the spring law only through law.h (cf_law_force_many), and it is the
** force kernel the solvers of msm.h call on every step.
**
** Units: mm, N, s and the mass unit that makes them consistent, the tonne (1 t = 1000 kg, so
** 1 N = 1 t mm/s^2); a density of 1000 kg/m^3 is 1e-9 t/mm^3. Stresses are MPa (N/mm^2).
** Axes: z is the loading axis; the bottom face is z = 0, the top face z = nz H.
**
** Spring weights. Each cell owns a quarter of each of its 12 edges (an edge is shared by up to four
** cells), half of each of its 12 face diagonals (a face by up to two cells) and all of its 4 body
** diagonals; a spring's weight w is the sum of the shares of the cells that contain it, and its
** force is w times the law. So every layer of axial springs carries nx ny springs' worth of force
** and a lattice of axial springs alone reproduces sigma = F/H^2 of one spring exactly.
**
** Spring families. The springs of each family (edges, face diagonals, body diagonals) carry the
** law times the family's weight (calibration.h): the default calibration makes the lattice
** isotropic at small strain (nu = 1/4) with the law's modulus k0/H. A family of weight 0 has no
** springs at all. Dashpots and Maxwell branches (msm.h) are scaled by the same weights, so the
** viscous response is calibrated with the elastic one.
**
** Diagonal springs use the same law in strain form: a diagonal of rest length L0 (sqrt 2 H or
** sqrt 3 H) is evaluated at the compression u = (L0 - L) H/L0 and carries its cell shares times
** its family weight times that force. It is therefore the fitted material, stretched to the
** diagonal's length: it reaches solid at the same strain as the edges (L_min = L0 L_min(H)/H,
** L_max = L0 L_max(H)/H, paper eqs. 18-21 scaled), and one law object (one table) serves every
** spring.
*/
#ifndef CF_LATTICE_H
#define CF_LATTICE_H

#include <stddef.h>
#include <stdint.h>

#include "model/calibration.h"
#include "conifit/error.h"
#include "model/law_internal.h"
#include "model/fibre.h"
#include "model/lattice_hourglass.h"
#include "model/net.h"

typedef enum cf_bottom_bc {
    CF_BOTTOM_AXIAL = 0,  /* bottom nodes held in z, free to slide laterally (lubricated platen) */
    CF_BOTTOM_CLAMPED = 1 /* bottom nodes held in x, y and z */
} cf_bottom_bc;

typedef struct cf_lattice_config {
    int nx, ny, nz;           /* cells along x, y and z (z = loading axis), each >= 1 */
    double weight[CF_FAMILY_COUNT]; /* force factor of each family (CF_FAMILY_EDGE, _FACE,
                              ** _BODY), dimensionless, >= 0; 0 = the family is absent */
    cf_calibration calibration; /* where the weights came from (reported with them) */
    double density_t_per_mm3; /* mass density, tonne/mm^3 (1e-9 = 1000 kg/m^3), > 0 */
    cf_bottom_bc bottom;      /* bottom-face boundary condition */
    double volume_modulus_MPa; /* kappa of the volume term (cell.h): every cell stores
                              ** (kappa/2)(J - 1)^2 H^3, J its volume (the trilinear hexahedron of
                              ** its eight nodes, 2 x 2 x 2 Gauss points: exact) over H^3; >= 0,
                              ** 0 (the default) for none */
    double hourglass;         /* hourglass control (lattice_hourglass.h): every cell stores
                              ** (k_h/2) sum_i |q_i|^2 over its four hourglass modes, zero for every
                              ** affine motion of the cell; k_h is this fraction of the cell's
                              ** small-strain shear stiffness (as the energy of a simple shear of
                              ** the same node motion); 0 for none, at most 1000;
                              ** CF_HOURGLASS_AUTO (the default): CF_HOURGLASS_DEFAULT with a
                              ** volume term, 0 without */
    const cf_law *group_law[CF_FAMILY_COUNT]; /* a law per spring group (a group is a family:
                              ** CF_FAMILY_EDGE, _FACE, _BODY), not owned; NULL (the default):
                              ** the lattice's law. A group's law has the lattice law's free
                              ** length H, and with CF_LAW_TABLE its table built */
    const cf_fibre_group *fibre; /* fibre groups (fibre.h), not owned, NULL (the default) for
                              ** none: each cell carries one spring of each group, its stretch
                              ** |F a| with F the cell's mean deformation gradient (that of its
                              ** trilinear hexahedron averaged over the cell, exact for a
                              ** homogeneous deformation), its nodal forces -H^3 P dF/dx; in the
                              ** forces and in the static solvers' tangent (msm_tangent.c);
                              ** explicit dynamics (inertia) refuses fibres: its stable step
                              ** does not count them yet */
    int nfibre;               /* their count, 0 .. CF_FIBRE_MAX */
} cf_lattice_config;

/* The hourglass fraction that means "the default with a volume term, none without"; that default
** is CF_HOURGLASS_DEFAULT (lattice_hourglass.h). */
#define CF_HOURGLASS_AUTO (-1.0)

/* 3 x 3 x 3 cells, the isotropic calibration, density 1e-9 t/mm^3, bottom axial, no volume term,
** hourglass control automatic, every group with the lattice's law. */
cf_lattice_config cf_lattice_default(void);

/* DOF fixity bits per node. */
enum { CF_FIX_X = 1, CF_FIX_Y = 2, CF_FIX_Z = 4 };

/* The lattice: nodes and springs as structures of arrays. Springs are ordered by their first
** node, whose index runs x fastest, so a pass over the springs walks memory nearly in order. */
typedef struct cf_lattice {
    cf_lattice_config cfg;
    const cf_law *law;      /* not owned */
    cf_law_method method;   /* evaluator used by the kernel */
    double H_mm;            /* cell edge = free length of the axial springs, mm */
    double travel_mm;       /* law travel s (axial compression at solid), mm */
    size_t nn;              /* number of nodes */
    size_t ns;              /* number of springs */
    /* nodes */
    double *x, *y, *z;      /* positions, mm */
    double *X, *Y, *Z;      /* reference positions, mm */
    double *mass_t;         /* node masses, t */
    double *fx, *fy, *fz;   /* forces on the nodes from the springs (output of the kernel), N */
    uint8_t *fix;           /* CF_FIX_* bits (bottom face and rigid-body pins) */
    /* springs */
    uint32_t *si, *sj;      /* end nodes, si < sj */
    double *L0_mm;          /* rest length, mm */
    double *a;              /* H / L0: converts length change to the law's compression, - */
    double *w;              /* force weight (cell shares x family weight), - */
    uint8_t *family;        /* CF_FAMILY_* of each spring */
    double *L_mm;           /* current length (kernel output), mm */
    double *u_mm;           /* law compression (L0 - L) a (kernel output), mm */
    double *F_N;            /* law force at u (kernel output), N, compression positive */
    double *k_N_per_mm;     /* law stiffness at u (kernel output when with_stiffness), N/mm */
    int with_stiffness;     /* 1 (default): the kernel also evaluates k_N_per_mm (statics, stable
                            ** step); 0: forces only, as an explicit step needs (cheaper) */
    double *T_N;            /* spring tension w (-F) + effects (kernel output), N */
    /* faces */
    size_t ntop;            /* nodes on the top face */
    uint32_t *top;          /* their indices */
    double *top_share;      /* tributary share of the top area, in units of H^2 (sum nx ny) */
    double area_mm2;        /* nx ny H^2, mm^2 */
    double height_mm;       /* nz H, mm */
    double m_min_t;         /* lightest node mass, t */
    int max_degree;         /* most springs meeting at one node */
    double hg_k_N_per_mm;   /* the hourglass stiffness k_h of every cell (cfg.hourglass resolved
                            ** for this law), N/mm; 0: no hourglass control */
    /* spring groups (cfg.group_law): */
    const cf_law *glaw[CF_FAMILY_COUNT]; /* each group's law (the lattice's where cfg gives NULL) */
    int grouped;            /* 1 when some group's law is not the lattice's: the kernel then
                            ** evaluates each group's law over its springs (gathered by gidx) */
    uint32_t *gidx;         /* grouped: the springs ordered by group, each in spring order */
    size_t gstart[CF_FAMILY_COUNT + 1]; /* grouped: group g is gidx[gstart[g] .. gstart[g+1]) */
    double *gu, *gF, *gk;   /* grouped: the gathered compressions, forces and stiffnesses */
} cf_lattice;

/* The law of spring s (its group's). */
static inline const cf_law *cf_lattice_spring_law(const cf_lattice *lat, size_t s)
{
    return lat->glaw[lat->family[s]];
}

/* The travel to solid on the side of compression u (u < 0: extension) of the group that reaches
** solid first on that side, mm: the lattice law's own with one group law. */
double cf_lattice_travel_at(const cf_lattice *lat, double u);


/* Builds the lattice at its reference (undeformed) state. CF_E_DATA with a message naming the
** field for a bad configuration (a group law of another free length among them), CF_E_INTERNAL
** when memory runs out. The law must outlive the
** lattice; with CF_LAW_TABLE the caller builds the law's table first. */
cf_status cf_lattice_create(cf_lattice *lat, const cf_law *law, cf_law_method method,
                            const cf_lattice_config *cfg, cf_error *err);

/* Releases the arrays. Safe on a zeroed lattice. */
void cf_lattice_free(cf_lattice *lat);

/* Puts every node back at its reference position. */
void cf_lattice_reset(cf_lattice *lat);

/* The share, along one axis of n cells, of the cells holding a segment from node index p with
** offset o (-1, 0 or 1): across the axis (o != 0) 1, or 0 when the far end is outside; along it
** (o == 0) 1/2 on the boundary and 1 inside, since there two cells hold it. A spring's weight is
** its family's times the product over the three axes, a node's mass the cell mass times the
** product with o = 0 (the explicit step's stencil forms its weights from it too). */
double cf_lattice_axis_share(int p, int o, int n);

/* The force kernel: from the current positions computes every spring's length, compression, law
** force and (when lat->with_stiffness) stiffness and elastic tension (L_mm, u_mm, F_N, k_N_per_mm,
** T_N) and the node forces
** fx, fy, fz (every spring adds equal and opposite forces along its axis to its two nodes).
** Returns the largest |u| / travel over all springs (>= 1 means some spring is at solid). */
double cf_lattice_forces(cf_lattice *lat);

/* Adds to fx, fy, fz the forces of extra tensions Textra[s] (N, tension positive) along each
** spring's current axis (uses L_mm from the last cf_lattice_forces) and adds them to T_N. */
void cf_lattice_add_tensions(cf_lattice *lat, const double *Textra_N);

/* The volume term of cell c (0 <= c < nx ny nz, x fastest): its eight nodes (the corner
** (di, dj, dk) at index di + 2 dj + 4 dk), J = V/H^3, dV/dx of each node (g, mm^2) and, when hess
** is not NULL, d2V/(dx_a dx_b) (hess[a][b][i][k], mm). */
double cf_lattice_cell_volume(const cf_lattice *lat, size_t c, uint32_t node[8], double g[8][3],
                              double (*hess)[8][3][3]);

/* The cells' node forces, the volume term's -kappa (J - 1) dV/dx and the hourglass control's
** (lattice_hourglass.h), of every cell, added to lat->fx, fy, fz (nothing when the lattice has
** neither): the fused step's springs (lattice_step.h) do not include them. */
void cf_lattice_add_volume_forces(cf_lattice *lat);

/* A bound on the largest row sum of |d2W/dx2| of the cells' energies at the current positions,
** over every node's three rows (N/mm): per cell kappa/H^3 g g^T + kappa (J - 1) d2V/dx2, summed
** over the cells of each node, plus the hourglass control's 8 (3 k_h / 16) (Gershgorin, for the
** explicit step's stability; 0 without either). */
double cf_lattice_volume_row_bound(const cf_lattice *lat);

/* Elastic energy stored in the springs and the cells at the current state, mJ = N mm (Gauss-
** Legendre quadrature of the law over each spring's compression, accurate to about 1e-10 relative
** away from solid; the volume term and the hourglass control exactly). */
double cf_lattice_elastic_energy(const cf_lattice *lat);

/* The hourglass control's part of it (lattice_hourglass.h), mJ; 0 without. */
double cf_lattice_hourglass_energy(const cf_lattice *lat);

/* The lattice's width along x over its rest width nx H: the mean x of the nodes of the +x face
** less that of the -x face, over nx H (1 at rest). */
double cf_lattice_lateral_stretch(const cf_lattice *lat);

/* Mean z displacement of the top face (mm, compression positive) and nominal compressive strain. */
double cf_lattice_top_strain(const cf_lattice *lat);

/* The lattice's spring network (lattice_net.c). */

/* The cubic lattice of cfg with cell edge H_mm (> 0): nodes at (i, j, k) H with index i + (nx + 1)
** (j + (ny + 1) k); the springs of the families of non-zero weight from each node in that order
** (the cell directions of cell.h), rest length H sqrt(1, 2 or 3) and weight the family's times the
** share of the cells that hold the spring (cf_lattice_axis_share); the bottom face's fixity of
** cfg->bottom (a sliding bottom also pins node (0,0,0) in x and y, node (nx,0,0) in y); every
** cell as a hexahedron, x fastest. CF_E_DATA for cells out of range, CF_E_INTERNAL when memory
** runs out (n is then empty). */
cf_status cf_net_lattice(cf_net *n, const cf_lattice_config *cfg, double H_mm, cf_error *err);

/* The cell counts of cfg: each between 1 and 10000, else CF_E_DATA naming the key
** (lattice.nx ...). cf_net_lattice and the lattice's own check use it. */
cf_status cf_net_lattice_check_cells(const cf_lattice_config *cfg, cf_error *err);

/* The nodes and springs cf_net_lattice makes of cfg (cells >= 1 along each axis), counted without
** making them (exact integers below 2^53), for the budgets of scenes. */
void cf_net_lattice_size(const cf_lattice_config *cfg, double *nodes, double *springs);

#endif
