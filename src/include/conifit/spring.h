/*
** The conical spring as data: its six design parameters (and the two of an optional cylindrical
** tail), its two types, and the one description
** of each parameter (name, unit, JSON key, meaning, fit bounds) that every reader, writer, report,
** export and command-line option works from. Adding a parameter or renaming a key is a change to
** src/model/spring.c alone.
*/
#ifndef CF_SPRING_H
#define CF_SPRING_H

#include <stddef.h>

#include "conifit/error.h"

/* The six design parameters of a conical spring. */
typedef struct cf_spring {
    double D1_mm; /* mean diameter of the smallest active coil, mm */
    double D2_mm; /* mean diameter of the largest active coil, mm (D2 >= D1) */
    double n;     /* number of active coils, dimensionless (n >= 2, real) */
    double d_mm;  /* wire diameter, mm */
    double G_MPa; /* shear modulus of the wire, MPa */
    double H_mm;  /* free length, mm (rest length in the mass-spring model) */
    /* The optional cylindrical tail (law kind conical-tail, src/model/law.md): n_tail coils of
    ** mean diameter D1 wound from the same wire, in series with the cone, taking H_tail of the free
    ** length H. Both 0 (an initializer that lists only the six) is the plain conical spring. */
    double n_tail;     /* number of tail coils, dimensionless (0: no tail) */
    double H_tail_mm;  /* free length of the tail, mm (0 without a tail; the cone has H - H_tail) */
} cf_spring;

typedef enum cf_spring_type {
    CF_TELESCOPING = 0,     /* (D2 - D1)/2 >= n d, solid length d */
    CF_NON_TELESCOPING = 1, /* (D2 - D1)/2 <  n d, solid length n d */
    CF_SPRING_TYPE_NONE = -1 /* no spring: what an accessor returns for a fit that is not there */
} cf_spring_type;

/* Index of each design parameter, in the order D1, D2, n, d, G, H: the CF_P_COUNT parameters of
** every spring (the ones a plain fit places); then the tail's two, up to CF_P_ALL. */
enum { CF_P_D1 = 0, CF_P_D2, CF_P_N, CF_P_D, CF_P_G, CF_P_H, CF_P_COUNT };
enum { CF_P_N_TAIL = CF_P_COUNT, CF_P_H_TAIL, CF_P_ALL };

/* 1 when p has a cylindrical tail (n_tail > 0). */
int cf_spring_has_tail(const cf_spring *p);

/* What conifit knows of one design parameter. */
typedef struct cf_spring_param {
    const char *name;    /* "D1": in messages, reports and NAME=VALUE settings */
    const char *unit;    /* "mm", "-" or "MPa" */
    const char *key;     /* key in fit files, exported springs and scenes: "D1_mm" */
    const char *meaning; /* "mean diameter of the smallest active coil" */
    double lower, upper; /* default bounds of the fit, in unit: wide enough for any tissue table
                         ** in any unit (micrometre to metre springs, foams to steel) */
} cf_spring_param;

/* The description of parameter k (0 <= k < CF_P_ALL); NULL for another k. */
const cf_spring_param *cf_spring_param_info(int k);

/* Value of parameter k of p, and setting it. */
double cf_spring_get(const cf_spring *p, int k);
void cf_spring_set(cf_spring *p, int k, double value);

/* The parameters as text, from the field table, into buf (cap bytes; returns buf), each value
** with `digits` significant digits: "D1 10 mm, D2 30 mm, n 4, d 1 mm, G 8e+04 MPa, H 40 mm", or
** with assign = 1 "D1=10 D2=30 n=4 d=1 G=8e+04 H=40" (no units); the tail's two follow only when
** the spring has a tail. */
const char *cf_spring_text(const cf_spring *p, int digits, int assign, char *buf, size_t cap);

/* Index (< CF_P_COUNT) of the parameter called name (its name "D1" or its key "D1_mm"), or -1;
** the tail's parameters are not found here (a fit places them with the law kind). */
int cf_spring_param_find(const char *name);

/* "telescoping" or "non-telescoping". */
const char *cf_spring_type_name(cf_spring_type type);

/* Parses "telescoping" / "non-telescoping"; CF_E_DATA naming the value otherwise. */
cf_status cf_spring_type_parse(const char *name, cf_spring_type *type, cf_error *err);

#endif
