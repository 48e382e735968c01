/*
** The reader's notes on a table in the text report and the fit file (report_notes.h).
*/
#include <string.h>

#include "base/safetext.h"
#include "report/report_notes.h"

/* The next non-empty note from *at (cf_table.notes holds one a line) in safe text into out;
** returns 0 when none is left. */
static int next_note(const char **at, char *out, size_t cap)
{
    while (**at) {
        const char *line = *at, *nl = strchr(line, '\n');
        size_t n = nl ? (size_t)(nl - line) : strlen(line);
        *at = line + n + (nl != NULL);
        if (n > 0) {
            cf_safe_text(out, cap, line, n);
            return 1;
        }
    }
    return 0;
}

void cf_report_notes_text(FILE *o, const cf_table *t, const char *indent)
{
    char note[4 * sizeof t->notes];
    for (const char *at = t->notes; next_note(&at, note, sizeof note);)
        fprintf(o, "%snote: %s\n", indent, note);
}

void cf_report_notes_json(json_t *obj, const cf_table *t)
{
    char note[4 * sizeof t->notes];
    json_t *a = NULL;
    for (const char *at = t->notes; obj && next_note(&at, note, sizeof note);) {
        if (!a)
            a = json_array();
        json_array_append_new(a, json_string(note));
    }
    if (a)
        json_object_set_new(obj, "notes", a);
}
