/*
** Hourglass control of the lattice's cells (see lattice_hourglass.h).
*/
#include "model/lattice_hourglass.h"

/* h_i(a) for corner a = di + 2 dj + 4 dk: xi eta, eta zeta, zeta xi, xi eta zeta. */
#define pattern cf_hourglass_pattern
int cf_hourglass_pattern(int i, int a)
{
    const int xi = 2 * (a & 1) - 1, eta = 2 * ((a >> 1) & 1) - 1, zeta = 2 * ((a >> 2) & 1) - 1;
    switch (i) {
    case 0:
        return xi * eta;
    case 1:
        return eta * zeta;
    case 2:
        return zeta * xi;
    default:
        return xi * eta * zeta;
    }
}

double cf_hourglass_coef(int a, int b)
{
    int s = 0;
    for (int i = 0; i < 4; i++)
        s += pattern(i, a) * pattern(i, b);
    return s / 64.0;
}

void cf_hourglass_modes(double x[8][3], double q[4][3])
{
    for (int i = 0; i < 4; i++)
        for (int c = 0; c < 3; c++) {
            double s = 0;
            for (int a = 0; a < 8; a++)
                s += pattern(i, a) * x[a][c];
            q[i][c] = s / 8.0;
        }
}

void cf_hourglass_forces(double q[4][3], double k_h, double f[8][3])
{
    for (int a = 0; a < 8; a++)
        for (int c = 0; c < 3; c++) {
            double s = 0;
            for (int i = 0; i < 4; i++)
                s += pattern(i, a) * q[i][c];
            f[a][c] = -k_h * s / 8.0;
        }
}

double cf_hourglass_stiffness(const double w[CF_FAMILY_COUNT], double kappa_MPa, double fraction,
                              const cf_law *law)
{
    const double f = fraction < 0 ? (kappa_MPa > 0 ? CF_HOURGLASS_DEFAULT : 0.0) : fraction;
    if (!(f > 0))
        return 0.0;
    const double k0c = law->k0_N_per_mm;
    const double k0e = law->extension ? law->extension->k0_N_per_mm : k0c;
    /* mu H = C44 (k0_c + k0_e) / 2, and k_h = 4 f mu H */
    return 2.0 * f * cf_cubic_moduli_of(w).C44 * (k0c + k0e);
}
