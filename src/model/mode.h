/*
** The test modes as a table (mode.c): one row per mode of cf_mode, holding what
** every layer needs to know of a mode -- its name, how it deforms a block (which stretches it sets,
** which it leaves free, which stress it reads), what its abscissa is, how a Cauchy stress becomes
** a nominal one, the incompressible forms of the hyperelastic baselines, and the words and labels
** of reports and plots. A new mode is a row here plus its formulas; the code that merely carries
** a mode reads the row.
*/
#ifndef CF_MODEL_MODE_H
#define CF_MODEL_MODE_H

#include "conifit/error.h"

typedef enum cf_mode {
    CF_MODE_UNIAXIAL = 0,
    CF_MODE_SHEAR = 1,
    CF_MODE_PLANAR = 2,
    CF_MODE_EQUIBIAXIAL = 3,
    CF_MODE_CONFINED = 4,
    CF_MODE_BIAXIAL = 5,
    CF_MODE_COUNT = 6
} cf_mode;

/* "uniaxial", "shear", "planar", "equibiaxial", "confined", "biaxial"; the parser refuses anything else
** with CF_E_DATA naming the value. */
const char *cf_mode_name(cf_mode m);
cf_status cf_mode_parse(const char *name, cf_mode *m, cf_error *err);

typedef struct cf_mode_row {
    const char *name;          /* as in tables' "# mode:" and the fit file */
    const char *deformation;   /* what the mode does to a block, for help and notes */
    /* The deformation gradient F at the mode's strain e and free stretch a: the identity, with
    ** 1 + e on the diagonal entries of strain_mask (bit i: F[i][i]), a on those of free_mask, and
    ** e at F[shear_i][shear_j] when shear_i >= 0. */
    unsigned strain_mask, free_mask;
    int shear_i, shear_j;
    int zero;                  /* the diagonal nominal stress the free stretch zeroes; -1: none */
    int si, sj;                /* the nominal stress component the mode reads */
    int any_sign;              /* the abscissa is an amount of shear: any sign, engineering only */
    int spring_curve;          /* the single spring's law is a curve of this mode (a uniaxial
                                  one); elsewhere only the lattice or its cell has a curve */
    int cauchy_over_stretch;   /* nominal = Cauchy / (1 + e) (incompressible); 0: nominal = Cauchy */
    const char *cauchy_words;  /* how that conversion is said in the report */
    /* Incompressible forms (the Yeoh and Ogden baselines): the principal stretches are l along the
    ** load, l^-q_in_plane... as lateral exponent q (1/2 uniaxial, 1 planar and shear, 2
    ** equibiaxial); 0 when an incompressible solid cannot follow the mode. */
    double q;
    const char *no_incompressible; /* why not, when q is 0 */
    const char *yeoh, *ogden;  /* the baselines' formulas in the mode, NULL when none */
    const char *x_quantity;    /* "engineering strain" or "amount of shear" (plots' axis) */
    const char *x_short;       /* "strain" or "amount of shear" (short labels) */
} cf_mode_row;

/* The row of mode m; NULL when m is not a mode. */
const cf_mode_row *cf_mode_row_of(cf_mode m);

/* F (row-major 3x3) of mode m at strain e and free stretch a, as the row says (biaxial: k = 1). */
void cf_mode_place(cf_mode m, double e, double a, double F[9]);
/* The same with the biaxial mode's strain along y per unit strain along x, F[1][1] = 1 + k e
** (other modes ignore k). */
void cf_mode_place_k(cf_mode m, double e, double a, double k, double F[9]);

/* The mode names as a list for messages: "uniaxial, shear, planar, equibiaxial, confined or
** biaxial". */
const char *cf_mode_list(void);

#endif
