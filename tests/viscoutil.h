/*
** What the tests of the time-dependent model and its fit share: the measured protocol of a ramp
** and hold, and a model with two Prony terms.
*/
#ifndef CF_TESTS_VISCOUTIL_H
#define CF_TESTS_VISCOUTIL_H

#include <math.h>
#include <string.h>

#include "model/viscomodel.h"

/* A ramp to compressive strain 0.3 (table's sign: -0.3) in 30 s, then held to 330 s: 16 ramp
** points, 20 hold points spaced geometrically (the protocol of the published muscle tables). */
#define NS 36
static inline void ramp_hold(double *t, double *x)
{
    for (int k = 0; k <= 15; k++) {
        t[k] = 2.0 * k;
        x[k] = -0.3 * t[k] / 30.0;
    }
    for (int k = 16; k < NS; k++) {
        t[k] = 30 + 300 * pow((double)(k - 15) / (NS - 16), 2);
        x[k] = -0.3;
    }
}

/* A model with two Prony terms, the one most tests start from. */
static inline cf_visco_params known(void)
{
    cf_visco_params p;
    memset(&p, 0, sizeof p);
    p.ident.rho = 0.3;
    p.ident.solid = 0.5;
    p.ident.scale = 0.01;
    p.nbranch = 2;
    p.g[0] = 0.35;
    p.tau_s[0] = 3;
    p.g[1] = 0.2;
    p.tau_s[1] = 40;
    return p;
}

#endif
