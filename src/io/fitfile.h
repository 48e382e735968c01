/*
** Reading fitted springs back from a conifit fit file (the JSON that `conifit fit -o` writes).
**
** Schema (all numbers finite; units in the key names):
**   {
**     "conifit_version": "0.1.0",
**     "data": { "file": "data/x.csv", "points": 40, "x_column": "strain", "x_unit": "-",
**               "y_column": "stress", "y_unit": "kPa", "kind": "stress-strain" | "force-displacement",
**               "sign": "tension-positive" | "compression-negative" },
**     "fits": [ { "type": "telescoping" | "non-telescoping",
**                 "params":  { one number per design parameter, under its key },
**                 "derived": { "rho", "travel_mm", "solid_strain", "F_T_N", "F_C_N",
**                              "k0_N_per_mm", "u_T_mm", "index_c", "L_min_mm", "L_max_mm",
**                              and with a tail "u_C_mm", "F_solid_N", "k_tail_N_per_mm", "tau" },
**                 "rmse", "max_abs_error", "r2", ... } , ... ],
**     "better_type": "telescoping" | "non-telescoping" | null (the types tie),
**     ...
**   }
** The keys of "params" are those of the spring's field table (cf_spring_param_info, spring.h), in
** its order; `tests/unit/test_spring.c` checks the documentation's lists of them against it.
** The tail's two ("n_tail", "H_tail_mm") are written only for a spring with a tail and read as 0
** when absent, so a plain spring's file is what it was before the tail existed.
** Only "fits[].type", "fits[].params" (and the provenance fields if present) are needed to read a
** spring back; everything else is report.
**
** The same reader takes a single exported spring (`conifit export --format json`), recognised by
** its "schema" key:
**   { "schema": "conifit-spring-1", "conifit_version": "0.1.0", "type": "telescoping",
**     "params": { ... as above ... },
**     "derived": { ... as above ... }, "units": { ... },
**     "provenance": { "fit_file", "data_file", "rmse", "rmse_unit", "fit_version" } }
** and, for a double-acting element, "params_extension" and "derived_extension" (its extension
** spring) and, for a lattice with a volume term, "lattice": { "volume_modulus_MPa" }, the keys of
** the fit file, which cf_fitfile_load_element reads back.
*/
#ifndef CF_FITFILE_H
#define CF_FITFILE_H

#include "conifit/error.h"
#include "model/law_internal.h"
#include "model/family.h"
#include "model/msm.h"

/* The "schema" value of a single exported spring. */
#define CF_SPRINGFILE_SCHEMA "conifit-spring-1"

/* A spring read from a fit file, with what is known of where it came from. */
typedef struct cf_fitted_spring {
    cf_spring params;
    cf_spring_type type;
    double rmse;                 /* fit RMSE in the data's stress (or force) unit; NAN if absent */
    char data_file[512];         /* "" if absent */
    char y_unit[32];             /* unit of rmse; "" if absent */
    char version[32];            /* conifit version that wrote the file; "" if absent */
    int target_lattice;          /* 1: the spring was fitted through the lattice (the fit's
                                 ** "target" says lattice); 0: the single spring's law (also a
                                 ** file without "target", written before it existed) */
    /* A viscoelastic fit (of a time series) also carries its Prony terms and dashpot. */
    int viscoelastic;            /* 1 when the fit has a "prony" list */
    int prony_count;
    double prony_g[CF_PRONY_MAX], prony_tau_s[CF_PRONY_MAX];
    double prony_k[CF_PRONY_MAX]; /* change of g_i per unit |strain| ("g_per_strain"; 0 when
                                  ** absent: quasi-linear) */
    double eta_MPa_s;            /* dashpot, 0 when none */
    /* A joint fit's double-acting element and volume term (joint.h), read by
    ** cf_fitfile_load_element only: */
    int has_extension;           /* 1: "params_extension" holds the extension spring */
    cf_spring extension;         /* its parameters (H the compression spring's) */
    double volume_modulus_MPa;   /* "lattice.volume_modulus_MPa", 0 when absent */
    int has_weight;              /* 1: a joint fit's "lattice.weights", the family weights its
                                 ** springs were fitted in (a scene and an export take them) */
    double weight[CF_FAMILY_COUNT];
    /* A fit of a law kind the library does not define (its "law" names a kind registered with
    ** cf_law_mech_register, lawmech.h): its mechanics row and quantities ("law_params"); NULL for
    ** the library's conical kinds. */
    const cf_law_mech *mech;
    double q[CF_LAW_Q_MAX];
} cf_fitted_spring;

/* 1 when fs carries lattice weights other than the isotropic calibration's (a joint fit with
** --calibration fitted): the lattice its springs are the material in; 0 otherwise (the
** default lattice is the fit's). */
int cf_fitted_own_weights(const cf_fitted_spring *fs);

/* The law of a fitted spring: its kind's (cf_law_init_kind) or the conical law of its params. The
** extension spring of a pair is the caller's to join. Errors as those calls. */
cf_status cf_fitted_law(const cf_fitted_spring *fs, cf_law *law, cf_error *err);

/* Loads the spring of the given type from the fit file at path ("-":
** standard input); type_name NULL (or "") takes the
** file's "better_type", or the only fit when there is one; when the types tie ("better_type" null,
** "comparison.tie" true), the first feasible fit. Errors: CF_E_NOINPUT when the file
** cannot be opened, CF_E_DATA when it is not JSON, lacks the type or a parameter, or holds a
** non-finite or invalid value (the message names the file, the key and the value). */
cf_status cf_fitfile_load(const char *path, const char *type_name, cf_fitted_spring *out,
                          cf_error *err);

/* cf_fitfile_load refuses a fit whose element is double-acting ("params_extension") or whose
** lattice has a volume term ("lattice.volume_modulus_MPa" > 0) with CF_E_DATA naming the key:
** readers of one spring per element must not run such a fit as its compression spring alone.
** cf_fitfile_load_element (a scene's 'spring.fit', export) reads
** them (has_extension, extension, volume_modulus_MPa), checking the extension spring as params
** (every key, a law it makes, the compression spring's H). */
cf_status cf_fitfile_load_element(const char *path, const char *type_name,
                                  cf_fitted_spring *out, cf_error *err);

/* Most tables a fit file's fit lists (a joint fit's; cf_fitted_model). */
#define CF_FITFILE_TABLES 16

/* A table the fit was fitted to, as its fit file records it. */
typedef struct cf_fitfile_table {
    char file[512];  /* the table's path as the fit named it */
    char mode[24];   /* its test mode ("uniaxial", "shear", ...) */
    size_t points;
    char unit[32];   /* the unit of rmse and scale (the table's stress or force unit) */
    double rmse;     /* the fit's RMSE of the table (its target: the lattice's homogenised cell, or
                     ** the single spring's law), in unit */
    double scale;    /* its RMS stress, the joint objective's weight ("scale"), in unit; NAN when
                     ** the file does not record it (a single fit, a joint fit written before the
                     ** key) */
} cf_fitfile_table;

/* A fit file's fit as a model to evaluate (cf_fitfile_load_model): the spring (and a double-acting
** element's extension spring and the volume term, as cf_fitfile_load_element reads them) and the
** lattice it was fitted through. */
typedef struct cf_fitted_model {
    cf_fitted_spring spring;
    int joint;                 /* 1: a joint fit (root "joint": true) */
    int force_displacement;    /* 1: fitted to a force-displacement table (data.kind) */
    char target_mode[24];      /* the fit's target.mode ("" when absent, or a joint fit) */
    double weight[3];          /* the lattice's family weights edge, face, body (the fit's
                               ** "lattice.weights", or "validation.lattice.weights"); valid when
                               ** has_weight */
    int has_weight;
    cf_law_method method;      /* "validation.law_method" (CF_LAW_CLOSED when absent; a joint fit's
                               ** cells are evaluated closed) */
    double objective;          /* a joint fit's weighted objective ("objective"); NAN otherwise */
    size_t ntables;            /* the tables fitted (a joint fit's "tables", a single fit's "data") */
    cf_fitfile_table tab[CF_FITFILE_TABLES];
} cf_fitted_model;

/* Loads the fit of the given type (as cf_fitfile_load chooses it) as a model: its spring as
** cf_fitfile_load_element reads it, and what says how it was evaluated (above). Refuses, with
** CF_E_DATA naming the file and key: a single exported spring (it does not record its lattice), a
** time-series fit, a fit through the lattice without the lattice's weights, a weight, table entry
** or objective that is not a finite number; CF_E_NOINPUT as cf_fitfile_load. */
cf_status cf_fitfile_load_model(const char *path, const char *type_name, cf_fitted_model *out,
                                cf_error *err);

/* The fibre-reinforced lattice of a joint fit file ("fibre_lattice", one entry per cross-fibre
** axis): canonical members (family.h) of the matrix and of each group, the groups' axes of the
** fibre frame ('f', 's', 'n'; the lattice's x, y, z) and the volume modulus. */
typedef struct cf_fitted_fibre {
    cf_ident matrix;
    int ngroups;
    char axis[CF_FIBRE_MAX];
    cf_ident group[CF_FIBRE_MAX];
    double slack[CF_FIBRE_MAX]; /* each group's recruitment strain (0 where the file has none) */
    double family[CF_FAMILY_COUNT]; /* the matrix's family weights, edge, face, body (1, 1, 1
                                    ** where the file has none) */
    double kappa_MPa;
} cf_fitted_fibre;

/* Loads the entry of path's "fibre_lattice" whose cross_axis is cross ("s" or "n"). CF_E_DATA
** naming the file and key: no "fibre_lattice", no entry of that cross axis, a quantity that is
** missing or not finite (rho in (0, 1], solid_strain in (0, 1), stress scale and kappa > 0), an
** axis other than f, s, n or twice; CF_E_NOINPUT as cf_fitfile_load. */
cf_status cf_fitfile_load_fibre(const char *path, const char *cross, cf_fitted_fibre *out,
                                cf_error *err);

/* Splits "FILE.json:TYPE" into path and type (type NULL when there is no ":TYPE" suffix naming a
** spring type) and loads it. */
cf_status cf_fitfile_load_spec(const char *spec, cf_fitted_spring *out, cf_error *err);

#endif
