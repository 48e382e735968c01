/*
** Softening in a table: where its curve is concave on the loading side, which the conical law
** (whose stiffness only grows with strain) cannot follow.
**
** The test is local and tolerant of noise: over windows a quarter of the strain range wide (at
** least six points), sliding along the loading side (the side of the table's largest |strain|,
** tension and compression alike, read as magnitudes), a quadratic is fitted by least squares. A
** window is concave when its curvature is negative by more than four standard errors AND bends
** the curve away from its chord by more than CF_SOFTENING_BEND of the table's largest |stress|:
** noise alone passes neither, a straight or stiffening curve not the second. The table softens
** when the concave windows cover at least CF_SOFTENING_SHARE of the strain range.
*/
#ifndef CF_SOFTENING_H
#define CF_SOFTENING_H

#include "model/table.h"

#define CF_SOFTENING_BEND 0.0125
#define CF_SOFTENING_SHARE 0.25

typedef struct cf_softening {
    int found;      /* 1: concave over at least CF_SOFTENING_SHARE of the range */
    double from;    /* the concave part, table strain (table sign), from the smaller |strain| */
    double to;
    double share;   /* its share of the loading side's range, - */
} cf_softening;

/* The concave part of table d's loading side (a table of fewer than 8 points on that side, or
** one that does not load, is never found softening). */
cf_softening cf_softening_of(const cf_table *d);

#endif
