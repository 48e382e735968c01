/*
** The design limits a flag widens, and options with the limits that hold a fit widened as far as
** those flags go (fit.h): what the fit would reach without them.
*/
#include "fit/fit.h"

const char *cf_fit_constraint_flag(unsigned bit)
{
    switch (bit) {
    case CF_C_INDEX_MAX: return "--index-max";
    case CF_C_RHO_MIN: return "--rho-min";
    case CF_C_COILS_MAX: return "--n-max";
    case CF_C_G_MAX: return "--G-max";
    case CF_C_D2_H: return "--D2-max-H";
    case CF_C_TRAVEL: return "nothing: no spring reaches the largest strain (a solid strain is "
                             "below 1)";
    case CF_C_TYPE: return "--rho-min, --index-max, --D2-max-H (a telescoping spring needs "
                           "rho <= index_max/(index_max + 4))";
    }
    return "--fix";
}

const char *cf_fit_constraint_flag_for(unsigned bit, int force_displacement)
{
    if (bit == CF_C_TRAVEL && force_displacement)
        return "nothing: no spring of the fitted law travels past the table's largest "
               "displacement";
    return cf_fit_constraint_flag(bit);
}

unsigned cf_fit_relax(const cf_fit_options *o, unsigned bits, cf_fit_options *out)
{
    *out = *o;
    unsigned done = 0;
    if ((bits & CF_C_INDEX_MAX) && o->index_max < CF_FIT_INDEX_MAX_LIMIT)
        out->index_max = CF_FIT_INDEX_MAX_LIMIT, done |= CF_C_INDEX_MAX;
    if ((bits & CF_C_RHO_MIN) && o->rho_min > CF_FIT_RHO_MIN_LIMIT)
        out->rho_min = CF_FIT_RHO_MIN_LIMIT, done |= CF_C_RHO_MIN;
    if ((bits & CF_C_COILS_MAX) && !o->fixed[CF_P_N] && o->upper[CF_P_N] < CF_FIT_COILS_MAX_LIMIT)
        out->upper[CF_P_N] = CF_FIT_COILS_MAX_LIMIT, done |= CF_C_COILS_MAX;
    if ((bits & CF_C_G_MAX) && !o->fixed[CF_P_G] && o->upper[CF_P_G] < CF_FIT_G_MAX_LIMIT)
        out->upper[CF_P_G] = CF_FIT_G_MAX_LIMIT, done |= CF_C_G_MAX;
    if ((bits & CF_C_D2_H) && o->D2_over_H_max < CF_FIT_D2_OVER_H_MAX_LIMIT)
        out->D2_over_H_max = CF_FIT_D2_OVER_H_MAX_LIMIT, done |= CF_C_D2_H;
    return done;
}
