/*
** ParaView output of a body (body.h): per saved state a VTK XML unstructured grid of its
** tetrahedra and one of its springs as lines, and a PVD collection naming them by time. ASCII,
** readable by ParaView and VTK's vtkXMLUnstructuredGridReader. Units are in the arrays' names
** (mm, N, kPa; "-" for none); the symmetric tensors have six components in VTK's order XX, YY,
** ZZ, XY, YZ, XZ, named in the files. The fields and their derivation: src/notes/simulate.md,
** "Fields of the ParaView files".
**
** body_NNNN.vtu: point data "displacement" (mm, 3), "stress_kPa" (6, the node's dual cell),
** "contact_force_N" (3, the probe's force on the node), "reaction_N" (3, the supports' force at
** the held components); cell data "stress_kPa" (6), "von_mises_kPa", "strain_green_lagrange"
** (6), "J", and with fibres "fibre_direction" (3, each tetrahedron's reference fibre direction;
** "fibre_direction_K" for group K > 0). springs_NNNN.vtu: cell data "force_N" (tension positive), "strain" (engineering,
** tension positive), "solid" (1 where the law is at solid). Both carry field data "TimeValue"
** (the PVD's time), "step", and with a probe "probe_depth_mm" and "probe_force_N".
*/
#ifndef CF_REPORT_VTU_H
#define CF_REPORT_VTU_H

#include <stdio.h>

#include "model/body.h"
#include "conifit/error.h"

/* One saved state of a body. */
typedef struct cf_vtu_state {
    const double *x;              /* 3 nn positions, mm */
    const double *J;              /* nt volume ratios */
    const cf_body_fields *fields; /* stresses (MPa, written in kPa), strains, spring forces */
    const double *contact;        /* 3 nn probe forces on the nodes, N (NULL: none) */
    const double *reaction;       /* 3 nn support forces, N (NULL: none) */
    const double *strain;         /* ns engineering strains */
    const unsigned char *solid;   /* ns */
    double time;                  /* the PVD's time of the state */
    size_t step;
    int has_probe;
    double depth_mm, force_N;     /* the probe's, when has_probe */
} cf_vtu_state;

/* The tetrahedra of b in state s to f. */
void cf_vtu_body(FILE *f, const cf_body *b, const cf_vtu_state *s);

/* The springs of b in state s to f. */
void cf_vtu_springs(FILE *f, const cf_body *b, const cf_vtu_state *s);

/* The collection of count states at times time[k]: files body_NNNN.vtu (part 0) and
** springs_NNNN.vtu (part 1), NNNN = k; `what` says in a comment what the time is. */
void cf_vtu_pvd(FILE *f, size_t count, const double *time, const char *what);

#endif
