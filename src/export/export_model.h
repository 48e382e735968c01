/*
** A model to export (private to the export module): nodes with their fixed directions, springs in
** groups that share one table, the top nodes that a prescribed displacement along z drives, the
** load steps, and conifit's own reaction at each step. Built from one spring (the --example of
** every format) or from the validation lattice, and written by one writer per target.
*/
#ifndef CF_OUT_EXPORT_MODEL_H
#define CF_OUT_EXPORT_MODEL_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "export/export_table.h"
#include "export/export_types.h"
#include "model/law_internal.h"
#include "model/net.h"

/* Springs of one rest length and one weight: their table in their own elongation and tension. */
typedef struct cf_xgroup {
    double L0_mm;       /* rest length, mm */
    double weight;      /* force factor on the law, - */
    double slack_mm;    /* a fibre group's: elongation taken slack before the law (its
                        ** recruitment strain times L0), mm; 0 otherwise */
    size_t count;       /* springs in the group */
    size_t rows;        /* rows of the table */
    double *e_mm;       /* elongation L - L0 = -u L0/H, mm, ascending */
    double *T_N;        /* tension = -weight F(u), N */
    const cf_law *law;  /* its spring group's law, NULL: the model's law */
    const cf_export_table *table; /* that law's table, NULL: the model's base table */
} cf_xgroup;

typedef struct cf_xmodel {
    const char *title;      /* one line: what the model is */
    const char *source;     /* fit file name, for provenance */
    const char *output;     /* the file written (NULL: standard output), names the model's own
                            ** output files */
    const cf_law *law;
    const cf_export_table *base; /* the law's table (weight 1, rest length H) */
    size_t nn;              /* nodes */
    double *X, *Y, *Z;      /* reference positions, mm */
    uint8_t *fix;           /* CF_FIX_X | CF_FIX_Y | CF_FIX_Z: held at zero displacement */
    size_t ns;              /* springs */
    uint32_t *si, *sj;      /* end nodes (0-based) */
    uint32_t *grp;          /* group of each spring */
    size_t ng;              /* groups */
    cf_xgroup *g;
    size_t ntop;            /* driven nodes: z displacement prescribed, x and y free unless fixed */
    uint32_t *top;
    /* A body's probe replayed (NULL: the top nodes move together by dz_mm): at step k, the nodes
    ** of conifit's contact set pn[pp[k] .. pp[k + 1]) with their z displacements pdz_mm[..]
    ** (nsteps + 1 offsets); and every node of top (all nodes ever in contact) with its z
    ** displacement udz_mm[k ntop + t] at step k, contact or not */
    size_t *pp;
    uint32_t *pn;
    double *pdz_mm, *udz_mm;
    /* and conifit's penalty contact for CalculiX: each node of top tied along z by a linear
    ** spring of stiffness kp_N_per_mm to a node of the punch's face (numbered after the body's
    ** and the volume term's), whose z displacement at step k is fdz_mm[k ntop + t]: the face at
    ** that depth for a node in contact, where the spring is slack (the node's solved position)
    ** otherwise */
    double kp_N_per_mm;
    double *fdz_mm;
    const double *xk_mm;    /* nsteps x 3 nn: the positions conifit solved at each step (not
                            ** owned; NULL: none), about which CalculiX's volume term is taken */
    size_t nsteps;          /* load steps */
    double *dz_mm;          /* z displacement of the driven nodes at the end of each step, mm */
    double *ref_N;          /* conifit's compressive top reaction at each step, N */
    double *strain;         /* compressive nominal strain at each step, - */
    double reaction_tol_N;  /* what the tables allow in the top reaction: tol F_C times the
                            ** weights of the springs a horizontal plane cuts, projected on z;
                            ** a lattice with cells (volume term, hourglass control): the
                            ** tables' error propagated through its equilibrium (at least that) */
    double area_mm2;        /* loaded area (lattice: nx ny H^2), mm^2 */
    double height_mm;       /* height along z, mm */
    /* a body's volume term: nt tetrahedra (4 node indices each, not owned); each node a stores
    ** V0_a (kappa/2)(J_a - 1)^2 with V0_a, V_a a quarter of the rest and current volumes of the
    ** tetrahedra around it (conifit's nodal volume term); 0 = none */
    size_t nt;
    const uint32_t *tet;
    /* The lattice's volume term (cell.h): every cell stores (kappa/2)(J - 1)^2 of its rest volume;
    ** written as an eight-node hexahedron per cell with a purely volumetric material by the
    ** formats that can (CalculiX, Abaqus; cf_xmodel_volume_refusal). */
    /* a body's element term (cf_body_match_elements): nt tensors of 36 (Voigt, MPa; not owned),
    ** written by CalculiX only; NULL: none */
    const double *elem;
    const char *note;       /* NULL or "": else a header line on what the loading leaves out */
    double kappa_MPa;       /* 0: no volume term (a body's or a lattice's) */
    size_t ncells;
    uint32_t *cell;         /* 8 nodes (0-based) per cell, corner di + 2 dj + 4 dk */
    /* The lattice's hourglass control (lattice_hourglass.h): every cell stores (k_h/2) sum_i
    ** |q_i|^2; written by CalculiX and Abaqus as an extra node per mode and cell whose
    ** displacement *EQUATION makes q_i (exact: q_i is linear in the displacements) on three
    ** grounded SPRING1 of stiffness k_h. 0: none (the other formats' lattices are built
    ** without it, cf_xmodel_carries_hourglass). */
    double hg_k_N_per_mm;
    /* Fibres (CalculiX, Abaqus; export_fibres.c): nfib embedded springs, fibre q between two
    ** auxiliary nodes at fx_mm[6 q .. 6 q + 3) and [6 q + 3 .. 6 q + 6) (its element's centre
    ** -+ (Hf/2) a), each end's displacement tied by *EQUATION to the element's fnc corners
    ** fcorner[fnc q .. fnc (q + 1)) (4: a body's tetrahedron, 8: a lattice cell) with the
    ** shape-function weights fwt[2 fnc q + fnc end + m] there; its tension-only table
    ** fg[fgrp[q]] (elongation Hf (lambda - 1), tension). 0: none. */
    size_t nfib, nfg, fnc;
    double fib_tol_N;       /* the fibre tables' share of reaction_tol_N, N */
    uint32_t *fcorner, *fgrp;
    double *fx_mm, *fwt;
    cf_xgroup *fg;
} cf_xmodel;
/* 1 when format f writes a lattice's hourglass control (CalculiX, Abaqus), else 0. */
int cf_xmodel_carries_hourglass(cf_export_format f);
/* NULL when format f can carry m's volume term (none, or CalculiX/Abaqus), else why it cannot. */
const char *cf_xmodel_volume_refusal(const cf_xmodel *m, cf_export_format f);

/* Groups of springs: one per spring (a body's every edge its own weight), or one per rest length
** and weight (a lattice's few, equal to 1e-12 relative). */
typedef enum cf_xgrouping { CF_XGROUP_EACH = 0, CF_XGROUP_SHARED = 1 } cf_xgrouping;

/* The nodes of net n (positions, held directions) and its springs (end nodes, groups with their
** rest lengths and weights) into m's arrays, allocated here; m's other fields are left as they
** are. 0, or -1 when memory runs out (what was allocated is left for cf_xmodel_free). */
int cf_xmodel_of_net(cf_xmodel *m, const cf_net *n, cf_xgrouping grouping);

/* Releases what the model owns (its arrays and group tables). Safe on a zeroed model. */
void cf_xmodel_free(cf_xmodel *m);

/* Fills the group tables from m->base (each group's L0 and weight set). 0, or -1 out of memory. */
int cf_xmodel_tables(cf_xmodel *m);

/* The writers of runnable models, one per target: 0, or -1 when memory runs out. */
int cf_xmodel_write_calculix(FILE *out, const cf_xmodel *m);
int cf_xmodel_write_abaqus(FILE *out, const cf_xmodel *m);
int cf_xmodel_write_febio(FILE *out, const cf_xmodel *m);
int cf_xmodel_write_lsdyna(FILE *out, const cf_xmodel *m);
int cf_xmodel_write_sofa(FILE *out, const cf_xmodel *m);

/* Writes one (force, elongation) pair of a *SPRING table, each number with a decimal point: ccx
** decides from the first line under *SPRING whether it holds degrees of freedom (integers) or
** spring data (reals), after deleting blank lines (ccx manual, *SPRING); each number fits the 20
** characters ccx reads. */
void cf_export_inp_pair(FILE *out, double force_N, double elongation_mm);

/* The name of the file FEBio writes the top nodes' reactions to, for a model written to `output`
** (NULL or "" for standard output): the output's base name without its extension, then
** "_top_Rz.txt" ("conifit_top_Rz.txt" for standard output), so that two models in one folder do
** not share it.
** The output's name is text from outside: folders are dropped, and the rest is written for an XML
** attribute: printable ASCII and whole printable UTF-8 characters kept, the five XML markup
** characters as entities (FEBio's reader decodes them), path separators ('/', '\', ':') and
** every other byte (controls, DEL, C1 controls, bytes that are not UTF-8) as '_'; a base name
** longer than CF_EXPORT_LOG_STEM_MAX bytes is cut at a character boundary. Returns buf. */
#define CF_EXPORT_LOG_STEM_MAX 200
char *cf_export_febio_log_name(char *buf, size_t cap, const char *output);

/* Writes a comment line with the spring's parameters, and the table's accuracy, each line
** starting with lead and ending with tail. */
/* Longest source name written, in bytes (a longer one is cut, ending in "..."). */
#define CF_EXPORT_SOURCE_MAX 256

/* The comment line "source: NAME" between lead and tail. NAME (a file name: text from outside) is
** written so that it cannot end the comment or the line: control characters (newlines included)
** and bytes that are not UTF-8 as \xNN (base/safetext.h); in an XML comment (tail "-->") a '-'
** after a '-' or at the end as \x2D, so "--" and "-->" cannot occur. NULL or "" is "(none)". */
void cf_export_comment_source(FILE *out, const char *lead, const char *tail, const char *source);

void cf_export_comment_spring(FILE *out, const char *lead, const char *tail, const cf_law *law);
void cf_export_comment_table(FILE *out, const char *lead, const char *tail,
                             const cf_export_table *t, const cf_law *law);

/* For an evenly spaced table (t->even; nothing otherwise): comment lines with its spacing and
** LCINT, the range it was shortened to and from, the law's force at its ends and what LS-DYNA
** does past them. */
void cf_export_comment_even(FILE *out, const char *lead, const char *tail,
                            const cf_export_table *t, const cf_law *law);

/* The SOFA form of one group's table: a linear part A + B e written as two compressible linear
** springs, plus one one-sided spring per interior node (see export_model.c). */
typedef struct cf_sofa_terms {
    double a_rest_N;     /* coefficient of the compressible spring of rest length L0, N */
    double a_half_N;     /* coefficient of the compressible spring of rest length L0/2, N */
    size_t nknots;
    double *knot_mm;     /* rest length of each one-sided spring, mm */
    double *a_N;         /* its coefficient (force = a (l - knot)/knot while l >= knot), N */
} cf_sofa_terms;
int cf_sofa_terms_of(const cf_xgroup *g, cf_sofa_terms *s);
void cf_sofa_terms_free(cf_sofa_terms *s);

/* Shared by the writers (export_model.c): the comment header every model starts with (lead and
** tail open and close a comment line of the target), and the set names of the fixed-direction
** masks (bit 0 x, 1 y, 2 z). */
void cf_xmodel_header(FILE *out, const char *lead, const char *tail, const cf_xmodel *m,
                      const char *target, const char *how);
extern const char *const cf_xmodel_mask_name[8];

/* A body's nodal volume term for CalculiX and Abaqus (export_inp_volume.c): how many auxiliary
** nodes (and SPRING1 elements) it adds after the body's nodes (and the springs' elements); its
** nodes, elements and equations (0, -1 out of memory); the lines of its held directions (inside
** a *BOUNDARY); and what step k (0-based) changes (*MODEL CHANGE: only step k's springs act). */
size_t cf_xmodel_inp_volume_nodes(const cf_xmodel *m);
int cf_xmodel_inp_nodal_volume(FILE *out, const cf_xmodel *m);
void cf_xmodel_inp_volume_held(FILE *out, const cf_xmodel *m);
void cf_xmodel_inp_volume_step(FILE *out, const cf_xmodel *m, size_t k);

/* The fibres of m for CalculiX and Abaqus (export_fibres.c): the auxiliary nodes (numbers from
** node0 + 1), their equations and the SPRINGA elements with their tables (numbers from
** elem0 + 1). */
void cf_xmodel_inp_fibres(FILE *out, const cf_xmodel *m, size_t node0, size_t elem0);
/* A body's element term (m->elem) for CalculiX (export_inp_elem.c): each tetrahedron a C3D4 of
** element number e0 + t + 1 with its own anisotropic material. */
void cf_xmodel_inp_elem(FILE *out, const cf_xmodel *m, size_t e0);

/* A real for CalculiX/Abaqus input: at most 20 characters, always with a decimal point
** (export_inp.c). */
void cf_export_inp_real(char buf[32], double x);

#endif
