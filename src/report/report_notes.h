/*
** The reader's notes on a table (cf_table.notes: a skipped preamble, units read from a units row
** or in another letter case, a strain column that looks like stretch) as the reports keep them:
** lines in the text report's header block and notes[] in the fit file. Private to src/report/.
*/
#ifndef CF_REPORT_NOTES_H
#define CF_REPORT_NOTES_H

#include <stdio.h>

#include <jansson.h>

#include "model/table.h"

/* Writes each note of t as one line "INDENT note: TEXT" (safe text); nothing when none. */
void cf_report_notes_text(FILE *o, const cf_table *t, const char *indent);

/* Sets obj's "notes" to the array of t's notes (safe text, none empty); leaves obj without the
** key when t has none. */
void cf_report_notes_json(json_t *obj, const cf_table *t);

#endif
