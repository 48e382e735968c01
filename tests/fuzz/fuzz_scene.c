/*
** libFuzzer harness: the scene reader (io/scene.c) on arbitrary text, then the budget and, for
** scenes within a small budget, the lattice it describes.
*/
#include "fuzz.h"

#include <string.h>

#include "io/budget.h"
#include "model/lattice.h"
#include "io/scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    if (!text)
        return 0;
    memcpy(text, data, size);
    text[size] = '\0';
    cf_scene sc;
    cf_error err = {0};
    if (cf_scene_parse(text, "fuzz.json", &sc, &err) == CF_OK) {
        cf_budget b = {64.0 * 1024 * 1024, 1e5, 1e8};
        cf_scene_cost c;
        cf_law law;
        if (cf_budget_check_size(&sc, "fuzz.json", &b, &c, &err) == CF_OK &&
            cf_law_init(&law, &sc.spring, &err) == CF_OK) {
            cf_lattice lat;
            if (cf_lattice_create(&lat, &law, CF_LAW_CLOSED, &sc.cfg.lattice, &err) == CF_OK) {
                cf_budget_check_steps(&sc, "fuzz.json", &lat, &b, &c, &err);
                cf_lattice_free(&lat);
            }
            cf_law_free(&law);
        }
        cf_scene_free(&sc);
    }
    free(text);
    return 0;
}
