/*
** Numbers and table rows as CalculiX and Abaqus read them (export_model.h): shared by the models'
** writer (export_inp.c) and the body's nodal volume term (export_inp_volume.c).
*/
#include "export/export_model.h"

#include <string.h>

/* A real for CalculiX/Abaqus input: at most 20 characters (ccx reads a number from a field of
** 20 characters), always with a decimal point, with as many significant digits as fit (17, or 14
** for a negative number with an exponent). */
void cf_export_inp_real(char buf[32], double x)
{
    if (x == 0.0)
        x = 0.0; /* no "-0" */
    for (int p = 17; p >= 8; p--) {
        char t[40];
        snprintf(t, sizeof t, "%.*g", p, x);
        char *e = strpbrk(t, "eE");
        if (!strchr(t, '.')) { /* 40 -> 40.  1e-05 -> 1.e-05 */
            char tail[40];
            snprintf(tail, sizeof tail, "%s", e ? e : "");
            if (e)
                *e = '\0';
            strcat(t, ".");
            strcat(t, tail);
        }
        if (strlen(t) <= 20) {
            memcpy(buf, t, strlen(t) + 1);
            return;
        }
    }
    snprintf(buf, 32, "%.8e", x);
}

void cf_export_inp_pair(FILE *out, double force_N, double elongation_mm)
{
    char a[32], b[32];
    cf_export_inp_real(a, force_N);
    cf_export_inp_real(b, elongation_mm);
    fprintf(out, "%s, %s\n", a, b);
}
