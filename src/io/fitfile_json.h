/*
** The one writer of conifit's spring JSON (private to the library): the fit file of
** `conifit fit -o` (report/report.c) and the single exported spring of `conifit export --format json`
** (report/export.c) both build their spring objects and write their documents here, so that
** cf_fitfile_load (fitfile.h) reads back exactly what was written.
*/
#ifndef CF_IO_FITFILE_JSON_H
#define CF_IO_FITFILE_JSON_H

#include <stdio.h>

#include <jansson.h>

#include "conifit/error.h"
#include "model/law_internal.h"
#include "conifit/output.h"

/* A JSON number, or null for a value that is not finite; a document holding a null is never
** written (cf_fitfile_dumps and cf_fitfile_prepare refuse it), so NaN and Inf never reach a file:
** a key without a value is left out, with a reason beside it. */
json_t *cf_json_number(double v);

/* jansson's reason for a document it could not parse, without the text it quotes from the file
** ("... near 'TOKEN'"): a scene or fit path may name any readable file, and a message must not
** show what that file holds; the line and column say where. Into out (cap bytes); returns out. */
const char *cf_json_reason(const json_error_t *e, char *out, size_t cap);

/* 1 when the document holds a null anywhere; path (capacity cap) then names its key
** ("fits[0].identifiable.rho.stderr"). */
int cf_json_find_null(const json_t *root, char *path, size_t cap);

/* {"type", "params" {D1_mm ...}, "derived" {rho, travel_mm, ...}} of a spring prepared by
** cf_law_init (keys from the spring description, spring.h). NULL when memory runs out. */
json_t *cf_fitfile_spring_json(const cf_law *law);

/* The document as text: two-space indent, doubles to 17 significant digits, a final newline.
** malloc'd; NULL when memory runs out or the document holds a null (cf_json_find_null). */
char *cf_fitfile_dumps(const json_t *root);

/* Writes the document to a temporary file beside path, complete but not in place: the caller
** commits it (cf_atomic_commit) with its other outputs, or aborts it. `inputs` (NULL-terminated,
** may be NULL) are refused as targets. CF_E_CANTWRITE (or CF_E_INTERNAL when memory runs out or
** the document holds a value that is not a finite number) on failure, no file left behind. */
cf_status cf_fitfile_prepare(const json_t *root, const char *path, const char *const *inputs,
                             cf_output *out, cf_error *err);

#endif
