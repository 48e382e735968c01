/*
** How far a body's spring network relaxes below its calibration (src/notes/contact-study.md,
** "Why the sphere drifts"): the study's graded quarter block (contact_study.c), its springs at
** small strain (k = c k0 H / L0), an affine strain imposed on the block's boundary, the inner
** nodes left to find their equilibrium (conjugate gradients). Prints, per strain mode, the
** network's energy before relaxing (the calibration's Voigt average) and after, over that of
** the isotropic continuum of the body's mu and lambda = mu. SIDE mm (default 30) shrinks the
** block about the contact point, meshed as the study meshes it there (the contact zone's
** elements only).
**
**   net_relax REFINE [SIDE]
*/
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "io/mesh.h"
#include "model/body.h"
#include "study/relax.h"

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: net_relax REFINE [SIDE]\n");
        return 2;
    }
    const double r = atof(argv[1]);
    cf_spring p = {10, 30, 4, 1, 8e4, 40};
    cf_law law;
    cf_error err = {0};
    if (cf_law_init(&law, &p, NULL) != CF_OK)
        return 70;
    const double W = argc > 2 ? atof(argv[2]) : 30, D = W;
    double lo[3] = {0, 0, -D}, hi[3] = {W, W, 0}, focus[3] = {0, 0, 0};
    cf_mesh m;
    if (cf_mesh_box(lo, hi, focus, 0.3 / r, 8 / r, 0.4 / r, &m, &err) != CF_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 70;
    }
    cf_body b;
    if (cf_body_create(&b, &m, &law, CF_LAW_CLOSED, 0, &err) != CF_OK)
        return 70;
    uint8_t *fr = calloc(b.nn, 1);
    if (!fr)
        return 70;
    size_t nfree = 0;
    for (size_t i = 0; i < b.nn; i++) {
        const double *X = b.X + 3 * i;
        fr[i] = !(X[0] < 1e-9 || X[1] < 1e-9 || X[2] > -1e-9 || X[0] > W - 1e-9 ||
                  X[1] > W - 1e-9 || X[2] < -D + 1e-9);
        nfree += fr[i];
    }
    static const char *name[4] = {"uniaxial strain zz", "shear xz", "shear xy", "pure shear xx-yy"};
    static const double G[4][3][3] = {{{0, 0, 0}, {0, 0, 0}, {0, 0, 1}},
                                      {{0, 0, .5}, {0, 0, 0}, {.5, 0, 0}},
                                      {{0, .5, 0}, {.5, 0, 0}, {0, 0, 0}},
                                      {{.5, 0, 0}, {0, -.5, 0}, {0, 0, 0}}};
    printf("refine %g, side %g mm, %zu nodes, %zu inner\n", r, W, b.nn, nfree);
    for (int mode = 0; mode < 4; mode++) {
        double voigt;
        const double rel = relax_ratio(&b, &law, G[mode], fr, &voigt);
        if (rel < 0)
            return 70;
        printf("  %-20s Voigt/iso %.4f  relaxed/iso %.4f  relaxed/Voigt %.4f\n", name[mode], voigt,
               voigt * rel, rel);
    }
    free(fr);
    cf_body_free(&b);
    cf_mesh_free(&m);
    cf_law_free(&law);
    return 0;
}
