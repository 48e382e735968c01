/*
** What a run of a scene (scene.h, cf_msm_run) shows beyond its curve: where the lattice first
** loses stability, the energy each load cycle dissipates, the strain at which the unloading
** carries no stress, and whether that strain is a permanent set or viscous strain that recovers.
**
** Samples are those of cf_msm_run: compression positive, stress in MPa. A cycles scene's run of n
** samples holds its cycles back to back, cycle c (0-based) over samples [c per, (c + 1) per] with
** per = (n - 1) / count.
*/
#ifndef CF_HYSTERESIS_H
#define CF_HYSTERESIS_H

#include <stddef.h>

#include "io/budget.h"
#include "conifit/error.h"
#include "model/law_internal.h"
#include "model/msm.h"
#include "io/scene.h"

/* Index of the first sample whose tangent had a negative pivot; n when none did. */
size_t cf_hysteresis_first_unstable(const cf_msm_sample *s, size_t n);

/* Area enclosed by the stress-strain path over samples [a, b] (trapezoids), kPa = kJ/m^3: the
** energy per unit reference volume the material took in over the path; for a closed loop run
** counter-clockwise in the (strain, stress) plane, the energy dissipated. a <= b < the samples. */
double cf_hysteresis_loop_energy(const cf_msm_sample *s, size_t a, size_t b);

/* One load cycle of a cycles scene's run. */
typedef struct cf_hysteresis_cycle {
    double energy_kPa;     /* dissipated energy, kPa = kJ/m^3 (cf_hysteresis_loop_energy) */
    double zero_strain;    /* force drive: the strain at zero force at the cycle's end; displacement
                           ** drive: the strain at which the unloading stress first reaches zero
                           ** (linear between samples), or the end strain when it never does */
} cf_hysteresis_cycle;

/* Cycle c (0 <= c < sc->cycles) of the run s[0..n-1] of the cycles scene sc. */
cf_hysteresis_cycle cf_hysteresis_cycle_of(const cf_scene *sc, const cf_msm_sample *s, size_t n,
                                           int c);

/* The recovery test. Strain left at zero force is not a permanent set: a viscous lattice creeps
** back. For a displacement-driven cycles scene with dashpots or Maxwell branches (no inertia),
** one force-driven cycle from the virgin state to the run's peak stress, an unloading to zero
** force, and zero force held for ten periods (or ten relaxation times, if longer). */
typedef struct cf_hysteresis_recovery {
    int ran;               /* 0: the scene is not one the test applies to (the rest is zero) */
    double peak_MPa;       /* peak stress of the scene's run, the force cycle's peak, MPa */
    double hold_s;         /* how long zero force is held, s */
    double zero_strain;    /* strain when the force is back to zero */
    double end_strain;     /* strain at the end of the hold */
    int recovered;         /* |end_strain| <= 1e-3 |zero_strain| + 1e-12: no permanent set */
} cf_hysteresis_recovery;

/* Runs the recovery test for the scene sc, whose run (s, n) gives the peak stress, with the law
** of its spring. CF_OK with r->ran = 0 when the test does not apply; the run's error otherwise. */
cf_status cf_hysteresis_recovery_test(const cf_scene *sc, const cf_law *law,
                                      const cf_msm_sample *s, size_t n,
                                      cf_hysteresis_recovery *r, cf_error *err);

/* The recovery test's cost on the scene's lattice lat, added to the run's in *c, against the
** budget b: CF_OK when the test does not apply or fits in what the run leaves of the step and work
** limits; else CF_E_DATA naming the key (effects.viscosity.tau_s, integrator.dt_s or
** integrator.substeps) and a value of it that would fit. `name` (the scene's file) starts the
** message. */
cf_status cf_hysteresis_recovery_check(const cf_scene *sc, const char *name, const cf_lattice *lat,
                                       const cf_budget *b, cf_scene_cost *c, cf_error *err);

#endif
