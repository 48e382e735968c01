/*
** The scene's "haptic" section (scene_haptic.h): the probe's path as a list of [t_ms, depth_mm]
** vertices, linear between them, starting at 0 ms and strictly increasing in time; the chord
** iterations per update of the haptic loop (body.h, cf_body_haptic_step).
*/
#include "io/scene_haptic.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

cf_status cf_scene_haptic_parse(json_t *h, const char *name, cf_scene *sc, cf_error *err)
{
    if (!json_is_object(h))
        return cf_error_set(err, CF_E_DATA, "%s: key 'haptic' must be an object", name);
    const char *key;
    json_t *v;
    json_object_foreach(h, key, v)
    {
        if (strcmp(key, "path") && strcmp(key, "iterations"))
            return cf_error_set(err, CF_E_DATA, "%s: unknown key 'haptic.%s' (expected path or "
                                "iterations)", name, key);
    }
    json_t *it = json_object_get(h, "iterations");
    sc->haptic_iterations = 3;
    if (it) {
        const double n = json_is_number(it) ? json_number_value(it) : NAN;
        if (!(n >= 1 && n <= 100) || n != floor(n))
            return cf_error_set(err, CF_E_DATA, "%s: key 'haptic.iterations' = %g: must be a "
                                "whole number from 1 to 100", name, n);
        sc->haptic_iterations = (int)n;
    }
    json_t *path = json_object_get(h, "path");
    const size_t n = json_is_array(path) ? json_array_size(path) : 0;
    if (n < 2)
        return cf_error_set(err, CF_E_DATA, "%s: key 'haptic.path' must be a list of at least two "
                            "[t_ms, depth_mm] pairs", name);
    sc->haptic_t_ms = malloc(n * sizeof *sc->haptic_t_ms);
    sc->haptic_depth_mm = malloc(n * sizeof *sc->haptic_depth_mm);
    if (!sc->haptic_t_ms || !sc->haptic_depth_mm)
        return cf_error_set(err, CF_E_INTERNAL, "out of memory for the haptic path");
    sc->haptic_n = n;
    for (size_t i = 0; i < n; i++) {
        json_t *p = json_array_get(path, i), *t = json_array_get(p, 0), *d = json_array_get(p, 1);
        if (!json_is_array(p) || json_array_size(p) != 2 || !json_is_number(t) ||
            !json_is_number(d))
            return cf_error_set(err, CF_E_DATA, "%s: key 'haptic.path[%zu]' must be a pair of "
                                "numbers [t_ms, depth_mm]", name, i);
        const double tv = json_number_value(t), dv = json_number_value(d);
        const double prev = i ? sc->haptic_t_ms[i - 1] : 0;
        if (!isfinite(tv) || (i == 0 && tv != 0) || (i > 0 && !(tv > prev)) ||
            !(tv <= CF_HAPTIC_MAX_MS))
            return cf_error_set(err, CF_E_DATA, "%s: key 'haptic.path[%zu]' time %g ms: the path "
                                "starts at 0 ms and its times increase strictly, to at most %g ms",
                                name, i, tv, CF_HAPTIC_MAX_MS);
        if (!isfinite(dv) || fabs(dv) > 1e12)
            return cf_error_set(err, CF_E_DATA, "%s: key 'haptic.path[%zu]' depth %g mm: must be "
                                "a finite number of at most 1e12 in size", name, i, dv);
        sc->haptic_t_ms[i] = tv;
        sc->haptic_depth_mm[i] = dv;
    }
    return CF_OK;
}
