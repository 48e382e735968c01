/*
** Stress and strain measures and test modes of a table (measures.h). The conversions follow from
** the deformation gradient of each test under incompressibility (J = 1): with F = diag(l1, l2, l3)
** and the load along 1, the nominal stress is P = J sigma F^-T, so P11 = sigma11 / l1 whatever the
** lateral stretches (uniaxial, planar, equibiaxial); simple shear F = I + gamma e1 (x) e2 leaves
** the sheared face's area unchanged, P12 = sigma12; confined compression holds l2 = l3 = 1, so
** J = l1 and P11 = sigma11. Log strain e gives the stretch exp(e), engineering strain exp(e) - 1.
*/
#include "io/measures.h"
#include "model/mode.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

/* What a declaration declares. */
enum { CF_DECL_STRESS = 0, CF_DECL_STRAIN = 1, CF_DECL_KINDS = 2 };

/* Names of the values of each kind, in the order of their enums. */
static const char *const cf_measures_names[CF_DECL_KINDS][3] = {{"nominal", "cauchy"},
                                                          {"engineering", "log", "stretch"}};

const char *cf_stress_measure_name(cf_stress_measure m)
{
    return (unsigned)m < 2 ? cf_measures_names[CF_DECL_STRESS][m] : "?";
}

const char *cf_strain_measure_name(cf_strain_measure m)
{
    return (unsigned)m < 3 ? cf_measures_names[CF_DECL_STRAIN][m] : "?";
}

const char *cf_decl_source_name(cf_decl_source s)
{
    static const char *const n[] = {"assumed", "comment", "column name", "option"};
    return (unsigned)s < 4 ? n[s] : "?";
}

typedef struct synonym {
    const char *word;
    int value;
} synonym;

static int lookup(const synonym *t, size_t n, const char *word)
{
    for (size_t i = 0; i < n; i++)
        if (strcasecmp(word, t[i].word) == 0)
            return t[i].value;
    return -1;
}

int cf_stress_measure_parse(const char *word, cf_stress_measure *m)
{
    static const synonym t[] = {{"nominal", CF_STRESS_NOMINAL},
                                {"engineering", CF_STRESS_NOMINAL},
                                {"pk1", CF_STRESS_NOMINAL},
                                {"piola", CF_STRESS_NOMINAL},
                                {"first-piola-kirchhoff", CF_STRESS_NOMINAL},
                                {"cauchy", CF_STRESS_CAUCHY},
                                {"true", CF_STRESS_CAUCHY}};
    int v = lookup(t, sizeof t / sizeof t[0], word);
    if (v >= 0)
        *m = (cf_stress_measure)v;
    return v >= 0 ? 0 : -1;
}

int cf_strain_measure_parse(const char *word, cf_strain_measure *m)
{
    static const synonym t[] = {{"engineering", CF_STRAIN_ENGINEERING},
                                {"nominal", CF_STRAIN_ENGINEERING},
                                {"log", CF_STRAIN_LOG},
                                {"logarithmic", CF_STRAIN_LOG},
                                {"true", CF_STRAIN_LOG},
                                {"hencky", CF_STRAIN_LOG},
                                {"stretch", CF_STRAIN_STRETCH},
                                {"lambda", CF_STRAIN_STRETCH}};
    int v = lookup(t, sizeof t / sizeof t[0], word);
    if (v >= 0)
        *m = (cf_strain_measure)v;
    return v >= 0 ? 0 : -1;
}

/* One comment line (without its '#'): 1 when it is a declaration "stress: WORD" or "strain: WORD"
** (key case-insensitive, at the start of the comment), with *kind and the word copied to word
** (at most cap - 1 characters); 0 otherwise. (The '# mode:' comment is read with the mode.) */
static int cf_measures_declaration(const char *s, size_t n, int *kind, char *word, size_t cap)
{
    static const char *const keys[CF_DECL_KINDS] = {"stress:", "strain:"};
    size_t i = 0;
    while (i < n && (s[i] == ' ' || s[i] == '\t'))
        i++;
    for (int k = 0; k < CF_DECL_KINDS; k++) {
        size_t kl = strlen(keys[k]);
        if (n - i < kl || strncasecmp(s + i, keys[k], kl) != 0)
            continue;
        size_t j = i + kl;
        while (j < n && (s[j] == ' ' || s[j] == '\t'))
            j++;
        size_t w = 0;
        while (j < n && w + 1 < cap && (isalnum((unsigned char)s[j]) || s[j] == '-' || s[j] == '_'))
            word[w++] = s[j++];
        word[w] = '\0';
        *kind = k;
        return 1;
    }
    return 0;
}

int cf_measures_contains_ci(const char *s, const char *word)
{
    size_t n = strlen(word);
    for (; *s; s++)
        if (strncasecmp(s, word, n) == 0)
            return 1;
    return 0;
}

/* The measure a column's name states, or -1: y names true_stress, cauchy..., nominal_stress,
** pk1...; x names log_strain, true_strain, hencky..., stretch, lambda (or the letter),
** engineering_strain. */
static int cf_measures_stress_of_column(const char *name)
{
    static const char *const cauchy[] = {"cauchy", "true_stress", "true stress", "truestress"};
    static const char *const nominal[] = {"nominal", "engineering", "pk1", "piola"};
    for (int k = 0; k < 4; k++)
        if (cf_measures_contains_ci(name, cauchy[k]))
            return CF_STRESS_CAUCHY;
    for (int k = 0; k < 4; k++)
        if (cf_measures_contains_ci(name, nominal[k]))
            return CF_STRESS_NOMINAL;
    return -1;
}

static int cf_measures_strain_of_column(const char *name)
{
    static const char *const logs[] = {"log", "true_strain", "true strain", "hencky"};
    for (int k = 0; k < 4; k++)
        if (cf_measures_contains_ci(name, logs[k]))
            return CF_STRAIN_LOG;
    if (strncasecmp(name, "stretch", 7) == 0 || strncasecmp(name, "lambda", 6) == 0 ||
        strncmp(name, "\xce\xbb", 2) == 0) /* a Greek small lambda */
        return CF_STRAIN_STRETCH;
    if (cf_measures_contains_ci(name, "engineering") || cf_measures_contains_ci(name, "nominal"))
        return CF_STRAIN_ENGINEERING;
    return -1;
}

/* What the file says about one quantity: from a declaration (line > 0) and/or a column (-1: it
** says nothing). */
typedef struct cf_measures_said {
    int declared;       /* value of the declaration, -1: none */
    size_t line;        /* its line */
    int column;         /* value stated by the column's name, -1: none */
} cf_measures_said;

/* Decides one quantity: the option (>= 0) wins over the file; a declaration and a column name
** that disagree are an error (CF_E_DATA naming the file, the line and the column); nothing said
** gives fallback, marked assumed. `what` names the quantity in messages ("stress measure"),
** names[] the values. */
static cf_status cf_measures_decide(const char *path, const char *column, const char *what,
                                    const char *const *names, int option,
                                    const cf_measures_said *said, int fallback, int *value,
                                    cf_decl_source *from, size_t *line, int *overridden,
                                    int *file_value, cf_error *err)
{
    *line = said->declared >= 0 ? said->line : 0;
    *overridden = 0;
    if (said->declared >= 0 && said->column >= 0 && said->declared != said->column && option < 0)
        return cf_error_set(err, CF_E_DATA,
                            "%s:%zu: the %s is declared '%s' but column '%s' is named for '%s' "
                            "(say which holds, or rename the column) ('%s')",
                            path, said->line, what, names[said->declared], column,
                            names[said->column], names[said->declared]);
    int file = said->declared >= 0 ? said->declared : said->column;
    *file_value = file;
    if (option >= 0) {
        *value = option;
        *from = CF_DECL_OPTION;
        *overridden = file >= 0 && file != option;
        return CF_OK;
    }
    if (said->declared >= 0) {
        *value = said->declared;
        *from = CF_DECL_COMMENT;
    } else if (said->column >= 0) {
        *value = said->column;
        *from = CF_DECL_COLUMN;
    } else {
        *value = fallback;
        *from = CF_DECL_ASSUMED;
    }
    return CF_OK;
}

cf_status cf_measures_read(const cf_csv_line *comments, size_t ncomments, const char *path,
                           const cf_measure_options *opt, const cf_column *xc, const cf_column *yc,
                           cf_table_measures *out, cf_error *err)
{
    static const char *const what[CF_DECL_KINDS] = {"stress measure", "strain measure"};
    static const char *const expect[CF_DECL_KINDS] = {"nominal or cauchy",
                                                      "engineering, log or stretch"};
    cf_measures_said said[CF_DECL_KINDS];
    for (int k = 0; k < CF_DECL_KINDS; k++)
        said[k] = (cf_measures_said){-1, 0, -1};
    for (size_t i = 0; i < ncomments; i++) {
        int kind, v = -1;
        char word[64];
        if (!cf_measures_declaration(comments[i].s, comments[i].n, &kind, word,
                                     sizeof word))
            continue;
        if (kind == CF_DECL_STRESS) {
            cf_stress_measure x;
            v = cf_stress_measure_parse(word, &x) == 0 ? (int)x : -1;
        } else {
            cf_strain_measure x;
            v = cf_strain_measure_parse(word, &x) == 0 ? (int)x : -1;
        }
        if (v < 0)
            return cf_csv_error(err, path, comments[i].line, 1,
                                "unknown %s (expected %s) ('%s')", what[kind], expect[kind], word);
        if (said[kind].declared >= 0 && said[kind].declared != v)
            return cf_csv_error(err, path, comments[i].line, 1,
                                "%s declared twice, differently (line %zu says otherwise) ('%s')",
                                what[kind], said[kind].line, word);
        said[kind].declared = v;
        said[kind].line = comments[i].line;
    }
    said[CF_DECL_STRESS].column = cf_measures_stress_of_column(yc->base);
    said[CF_DECL_STRAIN].column = cf_measures_strain_of_column(xc->base);
    int strain_opt = opt->strain_measure >= 0   ? opt->strain_measure
                     : opt->x_is_stretch == 1   ? CF_STRAIN_STRETCH
                     : opt->x_is_stretch == 0   ? CF_STRAIN_ENGINEERING
                                                : -1;
    const int option[CF_DECL_KINDS] = {opt->stress_measure, strain_opt};
    const char *col[CF_DECL_KINDS] = {yc->name, xc->name};
    int value[CF_DECL_KINDS], over[CF_DECL_KINDS], filev[CF_DECL_KINDS];
    cf_decl_source from[CF_DECL_KINDS];
    size_t line[CF_DECL_KINDS];
    for (int k = 0; k < CF_DECL_KINDS; k++) {
        cf_status st = cf_measures_decide(path, col[k], what[k], cf_measures_names[k], option[k],
                                          &said[k], 0, &value[k], &from[k], &line[k], &over[k],
                                          &filev[k], err);
        if (st != CF_OK)
            return st;
    }
    memset(out, 0, sizeof *out);
    out->stress = (cf_stress_measure)value[CF_DECL_STRESS];
    out->strain = (cf_strain_measure)value[CF_DECL_STRAIN];
    out->stress_from = from[CF_DECL_STRESS];
    out->strain_from = from[CF_DECL_STRAIN];
    out->stress_line = line[CF_DECL_STRESS];
    out->strain_line = line[CF_DECL_STRAIN];
    out->stress_overridden = over[CF_DECL_STRESS];
    out->strain_overridden = over[CF_DECL_STRAIN];
    out->stress_file = filev[CF_DECL_STRESS];
    out->strain_file = filev[CF_DECL_STRAIN];
    return CF_OK;
}

cf_status cf_measures_convert(cf_table *t, cf_error *err)
{
    cf_table_measures *m = &t->measures;
    const int shear = cf_mode_row_of(t->mode)->any_sign;
    if (t->kind == CF_TABLE_FORCE_DISPLACEMENT) {
        if (m->stress == CF_STRESS_CAUCHY)
            return cf_error_set(err, CF_E_DATA,
                                "%s: a Cauchy stress is declared, but the y column '%s' is a "
                                "force: only a stress has a measure ('cauchy')",
                                t->path, t->y_column);
        if (m->strain == CF_STRAIN_LOG)
            return cf_error_set(err, CF_E_DATA,
                                "%s: a log strain is declared, but the x column '%s' is a "
                                "displacement ('log')", t->path, t->x_column);
        return CF_OK;
    }
    if (shear && m->strain != CF_STRAIN_ENGINEERING)
        return cf_error_set(err, CF_E_DATA,
                            "%s: a simple-shear table is the amount of shear against the shear "
                            "stress; a %s strain has no meaning there ('%s')",
                            t->path, cf_strain_measure_name(m->strain),
                            cf_strain_measure_name(m->strain));
    if (m->strain == CF_STRAIN_LOG) {
        for (size_t i = 0; i < t->count; i++)
            t->x[i] = expm1(t->x[i]);
        m->strain_converted = 1;
    } else if (m->strain == CF_STRAIN_STRETCH) {
        m->strain_converted = 1; /* the reader took stretch - 1 */
    }
    /* a stretch must stay positive; simple shear's amount gamma is no stretch and takes either
    ** sign without bound */
    for (size_t i = 0; i < t->count; i++)
        if (!isfinite(t->x[i]) || (!shear && !(t->x[i] > -1)))
            return cf_error_set(err, CF_E_DATA,
                                "%s: data row %zu: strain %g is a stretch of %g; a stretch must "
                                "be positive ('%g')",
                                t->path, i + 1, t->x[i], 1 + t->x[i], t->x[i]);
    if (m->stress == CF_STRESS_CAUCHY) {
        if (cf_mode_row_of(t->mode)->cauchy_over_stretch)
            for (size_t i = 0; i < t->count; i++)
                t->y[i] /= 1 + t->x[i];
        m->stress_converted = 1;
    }
    return CF_OK;
}
