/*
** Text made safe to show in a message (see safetext.h).
*/
#include "base/safetext.h"

#include <stdio.h>
#include <string.h>

size_t cf_text_char_length(const unsigned char *s, size_t n)
{
    const unsigned c = s[0];
    if (c < 0x80)
        return c >= 0x20 && c != 0x7f;
    size_t len;
    unsigned cp;
    if (c >= 0xc2 && c <= 0xdf) {
        len = 2;
        cp = c & 0x1f;
    } else if (c >= 0xe0 && c <= 0xef) {
        len = 3;
        cp = c & 0x0f;
    } else if (c >= 0xf0 && c <= 0xf4) {
        len = 4;
        cp = c & 0x07;
    } else {
        return 0;
    }
    if (len > n)
        return 0;
    for (size_t i = 1; i < len; i++) {
        if ((s[i] & 0xc0) != 0x80)
            return 0;
        cp = cp << 6 | (s[i] & 0x3f);
    }
    const unsigned lowest[5] = {0, 0, 0x80, 0x800, 0x10000};
    if (cp < lowest[len] || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff) ||
        (cp >= 0x80 && cp <= 0x9f))
        return 0;
    return len;
}

/* The next piece of the safe form of s (n > 0 bytes left) into piece (8 bytes); its length, and
** in *used the input bytes it stands for. */
static size_t next_piece(const unsigned char *s, size_t n, char piece[8], size_t *used)
{
    size_t len = cf_text_char_length(s, n);
    if (len) {
        memcpy(piece, s, len);
        *used = len;
        return len;
    }
    snprintf(piece, 8, "\\x%02X", s[0]);
    *used = 1;
    return 4;
}

char *cf_safe_text(char *out, size_t cap, const char *s, size_t n)
{
    const unsigned char *u = (const unsigned char *)s;
    char piece[8];
    size_t used, total = 0;
    for (size_t i = 0; i < n && total < cap; i += used)
        total += next_piece(u + i, n - i, piece, &used);
    /* all of it when it fits, else whole pieces up to cap - 4 and "..." */
    const size_t room = total < cap ? cap - 1 : (cap > 4 ? cap - 4 : cap - 1);
    size_t o = 0;
    for (size_t i = 0; i < n; i += used) {
        size_t plen = next_piece(u + i, n - i, piece, &used);
        if (o + plen > room)
            break;
        memcpy(out + o, piece, plen);
        o += plen;
    }
    if (total >= cap && cap > 4) {
        memcpy(out + o, "...", 3);
        o += 3;
    }
    out[o] = '\0';
    return out;
}
