/*
** What every stage of the table reader shares (io/reader.h): its out-of-memory refusal and the
** split of a line into fields with the line and column of a quoting error. Below the header
** (header.c), the units row (unitsrow.c) and the reader itself (measure.c), which all call it.
*/
#include "io/reader.h"

cf_status cf_reader_out_of_memory(cf_error *err, const char *path)
{
    return cf_error_set(err, CF_E_INTERNAL, "%s: out of memory reading the table", path);
}

cf_status cf_reader_split(reader *r, const cf_csv_line *l, size_t n, char delim, cf_error *err)
{
    size_t bad = 0;
    const char *why = NULL;
    int rc = cf_csv_split(l->s, n, delim, &r->f, &bad, &why);
    if (rc == -2)
        return cf_reader_out_of_memory(err, r->path);
    if (rc == -1) {
        char q[256];
        cf_csv_quote(q, sizeof q, l->s, n);
        return cf_csv_error(err, r->path, l->line, bad, "%s ('%s')", why, q);
    }
    return CF_OK;
}
