/*
** Opening input files: only regular files are read, and opening never blocks.
**
** A FIFO, socket or device named as an input would block the run forever (a FIFO with no writer)
** or feed it endless bytes (/dev/zero); a folder cannot be read. cf_input_open opens without
** blocking, looks at what the name is, and refuses anything but a regular file (a symbolic link
** to one is followed). Standard input ("-") is the caller's business.
*/
#ifndef CF_INPUT_H
#define CF_INPUT_H

#include <stdio.h>
#include <sys/types.h>

#include "conifit/error.h"

/* Opens path for reading ("rb"). NULL with CF_E_NOINPUT when it cannot be opened or is not a
** regular file; the message names the path, what it was to be read as (`what`, e.g. "scene") and
** what the path is ("a FIFO", "a folder", ...). */
FILE *cf_input_open(const char *path, const char *what, cf_error *err);

/* What a file of mode m is, for messages: "a symbolic link", "a FIFO", "a folder", ... */
const char *cf_file_kind(mode_t m);

#endif
