/*
** The lexer of measurement tables, private to the table reader (io/measure.c, io/columns.c,
** io/measures.c): lines of text, fields split at a delimiter with double quotes, '#' comments,
** numbers in a cell, and messages "PATH:LINE:COL: what is wrong" with the offending text quoted
** printably. Columns count fields from 1; where a line holds bytes that are not text, they count
** bytes.
*/
#ifndef CF_IO_CSV_H
#define CF_IO_CSV_H

#include <stddef.h>

#include "conifit/error.h"

/* One line of the text, as a span of it. */
typedef struct cf_csv_line {
    const char *s;
    size_t n;    /* without the line end (and without a CR before it) */
    size_t line; /* 1-based */
} cf_csv_line;

/* The fields of one row, unquoted, each NUL-terminated inside buf. */
typedef struct cf_csv_fields {
    char *buf;
    size_t buf_cap;
    size_t *off;
    size_t count, cap;
} cf_csv_fields;

/* Field i of f. */
static inline const char *cf_csv_field(const cf_csv_fields *f, size_t i)
{
    return f->buf + f->off[i];
}

/* What a cell holds, for cf_csv_number. */
typedef enum cf_csv_num {
    CF_CSV_NUM_OK,
    CF_CSV_NUM_EMPTY,
    CF_CSV_NUM_NOT_NUMBER,
    CF_CSV_NUM_NOT_FINITE
} cf_csv_num;

/* Copies text into out as a short quotation for a message: at most its first 60 bytes, cut
** between characters and ending in "..." when cut, made safe as every message is (control
** characters and bytes that are not UTF-8 as \xNN: base/safetext.h). */
void cf_csv_quote(char *out, size_t cap, const char *s, size_t n);

/* CF_E_DATA with "PATH:LINE:COL: message". */
cf_status cf_csv_error(cf_error *err, const char *path, size_t line, size_t col, const char *fmt,
                       ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;

/* Releases the buffers of f (safe on a zeroed struct). */
void cf_csv_fields_free(cf_csv_fields *f);

/* Length of the line's content: up to a '#' outside double quotes (a comment), trailing
** blanks removed. */
size_t cf_csv_content_length(const char *s, size_t n);

/* Splits s[0..n) at delim into f (delim ' ': at runs of blanks and TABs, a field that opens with
** '[' or '(' joined to the one before, so that "stress [kPa]" stays one name). Returns 0, or -1 on
** a quoting error (with *bad_col the field's column, from 1, and *why the reason), or -2 when
** memory runs out. */
int cf_csv_split(const char *s, size_t n, char delim, cf_csv_fields *f, size_t *bad_col,
                 const char **why);

/* Checks a line for bytes that do not belong in a text table: NUL, control characters other than
** TAB, a CR that does not end the line, and malformed UTF-8. Returns the byte offset of the first
** bad byte, or n when the line is text. */
size_t cf_csv_bad_byte(const unsigned char *s, size_t n);

/* Copies src into dst (cap bytes with the NUL) as valid UTF-8 without control characters, for
** names that end up in reports and JSON: a byte that does not start a valid character (a file
** name in another encoding) or is a control character becomes '?', and a name too long is cut at
** a character boundary, never inside one. */
void cf_csv_utf8_copy(char *dst, size_t cap, const char *src);

/* Parses a cell as a finite decimal number ('.' decimal point; a single ',' is taken as the
** decimal point when the delimiter is not a comma). */
cf_csv_num cf_csv_number(const char *text, char delim, double *out);

/* Copies s[0..n) into out (cap bytes with the NUL) without leading and trailing white space,
** cut to fit. */
void cf_csv_trim_copy(char *out, size_t cap, const char *s, size_t n);

/* 1 when the line's first character other than blanks and TABs is '#'. */
int cf_csv_is_comment(const cf_csv_line *l);

/* The delimiter of a header line: the most frequent of TAB, ';' and ',' outside double quotes (a
** tie goes to ',', then to ';'); when there is none of them, ' ' (fields separated by blanks) if
** the line holds at least two words, not counting a word that opens with '[' or '(', else 0. */
char cf_csv_delimiter(const char *s, size_t n);

#endif
