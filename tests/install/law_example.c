/*
** A user's program against an installed libconifit (tests/install/run.sh builds it with
** pkg-config, shared and static): the force of one spring at the displacements given as
** arguments, one "u F" line each, then the same forces through the batch call. Exit 1 with the
** library's message if the spring is refused.
*/
#include <stdio.h>
#include <stdlib.h>

#include <conifit/law.h>
#include <conifit/version.h>

int main(int argc, char **argv)
{
    cf_spring p = {.D1_mm = 4, .D2_mm = 12, .n = 5, .d_mm = 0.8, .G_MPa = 80000, .H_mm = 10};
    cf_error err = {0};
    cf_law *law = cf_law_create(&p, &err);
    if (!law) {
        fprintf(stderr, "law_example: %s\n", err.msg);
        return 1;
    }
    int n = argc - 1;
    double *u = malloc((size_t)(n > 0 ? n : 1) * sizeof *u);
    double *F = malloc((size_t)(n > 0 ? n : 1) * sizeof *F);
    if (!u || !F)
        return 1;
    for (int i = 0; i < n; i++) {
        u[i] = strtod(argv[i + 1], NULL);
        printf("%s %.17g\n", argv[i + 1], cf_law_force(law, CF_LAW_CLOSED, u[i], NULL, NULL));
    }
    cf_law_force_many(law, CF_LAW_CLOSED, (size_t)n, u, F, NULL);
    for (int i = 0; i < n; i++)
        printf("many %s %.17g\n", argv[i + 1], F[i]);
    printf("version %s\n", CF_VERSION);
    cf_law_destroy(law);
    free(u);
    free(F);
    return 0;
}
