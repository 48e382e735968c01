/*
** The description of the spring's design parameters (see spring.h).
*/
#include "conifit/spring.h"

#include <stdio.h>
#include <string.h>

static const cf_spring_param params[CF_P_ALL] = {
    {"D1", "mm", "D1_mm", "mean diameter of the smallest active coil", 1e-6, 1e6},
    {"D2", "mm", "D2_mm", "mean diameter of the largest active coil", 1e-6, 1e9},
    {"n", "-", "n", "number of active coils (>= 2, may be fractional)", 2, 1e7},
    {"d", "mm", "d_mm", "wire diameter", 1e-7, 1e5},
    {"G", "MPa", "G_MPa", "shear modulus of the wire (N/mm^2)", 1e-15, 1e15},
    {"H", "mm", "H_mm", "free length (rest length in the mass-spring model)", 1e-6, 1e6},
    {"n_tail", "-", "n_tail", "coils of the cylindrical tail (diameter D1, same wire; 0: none)", 0,
     1e7},
    {"H_tail", "mm", "H_tail_mm", "free length of the cylindrical tail (part of H)", 0, 1e6},
};

int cf_spring_has_tail(const cf_spring *p)
{
    return p->n_tail > 0;
}

const cf_spring_param *cf_spring_param_info(int k)
{
    return (k >= 0 && k < CF_P_ALL) ? &params[k] : NULL;
}

double cf_spring_get(const cf_spring *p, int k)
{
    switch (k) {
    case CF_P_D1: return p->D1_mm;
    case CF_P_D2: return p->D2_mm;
    case CF_P_N: return p->n;
    case CF_P_D: return p->d_mm;
    case CF_P_G: return p->G_MPa;
    case CF_P_H: return p->H_mm;
    case CF_P_N_TAIL: return p->n_tail;
    case CF_P_H_TAIL: return p->H_tail_mm;
    default: return 0;
    }
}

void cf_spring_set(cf_spring *p, int k, double value)
{
    switch (k) {
    case CF_P_D1: p->D1_mm = value; break;
    case CF_P_D2: p->D2_mm = value; break;
    case CF_P_N: p->n = value; break;
    case CF_P_D: p->d_mm = value; break;
    case CF_P_G: p->G_MPa = value; break;
    case CF_P_H: p->H_mm = value; break;
    case CF_P_N_TAIL: p->n_tail = value; break;
    case CF_P_H_TAIL: p->H_tail_mm = value; break;
    default: break;
    }
}

const char *cf_spring_text(const cf_spring *p, int digits, int assign, char *buf, size_t cap)
{
    size_t n = 0;
    if (cap)
        buf[0] = '\0';
    const int count = cf_spring_has_tail(p) ? CF_P_ALL : CF_P_COUNT;
    for (int k = 0; k < count && n < cap; k++) {
        const cf_spring_param *sp = &params[k];
        const int unit = !assign && strcmp(sp->unit, "-") != 0;
        int w = snprintf(buf + n, cap - n, "%s%s%s%.*g%s%s", k ? (assign ? " " : ", ") : "",
                         sp->name, assign ? "=" : " ", digits, cf_spring_get(p, k),
                         unit ? " " : "", unit ? sp->unit : "");
        n += w > 0 ? (size_t)w : 0;
    }
    return buf;
}

int cf_spring_param_find(const char *name)
{
    for (int k = 0; name && k < CF_P_COUNT; k++)
        if (strcmp(name, params[k].name) == 0 || strcmp(name, params[k].key) == 0)
            return k;
    return -1;
}

const char *cf_spring_type_name(cf_spring_type type)
{
    return type == CF_TELESCOPING       ? "telescoping"
           : type == CF_NON_TELESCOPING ? "non-telescoping"
                                        : "none";
}

cf_status cf_spring_type_parse(const char *name, cf_spring_type *type, cf_error *err)
{
    if (name && strcmp(name, "telescoping") == 0) {
        *type = CF_TELESCOPING;
        return CF_OK;
    }
    if (name && strcmp(name, "non-telescoping") == 0) {
        *type = CF_NON_TELESCOPING;
        return CF_OK;
    }
    return cf_error_set(err, CF_E_DATA,
                        "unknown spring type '%s' (expected telescoping or non-telescoping)",
                        name ? name : "(null)");
}
