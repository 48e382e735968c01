/*
** ParaView output of a body (body.h): per saved state a VTK XML unstructured grid of its
** tetrahedra (point data "displacement" in mm, cell data "J") and one of its springs as lines
** (cell data "strain", engineering, tension positive, and "solid", 1 where the law is at solid),
** and a PVD collection naming them by probe depth. ASCII, readable by ParaView and VTK's
** vtkXMLUnstructuredGridReader.
*/
#ifndef CF_REPORT_VTU_H
#define CF_REPORT_VTU_H

#include <stdio.h>

#include "model/body.h"
#include "conifit/error.h"

/* The tetrahedra with positions x (3 nn) and volume ratios J (nt) to f. */
void cf_vtu_body(FILE *f, const cf_body *b, const double *x, const double *J);

/* The springs with positions x, strains and solid flags (ns each) to f. */
void cf_vtu_springs(FILE *f, const cf_body *b, const double *x, const double *strain,
                    const unsigned char *solid);

/* The collection of count states at probe depths depth[k] (used as their times): files
** body_NNNN.vtu (part 0) and springs_NNNN.vtu (part 1), NNNN = k. */
void cf_vtu_pvd(FILE *f, size_t count, const double *depth);

#endif
