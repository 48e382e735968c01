/*
** Column names and units of a measurement table (columns.h).
*/
#include "io/columns.h"
#include "model/mode.h"

#include "io/measures.h"

#include <ctype.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

/* ---- units -------------------------------------------------------------------------------- */

/* 1 mmHg = 133.322387415 Pa (conventional millimetre of mercury). */
static const cf_unit_def units[] = {
    {"Pa", CF_UNIT_STRESS, 1e-6, "Pa"},
    {"kPa", CF_UNIT_STRESS, 1e-3, "kPa"},
    {"KPa", CF_UNIT_STRESS, 1e-3, "kPa"},
    {"MPa", CF_UNIT_STRESS, 1.0, "MPa"},
    {"GPa", CF_UNIT_STRESS, 1e3, "GPa"},
    {"N/mm2", CF_UNIT_STRESS, 1.0, "N/mm2"},
    {"N/mm^2", CF_UNIT_STRESS, 1.0, "N/mm2"},
    {"N/mm\xc2\xb2", CF_UNIT_STRESS, 1.0, "N/mm2"},
    {"N/m2", CF_UNIT_STRESS, 1e-6, "N/m2"},
    {"N/m^2", CF_UNIT_STRESS, 1e-6, "N/m2"},
    {"N/m\xc2\xb2", CF_UNIT_STRESS, 1e-6, "N/m2"},
    {"mmHg", CF_UNIT_STRESS, 133.322387415e-6, "mmHg"},
    {"N", CF_UNIT_FORCE, 1.0, "N"},
    {"mN", CF_UNIT_FORCE, 1e-3, "mN"},
    {"kN", CF_UNIT_FORCE, 1e3, "kN"},
    {"uN", CF_UNIT_FORCE, 1e-6, "uN"},
    {"\xc2\xb5N", CF_UNIT_FORCE, 1e-6, "uN"}, /* micro sign */
    {"\xce\xbcN", CF_UNIT_FORCE, 1e-6, "uN"}, /* Greek mu */
    {"m", CF_UNIT_LENGTH, 1e3, "m"},
    {"cm", CF_UNIT_LENGTH, 10.0, "cm"},
    {"mm", CF_UNIT_LENGTH, 1.0, "mm"},
    {"um", CF_UNIT_LENGTH, 1e-3, "um"},
    {"\xc2\xb5m", CF_UNIT_LENGTH, 1e-3, "um"},
    {"\xce\xbcm", CF_UNIT_LENGTH, 1e-3, "um"},
    {"s", CF_UNIT_TIME, 1.0, "s"},
    {"sec", CF_UNIT_TIME, 1.0, "s"},
    {"ms", CF_UNIT_TIME, 1e-3, "ms"},
    {"min", CF_UNIT_TIME, 60.0, "min"},
    {"h", CF_UNIT_TIME, 3600.0, "h"},
    {"-", CF_UNIT_STRAIN, 1.0, "-"},
    {"1", CF_UNIT_STRAIN, 1.0, "-"},
    {"mm/mm", CF_UNIT_STRAIN, 1.0, "-"},
    {"m/m", CF_UNIT_STRAIN, 1.0, "-"},
    {"in/in", CF_UNIT_STRAIN, 1.0, "-"},
    {"%", CF_UNIT_STRAIN, 0.01, "%"},
    {"percent", CF_UNIT_STRAIN, 0.01, "%"},
    {"pct", CF_UNIT_STRAIN, 0.01, "%"},
};

/* Letter case is ignored in a unit ("Mpa", "MPA", "kpa", "n"), except for a leading m or M: SI
** reads m as milli (or metre) and M as mega, so "mPa" is never MPa and "MN" never mN. */
static int same_unit(const char *spelled, const char *name)
{
    if ((spelled[0] == 'm' || spelled[0] == 'M' || name[0] == 'm' || name[0] == 'M') &&
        spelled[0] != name[0])
        return 0;
    return strcasecmp(spelled, name) == 0;
}

const cf_unit_def *cf_unit_find(const char *name)
{
    for (size_t i = 0; i < sizeof units / sizeof units[0]; i++)
        if (strcmp(units[i].name, name) == 0)
            return &units[i];
    for (size_t i = 0; i < sizeof units / sizeof units[0]; i++)
        if (same_unit(name, units[i].name))
            return &units[i];
    return NULL;
}

const cf_unit_def *cf_unit_m_case(const char *name)
{
    for (size_t i = 0; i < sizeof units / sizeof units[0]; i++)
        if (strcasecmp(units[i].name, name) == 0 && !same_unit(name, units[i].name))
            return &units[i];
    return NULL;
}

/* True when name equals a known unit up to letter case ("kpa", "n"): a unit written wrongly. */
static int unit_like(const char *name)
{
    for (size_t i = 0; i < sizeof units / sizeof units[0]; i++)
        if (strcasecmp(units[i].name, name) == 0)
            return 1;
    return 0;
}

cf_unit_class cf_measure_unit(const char *name, double *to_conifit)
{
    const cf_unit_def *u = name ? cf_unit_find(name) : NULL;
    if (!u)
        return CF_UNIT_UNKNOWN;
    if (to_conifit)
        *to_conifit = u->to_conifit;
    return u->cls;
}

const char cf_unit_list[] =
    "stress: Pa kPa MPa GPa N/mm2 N/m2 mmHg; force: N mN kN uN; length: m cm mm um; "
    "time: s sec ms min h; strain: - mm/mm in/in m/m % percent";

/* ---- column names ------------------------------------------------------------------------- */

void cf_column_parse(cf_column *c, const char *name)
{
    snprintf(c->name, sizeof c->name, "%s", name);
    size_t n = strlen(name);
    c->unit[0] = '\0';
    if (n > 0 && (name[n - 1] == ']' || name[n - 1] == ')')) {
        char open = name[n - 1] == ']' ? '[' : '(';
        const char *o = strrchr(name, open);
        if (o && o > name) {
            cf_csv_trim_copy(c->base, sizeof c->base, name, (size_t)(o - name));
            cf_csv_trim_copy(c->unit, sizeof c->unit, o + 1, (size_t)(name + n - 1 - (o + 1)));
            if (c->base[0])
                return;
        }
    }
    const char *us = strrchr(name, '_');
    if (us && us > name && us[1] && (cf_unit_find(us + 1) || unit_like(us + 1))) {
        cf_csv_trim_copy(c->base, sizeof c->base, name, (size_t)(us - name));
        snprintf(c->unit, sizeof c->unit, "%s", us + 1);
        return;
    }
    cf_csv_trim_copy(c->base, sizeof c->base, name, n);
    c->unit[0] = '\0';
}

static int starts_with_ci(const char *s, const char *prefix)
{
    return strncasecmp(s, prefix, strlen(prefix)) == 0;
}

int cf_column_is_x(const char *b)
{
    static const char *const p[] = {"strain", "stretch", "lambda", "displacement", "elongation",
                                    "gamma", "shear", "log_strain", "true_strain", "hencky",
                                    "\xce\xbb" /* the Greek letter lambda */};
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++)
        if (starts_with_ci(b, p[i]))
            return 1;
    return 0;
}

cf_unit_class cf_column_y_class(const char *b)
{
    if (cf_measures_contains_ci(b, "stress") || starts_with_ci(b, "cauchy"))
        return CF_UNIT_STRESS;
    if (starts_with_ci(b, "load") || cf_measures_contains_ci(b, "force"))
        return CF_UNIT_FORCE;
    return CF_UNIT_UNKNOWN;
}

int cf_column_is_y(const char *b)
{
    return starts_with_ci(b, "stress") || starts_with_ci(b, "force") || starts_with_ci(b, "load") ||
           starts_with_ci(b, "cauchy") || starts_with_ci(b, "true_stress");
}

int cf_column_is_weight(const char *b)
{
    return strcasecmp(b, "weight") == 0 || strcasecmp(b, "weights") == 0;
}

int cf_column_is_time(const char *b)
{
    return strcasecmp(b, "time") == 0 || strcasecmp(b, "t") == 0;
}

/* ---- units stated in '#' comments --------------------------------------------------------- */

static int word_char(char c)
{
    return isalnum((unsigned char)c) || c == '_';
}

/* Does u (a bracket's content or a bare word) name a unit of one of the wanted classes? */
static const cf_unit_def *wanted_unit(const char *u, const cf_unit_class *want, size_t nwant)
{
    const cf_unit_def *d = cf_unit_find(u);
    for (size_t k = 0; d && k < nwant; k++)
        if (d->cls == want[k])
            return d;
    return NULL;
}

/* Looks in one comment for the column name as a word followed, in the same clause (up to ',' or
** ';' or an unmatched closing bracket), by a bracketed unit of a wanted class:
** "stress = nominal stress [kPa]", "displacement [mm]". Linear in the comment's length: a scan
** that fails resumes where it stopped (a later mention of the name in the same clause would see
** only part of what this one saw), and a bracket is searched for its closing one no further than
** the longest unit name. */
static const cf_unit_def *comment_unit_after_name(const char *s, size_t n, const char *name,
                                                  const cf_unit_class *want, size_t nwant)
{
    size_t len = strlen(name);
    if (len == 0)
        return NULL;
    size_t i = 0;
    while (i + len <= n) {
        if ((i > 0 && word_char(s[i - 1])) || strncasecmp(s + i, name, len) != 0 ||
            (i + len < n && word_char(s[i + len]))) {
            i++;
            continue;
        }
        size_t j = i + len;
        for (; j < n; j++) {
            char c = s[j];
            if (c == ',' || c == ';' || c == ')' || c == ']')
                break;
            if (c == '[' || c == '(') {
                char close = c == '[' ? ']' : ')';
                size_t room = n - j - 1 < CF_COLUMN_NAME_CAP ? n - j - 1 : CF_COLUMN_NAME_CAP;
                const char *e = memchr(s + j + 1, close, room);
                if (!e)
                    break;
                char u[CF_COLUMN_NAME_CAP];
                cf_csv_trim_copy(u, sizeof u, s + j + 1, (size_t)(e - (s + j + 1)));
                const cf_unit_def *d = wanted_unit(u, want, nwant);
                if (d)
                    return d;
                j = (size_t)(e - s);
            }
        }
        i = j > i ? j : i + 1;
    }
    return NULL;
}

/* "... (x, y): strain, MPa" or "(x, y) = mm, mN": units listed for x and y in that order. */
static const cf_unit_def *comment_unit_xy(const char *s, size_t n, int which,
                                          const cf_unit_class *want, size_t nwant)
{
    static const char key[] = "(x, y)";
    const size_t klen = sizeof key - 1;
    for (size_t i = 0; i + klen <= n; i++) {
        if (strncasecmp(s + i, key, klen) != 0)
            continue;
        size_t j = i + klen;
        while (j < n && (s[j] == ' ' || s[j] == ':' || s[j] == '=' || s[j] == '\t'))
            j++;
        for (int k = 0; k <= which && j < n; k++) {
            size_t start = j;
            while (j < n && s[j] != ',' && s[j] != ';')
                j++;
            if (k == which) {
                char tok[CF_COLUMN_NAME_CAP];
                cf_csv_trim_copy(tok, sizeof tok, s + start, j - start);
                /* the token may be "kPa" or "stress kPa" or "[kPa]": try its last word */
                char *w = tok + strlen(tok);
                while (w > tok && !isspace((unsigned char)w[-1]))
                    w--;
                while (*w == '[' || *w == '(')
                    w++;
                size_t wl = strlen(w);
                while (wl > 0 && (w[wl - 1] == ']' || w[wl - 1] == ')' || w[wl - 1] == '.'))
                    w[--wl] = '\0';
                return wanted_unit(w, want, nwant);
            }
            j++;
        }
    }
    return NULL;
}

const cf_unit_def *cf_comment_unit(const cf_csv_line *comments, size_t ncomments,
                                   const char *name, int which, const cf_unit_class *want,
                                   size_t nwant)
{
    for (size_t i = 0; i < ncomments; i++) {
        const cf_unit_def *d =
            comment_unit_after_name(comments[i].s, comments[i].n, name, want, nwant);
        if (d)
            return d;
    }
    for (size_t i = 0; i < ncomments; i++) {
        const cf_unit_def *d = comment_unit_xy(comments[i].s, comments[i].n, which, want, nwant);
        if (d)
            return d;
    }
    return NULL;
}

/* ---- the test mode stated in a '# mode: NAME' comment --------------------------------------- */

cf_status cf_comment_mode(const cf_csv_line *comments, size_t ncomments, const char *path,
                          cf_mode *mode, int *found, cf_error *err)
{
    *found = 0;
    for (size_t i = 0; i < ncomments; i++) {
        const char *s = comments[i].s, *end = s + comments[i].n;
        while (s < end && isspace((unsigned char)*s))
            s++;
        if ((size_t)(end - s) < 5 || strncmp(s, "mode:", 5) != 0)
            continue;
        s += 5;
        while (s < end && isspace((unsigned char)*s))
            s++;
        const char *w = s;
        while (s < end && !isspace((unsigned char)*s) && *s != ',' && *s != ';')
            s++;
        char name[32];
        snprintf(name, sizeof name, "%.*s", (int)(s - w), w);
        if (cf_mode_parse(name, mode, NULL) != CF_OK)
            return cf_csv_error(err, path, comments[i].line, 1,
                                "comment 'mode: %s': expected %s ('%s')", name, cf_mode_list(),
                                name);
        *found = 1;
        return CF_OK;
    }
    return CF_OK;
}

