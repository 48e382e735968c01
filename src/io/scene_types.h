/*
** A scene as data (scene.h reads it; schema in src/notes/simulate.md, section "Scenes"): the
** spring, the lattice or the tissue body, its regions, probe and haptic path, the loading
** protocol and the time-dependent effects. A header of its own, so that the parts of the reader
** (scene_haptic.h) depend on the type and not on the reader that uses them.
*/
#ifndef CF_IO_SCENE_TYPES_H
#define CF_IO_SCENE_TYPES_H

#include <stddef.h>

#include "model/body.h"
#include "model/law_internal.h"
#include "model/msm.h"

typedef enum cf_protocol_kind {
    CF_PROTO_RAMP = 0,   /* 0 -> target over duration_s */
    CF_PROTO_CYCLES = 1, /* 0 -> target -> 0, count times, period_s each */
    CF_PROTO_HOLD = 2,   /* 0 -> target over ramp_s, then held for hold_s (creep or relaxation) */
    CF_PROTO_HISTORY = 3 /* through listed (time, value) points: a measured loading history */
} cf_protocol_kind;

/* What a region of a body does (src/notes/simulate.md, "Regions"): every prescribed component of
** its nodes held (fixed) or moved by a displacement (displaced), or a total force spread over it
** (loaded); each ramps from 0 over the run's steps, as the probe does. */
typedef enum cf_region_use {
    CF_REGION_FIXED = 0,
    CF_REGION_DISPLACED = 1,
    CF_REGION_LOADED = 2
} cf_region_use;

typedef struct cf_scene_region {
    cf_region_use use;
    cf_select sel;              /* which nodes */
    unsigned comps;             /* fixed, displaced: bit c set = component c prescribed */
    double vec[3];              /* displaced: displacement, mm; loaded: total force, N */
    char key[48];               /* the scene key that names it ("fixed", "displaced[1]") */
} cf_scene_region;

/* Most points of a probe's path. */
#define CF_SCENE_MAX_PATH 1000

/* Most spring groups a scene may have (a lattice has CF_FAMILY_COUNT at most). */
#define CF_SCENE_MAX_GROUPS 8

/* Most regions a scene may have. */
#define CF_SCENE_MAX_REGIONS 64

/* A spring group of a scene ("groups", src/notes/simulate.md): in a lattice the springs of one
** family (CF_FAMILY_EDGE, _FACE, _BODY), in a body those with both ends in a region, taking a
** law of their own, that of spring. */
typedef struct cf_scene_group {
    int family;                 /* a lattice's: CF_FAMILY_*; a body's: -1 */
    cf_select sel;              /* a body's: the region */
    cf_spring spring;           /* its spring (the scene spring's free length H) */
    char source[600];           /* "params" or the fit file (and type) it came from */
} cf_scene_group;

/* A fibre group of a scene ("fibres", src/notes/simulate.md): one spring per lattice cell along
** a material direction, acting in fibre tension only (model/fibre.h). */
typedef struct cf_scene_fibre {
    double axis[3];             /* its reference direction, unit length (the scene's normalised) */
    double density;             /* springs per cell, > 0 */
    double slack;               /* recruitment strain (fibre.h), [0, 1); 0: taut at rest */
    cf_spring spring;           /* its spring (free length Hf, any) */
    char source[600];           /* "params" or the fit file (and type) it came from */
} cf_scene_fibre;

/* A fibre group of a body's scene ("fibres", src/notes/simulate.md, "Fibres in a body"): a
** tension-only spring per tetrahedron along the direction of the helix rule (cf_body_helix_dirs). */
typedef struct cf_scene_body_fibre {
    double normal[3], reference[3]; /* helix.normal, helix.reference */
    double from_deg, to_deg;        /* helix.from_deg, helix.to_deg */
    cf_spring spring;               /* its spring (any free length) */
    double density;                 /* springs per lattice cell of the scene spring's H */
    double slack;                   /* recruitment strain (fibre.h), [0, 1) */
    char source[600];               /* "params" or the fit file (and type) it came from */
} cf_scene_body_fibre;

typedef struct cf_scene {
    cf_spring spring;           /* the spring of every lattice edge */
    int has_extension;          /* 1: 'spring_extension' makes every element double-acting
                                   (law.h, cf_law.extension) with the spring below */
    cf_spring extension;        /* its extension spring (the same H) */
    char spring_source[600];    /* "params" or the fit file (and type) it came from */
    char fit_path[4096];        /* the fit file 'spring.fit' names, "" with 'spring.params': an
                                   input of the run like the scene itself */
    size_t ngroups;             /* "groups": spring groups with a law of their own (0: every
                                   spring the scene spring's) */
    cf_scene_group groups[CF_SCENE_MAX_GROUPS];
    size_t nfibres;             /* "fibres": fibre groups of a lattice (0: none) */
    cf_scene_fibre fibres[CF_FIBRE_MAX];
    int fibre_fit;              /* 1: "fibres" names a fibre fit file, whose matrix is the spring
                                   and whose groups, weights and kappa the lattice's */
    double fibre_fit_kappa_MPa; /* that fit's volume modulus, MPa */
    double fibre_fit_family[CF_FAMILY_COUNT]; /* its matrix's family weights (edge, face, body) */
    cf_law_method method;       /* law evaluator */
    size_t table_intervals;     /* for CF_LAW_TABLE */
    cf_msm_config cfg;          /* lattice and solver settings */
    cf_msm_effects effects;     /* time-dependent effects */
    cf_protocol_kind kind;
    cf_msm_drive drive;         /* displacement (to_strain) or force (to_stress_kPa) */
    double target;              /* compressive strain (-) or compressive stress (MPa) */
    int cycles;                 /* number of load-unload cycles (CF_PROTO_CYCLES) */
    size_t npath;               /* vertices of the loading path */
    double *path_t_s, *path_v;  /* the path (value as in cf_msm_path) */
    size_t nsamples;            /* reported samples */
    double *sample_t_s;         /* their times, s */
    /* A tissue body instead of the lattice (body.h; src/notes/simulate.md, "Bodies"): */
    int has_body;               /* 1 when the scene has "body" (then no "lattice" or "protocol") */
    char body_mesh[4096];       /* body.mesh: the volume mesh file */
    double body_unit_mm;        /* body.unit_mm: mesh coordinates times this are mm */
    int body_refine;            /* body.refine: uniform refinements of the mesh (0 to 4) */
    double body_element_size_mm; /* body.element_size_mm: with a closed surface (.obj, .stl) for
                                    body.mesh, the target size of the tetrahedra filling it, mm;
                                    0 with a volume mesh */
    int body_volume;            /* 0 no volume term, 1 body.volume_modulus_MPa, 2 body.poisson_ratio,
                                   3 the volume term of spring.fit's lattice (its kappa, taken as
                                   the body's: src/notes/simulate.md, "The fitted lattice's
                                   volume term in a body") */
    double body_volume_value;   /* kappa (MPa) or nu */
    int body_element_term;      /* body.element_term: 1 gives every tetrahedron the isotropic
                                   tensor less its springs' share (cf_body_match_elements) */
    int body_steps;             /* static steps of the run: probe.steps, or body.steps without a
                                   probe */
    int body_dynamic;           /* 1: 'effects.inertia' = true, a dynamic run (body_steps implicit
                                   steps of body_dt_s from 0 to body.duration_s) */
    double body_duration_s;     /* body.duration_s */
    double body_ramp_s;         /* body.ramp_s: the loads and the probe ramp from 0 over it, then
                                   hold (0: applied at the first step) */
    double body_damping_per_s;  /* body.damping_per_s: mass-proportional damping c (c m v) */
    double body_newmark_gamma;  /* body.newmark_gamma: 1/2 (average acceleration) to 1 */
    double body_dt_s;           /* the step: integrator.dt_s, shortened so that the duration is a
                                   whole number of steps */
    size_t nregions;            /* the regions "fixed", "displaced", "loaded", in that order */
    cf_scene_region regions[CF_SCENE_MAX_REGIONS];
    int has_probe;              /* 1 when the scene has "probe" */
    size_t probe_npath;         /* probe.path: 0, or its points (2 to CF_SCENE_MAX_PATH): the
                                   probe's reference point at times probe_path_t_s (strictly
                                   increasing), straight between them; probe.center_mm is the
                                   first point and the steps are equal in time */
    double probe_path_t_s[CF_SCENE_MAX_PATH];
    double probe_path_mm[CF_SCENE_MAX_PATH][3];
    cf_probe probe;             /* probe */
    /* "haptic": the probe's path in time for `simulate --haptic` (src/notes/simulate.md) */
    size_t haptic_n;            /* vertices of the path (0: no "haptic") */
    double *haptic_t_ms, *haptic_depth_mm; /* [t_ms, depth_mm], t from 0 strictly increasing */
    int haptic_iterations;      /* chord iterations per update (cf_body_haptic_step), 1..100 */
    size_t body_nfibres;        /* a body's "fibres": its fibre groups (0: none) */
    cf_scene_body_fibre body_fibres[CF_FIBRE_MAX];
} cf_scene;

#endif
