/*
** Text from outside (file names, column names, values, another program's output) made safe to
** show in a message: what it says stays readable, and nothing in it can act on a terminal.
**
** Kept as they are: printable ASCII and whole, valid UTF-8 sequences of printable characters.
** Shown as \xNN, byte by byte: C0 control characters (newline, tab and ESC included), DEL, the C1
** controls U+0080..U+009F in UTF-8 (some terminals take U+009B as a command introducer), and any
** byte that is not part of valid UTF-8 (a Windows code page's degree sign, say). The result is
** never cut inside a character or an escape.
*/
#ifndef CF_SAFETEXT_H
#define CF_SAFETEXT_H

#include <stddef.h>

/* Length of the valid UTF-8 sequence of one printable character at s (n bytes left): 1 to 4, or 0
** when the byte at s does not start one (a control character, DEL, a C1 control, a stray or overlong
** byte, a surrogate, a sequence cut short). */
size_t cf_text_char_length(const unsigned char *s, size_t n);

/* Writes the safe form of the n bytes at s into out (cap bytes, NUL-terminated; cap >= 1), ending
** with "..." when it did not fit. Returns out. */
char *cf_safe_text(char *out, size_t cap, const char *s, size_t n);

#endif
