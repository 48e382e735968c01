/*
** Export of a fitted conical spring, or of the whole calibrated lattice it was validated in, to
** other simulators: the law as a force-displacement table, written in each target's own
** conventions and units, either as a block to paste into a model or as a model that runs as it is.
** The law's table is in export_table.h, the formats as a type in export_types.h.
**
** Sign conventions: conifit's u > 0 compresses and F has the sign of u. CalculiX, Abaqus,
** FEBio, LS-DYNA and SOFA take tension positive, so their tables hold elongation = -u (mm) and
** force = -F(u) (N), ascending in elongation.
*/
#ifndef CF_EXPORT_H
#define CF_EXPORT_H

#include <stddef.h>
#include <stdio.h>

#include "conifit/error.h"
#include "export/export_table.h"
#include "export/export_types.h"
#include "io/fitfile.h"
#include "model/law_internal.h"
#include "model/msm.h"
#include "io/scene.h"

/* One entry of the registry, as callers see it. */
typedef struct cf_export_format_info {
    cf_export_format format;
    const char *name;        /* the value of --format: "calculix" */
    const char *extension;   /* the usual file name ending, with its dot: ".inp" */
    const char *description; /* one line: the target and what the block is */
    int model;               /* 1: writes runnable models (one spring, or the lattice) */
    int table;               /* 1: writes the law as a table (json writes the spring itself) */
    size_t max_rows;         /* most rows the target reads in one table, 0 for no limit */
    int even;                /* 1: the target resamples a curve to evenly spaced points, so its
                             ** table is evenly spaced (max_rows at most, its range shortened to
                             ** where that meets the tolerance) */
} cf_export_format_info;

/* The entry of a format, NULL for a value outside the enum. Formats run 0 .. COUNT - 1. */
const cf_export_format_info *cf_export_format_get(cf_export_format format);

/* Parses a format name; CF_E_DATA naming every format otherwise. */
cf_status cf_export_format_parse(const char *name, cf_export_format *format, cf_error *err);

/* The format whose extension ends path: CF_OK with *format; CF_E_DATA when none does, or when
** several share it (the message names them). */
cf_status cf_export_format_of_path(const char *path, cf_export_format *format, cf_error *err);

/* The name of a format ("?" outside the enum). */
const char *cf_export_format_name(cf_export_format format);

/* Writes the names of the formats (all, or only those that write models) into buf as an English
** list, "a, b or c"; returns buf (truncated to cap). */
const char *cf_export_format_list(char *buf, size_t cap, int models_only);

/* What to write. Build with cf_export_default_options, then change fields. */
typedef struct cf_export_options {
    cf_export_format format;
    double tol;          /* tolerance of the table, fraction of F_C */
    int have_range;      /* 1: the table covers [u_lo_mm, u_hi_mm] only */
    double u_lo_mm, u_hi_mm; /* compression range of the table, mm (u_lo <= 0 <= u_hi) */
    int example;         /* a complete one-spring model that runs as it is, instead of the block */
    const char *source;  /* name of the fit file, for provenance ("" or NULL if none) */
    const char *output;  /* name of the file written (-o), from which a model names its own
                         ** outputs (FEBio's log file); "" or NULL for standard output */
    int auto_tol;        /* calculix/abaqus: loosen tol (x2, x2.5, x2 ...) until the table fits
                         ** CF_EXPORT_CALCULIX_MAX_ROWS rows, instead of refusing */
} cf_export_options;

cf_export_options cf_export_default_options(void);

/* What was written: row count and achieved error, for the user. */
typedef struct cf_export_report {
    size_t rows;          /* rows of the table written (largest of all groups for a lattice) */
    double max_err_rel;   /* achieved maximum error, fraction of F_C */
    double max_err_N;     /* the same in N (one spring, weight 1) */
    double u_lo_mm, u_hi_mm; /* range of the table, mm */
    double tol;           /* tolerance the table was built with */
    int even;             /* 1: an evenly spaced table, over [u_lo, u_hi] of [req_lo, req_hi] */
    double req_lo_mm, req_hi_mm; /* the range asked for, mm */
    double end_force_rel; /* the law's force at the table's ends, fraction of F_C (the larger) */
    double solid_force_rel; /* the law's force at solid, fraction of F_C: 1, or F_solid/F_C > 1
                            ** for a spring with a tail */
    size_t groups;        /* lattice: spring groups (one table each) */
    size_t springs;       /* lattice: springs */
    size_t nodes;         /* lattice: nodes */
    size_t steps;         /* lattice: load steps */
    char warning[1024];   /* "" or what the model does not do as conifit does (a body's probe
                          ** replayed rather than solved as a contact; a scene's time protocol
                          ** written without its time effects; a loading cut where the lattice
                          ** stops following it) */
} cf_export_report;

/* Writes the spring in the chosen format to out. Never writes NaN or Inf. */
cf_status cf_export_write(FILE *out, const cf_fitted_spring *fs, const cf_export_options *opt,
                          cf_export_report *rep, cf_error *err);

/* Most load steps of a lattice export. */
#define CF_EXPORT_MAX_STEPS 256

/* The lattice to export and its loading: a static uniaxial compression (the validation's test),
** reported at each strain of `strain` (compressive strain, -, > 0 shortens; increasing). */
typedef struct cf_export_lattice {
    cf_msm_config cfg;          /* lattice and Newton settings */
    cf_law_method method;       /* evaluator of conifit's own reference run */
    size_t nsteps;              /* load steps, <= CF_EXPORT_MAX_STEPS */
    double strain[CF_EXPORT_MAX_STEPS]; /* compressive strain at the end of each step, - */
    int stress_drive;           /* 1: strain[] holds compressive nominal stresses (MPa) that
                                ** conifit's elastic lattice, force-driven, turns into the strains
                                ** written (a creep protocol) */
    size_t ngroups;             /* spring groups with a law of their own (a scene's "groups"):
                                ** group k is the family group_family[k] (CF_FAMILY_*) with the
                                ** law of group_spring[k] (the fit's free length H); 0: none */
    int group_family[CF_FAMILY_COUNT];
    cf_spring group_spring[CF_FAMILY_COUNT];
    size_t nfibre;              /* fibre groups (a scene's "fibres"; model/fibre.h): group k one
                                ** spring of fibre_spring[k] per cell along the unit fibre_dir[k]
                                ** (lattice frame), fibre_density[k] per cell; 0: none */
    cf_spring fibre_spring[CF_FIBRE_MAX];
    double fibre_dir[CF_FIBRE_MAX][3];
    double fibre_density[CF_FIBRE_MAX];
    double fibre_slack[CF_FIBRE_MAX]; /* group k's recruitment strain (model/fibre.h) */
    char note[640];             /* "" or, for a scene's time protocol written as its quasi-static
                                ** displacement history, what the model does not carry (the
                                ** file's header and the report's warning say it) */
} cf_export_lattice;
/* Default loading: CF_EXPORT_DEFAULT_STEPS equal steps to this fraction of the solid strain. */
#define CF_EXPORT_DEFAULT_STEPS 20
#define CF_EXPORT_DEFAULT_STRAIN_FRACTION 0.5

/* The validation's lattice (cf_validate_default) loaded in CF_EXPORT_DEFAULT_STEPS equal steps to
** half the solid strain of law. */
cf_export_lattice cf_export_lattice_default(const cf_law *law);

/* The lattice and loading of a scene under a displacement drive: protocol "ramp" (a static
** uniaxial compression, no time effect), or a time protocol ("hold", "cycles", "history") written
** as its quasi-static displacement history of the elastic lattice, lx->note naming what is not
** carried (the time effects: viscosity, damping, inertia), a stress drive through the strains
** of conifit's elastic lattice under it; the steps are the scene's samples after t = 0.
** CF_E_DATA naming the key otherwise (a ramp under a stress drive, gravity). */
cf_status cf_export_lattice_from_scene(const cf_scene *sc, const char *name,
                                       cf_export_lattice *lx, cf_error *err);

/* Writes the lattice built from the fitted spring, every spring family (and each share of it at
** the faces) as its own group with its weight and its own table, the boundary conditions, the
** loading and the output requests, as a model that runs in the target (calculix, abaqus, febio,
** lsdyna, sofa). conifit's own static run of the same lattice is done first: its top-face
** reaction at every step is written into the file's header for comparison. CF_E_DATA when the
** lattice cannot follow the loading (a solve fails, or a spring would pass the table's end),
** with the largest strain that works. Never writes NaN or Inf. */
cf_status cf_export_write_lattice(FILE *out, const cf_fitted_spring *fs,
                                  const cf_export_options *opt, const cf_export_lattice *lx,
                                  cf_export_report *rep, cf_error *err);

/* conifit's own static run of a body probed by a flat punch, step by step: what a body's export
** carries (cf_export_write_body). Arrays of the caller's. */
typedef struct cf_export_body_run {
    size_t nsteps;
    const double *depth_mm;  /* nsteps: the probe's depth at each step */
    const double *force_N;   /* nsteps: conifit's probe force (positive pushing into the body) */
    const double *x_mm;      /* nsteps * 3 nn: the positions solved at each step */
    const uint8_t *contact;  /* nsteps * nn: 1 for the nodes in the probe's contact set at each
                             ** step (cf_body_contact_set) */
} cf_export_body_run;

/* Writes the tissue body b (model/body.h) as a CalculiX or FEBio 4 model or a SOFA scene
** (opt->format calculix, febio or sofa; others CF_E_DATA; sofa only without a volume term,
** kappa = 0, nu = 0.25, since SOFA's springs cannot express it): every edge a spring group of its
** own, rest length L0 and its calibration factor as the weight (the law in strain form times that
** factor, as the lattice's groups); the held components; the volume term as conifit takes it, per
** node (J_a of the quarter volumes around node a): CalculiX has no element that does, so it is
** written as one grounded linear spring per node whose displacement an *EQUATION ties to the
** node's volume change, linearised about the rest state (src/notes/export.md gives what that
** costs); FEBio: tet4 elements in a ut4 domain (FEBio's node-averaged tetrahedron) with alpha 0,
** of a Mooney-Rivlin material with c1 = c2 = 0, k = kappa and pressure_model 2. The probe (a flat
** punch moving along +-z) is carried as conifit ran it: its contact set and the displacement along
** z of each node of it at each step, from run, prescribed (x and y free: frictionless); CalculiX
** one *STEP per load step with that step's set, FEBio and SOFA every node that is ever in contact
** driven along its solved z displacement at every step (a node outside the set then sits at
** conifit's equilibrium, where its reaction is zero). conifit's probe force at every step is in
** the header for comparison, and rep->warning names the replay. CF_E_DATA for another probe or a
** run without contact. Never writes NaN or Inf. */
cf_status cf_export_write_body(FILE *out, const cf_body *b, const cf_probe *pr,
                               const cf_export_body_run *run, const cf_export_options *opt,
                               cf_export_report *rep, cf_error *err);

#endif
