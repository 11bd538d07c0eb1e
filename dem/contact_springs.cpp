// Implicit contact-spring blocks (see contact_springs.h; docs/contact.md 2b, Eqs. C1-C3).
#include "contact_springs.h"

namespace fdm {
namespace contact {

namespace {

// K = kn n n^T + kt (I - n n^T)
void stiffness(const double n[3], double kn, double kt, double K[3][3])
{
  for (int a = 0; a < 3; a++)
    for (int b = 0; b < 3; b++) K[a][b] = (kn - kt) * n[a] * n[b] + (a == b ? kt : 0.0);
}

// [n]x: the matrix of w -> n x w
void cross(const double n[3], double C[3][3])
{
  C[0][0] = 0;     C[0][1] = -n[2]; C[0][2] = n[1];
  C[1][0] = n[2];  C[1][1] = 0;     C[1][2] = -n[0];
  C[2][0] = -n[1]; C[2][1] = n[0];  C[2][2] = 0;
}

// R = s B^T K B for B (3 x m, row-major)
void congruence(const double *B, int m, const double K[3][3], double s, double *R)
{
  double KB[3][12];
  for (int a = 0; a < 3; a++)
    for (int c = 0; c < m; c++) KB[a][c] = K[a][0] * B[c] + K[a][1] * B[m + c] + K[a][2] * B[2 * m + c];
  for (int r = 0; r < m; r++)
    for (int c = 0; c < m; c++)
      R[m * r + c] = s * (B[r] * KB[0][c] + B[m + r] * KB[1][c] + B[2 * m + r] * KB[2][c]);
  // exactly symmetric (the products above round differently in the two triangles)
  for (int r = 0; r < m; r++)
    for (int c = r + 1; c < m; c++) R[m * c + r] = R[m * r + c] = 0.5 * (R[m * r + c] + R[m * c + r]);
}

// kt [t t^T + (1 - keep)(I - n n^T - t t^T)] with kt = 1: the tangential spring's part that leaves
void slideStiffness(const double n[3], const double t[3], double keep, double K[3][3])
{
  for (int a = 0; a < 3; a++)
    for (int b = 0; b < 3; b++)
      K[a][b] = t[a] * t[b] + (1 - keep) * ((a == b ? 1.0 : 0.0) - n[a] * n[b] - t[a] * t[b]);
}

// s B^T K B of a pair (Eq. C1: v_r = U_i - U_j - (l_i Omega_i + l_j Omega_j) x n
// = U_i + l_i n x Omega_i - U_j + l_j n x Omega_j)
void pairBlock(const double n[3], double leverI, double leverJ, const double K[3][3], double s, double R[144])
{
  double C[3][3], B[36];
  cross(n, C);
  for (int a = 0; a < 3; a++)
    for (int b = 0; b < 3; b++) {
      B[12 * a + b] = a == b ? 1.0 : 0.0;
      B[12 * a + 3 + b] = leverI * C[a][b];
      B[12 * a + 6 + b] = a == b ? -1.0 : 0.0;
      B[12 * a + 9 + b] = leverJ * C[a][b];
    }
  congruence(B, 12, K, s, R);
}

// s B^T K B of a particle and a wall, and the wall-velocity term dt B^T K U_w (Eq. C2)
void wallBlock(const double n[3], double lever, const double K[3][3], double s, double dt, const double wallVelocity[3],
               double R[36], double wallTerm[6])
{
  double C[3][3], B[18];
  cross(n, C);
  for (int a = 0; a < 3; a++)
    for (int b = 0; b < 3; b++) {
      B[6 * a + b] = a == b ? 1.0 : 0.0;
      B[6 * a + 3 + b] = lever * C[a][b];
    }
  congruence(B, 6, K, s, R);
  double f[3];
  for (int a = 0; a < 3; a++) f[a] = dt * (K[a][0] * wallVelocity[0] + K[a][1] * wallVelocity[1] + K[a][2] * wallVelocity[2]);
  for (int r = 0; r < 6; r++) wallTerm[r] = B[r] * f[0] + B[6 + r] * f[1] + B[12 + r] * f[2];
}

}  // namespace

void pairSpringBlock(const double n[3], double leverI, double leverJ, double kn, double kt, double c1dt,
                     double R[144])
{
  double K[3][3];
  stiffness(n, kn, kt, K);
  pairBlock(n, leverI, leverJ, K, c1dt, R);
}

void wallSpringBlock(const double n[3], double lever, double kn, double kt, double c1dt, double dt,
                     const double wallVelocity[3], double R[36], double wallTerm[6])
{
  double K[3][3];
  stiffness(n, kn, kt, K);
  wallBlock(n, lever, K, c1dt, dt, wallVelocity, R, wallTerm);
}

void pairSlideBlock(const double n[3], double leverI, double leverJ, const double t[3], double keep, double ktc1dt,
                    double R[144])
{
  double K[3][3];
  slideStiffness(n, t, keep, K);
  pairBlock(n, leverI, leverJ, K, ktc1dt, R);
}

void wallSlideBlock(const double n[3], double lever, const double t[3], double keep, double ktc1dt, double ktdt,
                    const double wallVelocity[3], double R[36], double wallTerm[6])
{
  double K[3][3];
  slideStiffness(n, t, keep, K);
  wallBlock(n, lever, K, ktc1dt, ktdt, wallVelocity, R, wallTerm);
}

namespace {

// the tangential part (I - n n^T) of v
void tangential(const double n[3], double v[3])
{
  const double vn = v[0] * n[0] + v[1] * n[1] + v[2] * n[2];
  for (int a = 0; a < 3; a++) v[a] -= vn * n[a];
}

}  // namespace

void pairTangentialForceAtEnd(const double n[3], double leverI, double leverJ, double ktc1dt, const double ft[3],
                              const double uRel[12], double out[3])
{
  // B u (Eq. C1): U_i - U_j - (l_i Omega_i + l_j Omega_j) x n
  double w[3], slip[3];
  for (int a = 0; a < 3; a++) w[a] = leverI * uRel[3 + a] + leverJ * uRel[9 + a];
  const double wxn[3] = {w[1] * n[2] - w[2] * n[1], w[2] * n[0] - w[0] * n[2], w[0] * n[1] - w[1] * n[0]};
  for (int a = 0; a < 3; a++) slip[a] = uRel[a] - uRel[6 + a] - wxn[a];
  tangential(n, slip);
  for (int a = 0; a < 3; a++) out[a] = ft[a] - ktc1dt * slip[a];
}

void wallTangentialForceAtEnd(const double n[3], double lever, double ktc1dt, double ktdt, const double ft[3],
                              const double wallVelocity[3], const double uRel[6], double out[3])
{
  // rho = c1 B u_rel - U_w (c1 + c0 = 1): the wall's displacement in the step is dt U_w
  const double w[3] = {lever * uRel[3], lever * uRel[4], lever * uRel[5]};
  const double wxn[3] = {w[1] * n[2] - w[2] * n[1], w[2] * n[0] - w[0] * n[2], w[0] * n[1] - w[1] * n[0]};
  double slip[3], wall[3] = {wallVelocity[0], wallVelocity[1], wallVelocity[2]};
  for (int a = 0; a < 3; a++) slip[a] = uRel[a] - wxn[a];
  tangential(n, slip);
  tangential(n, wall);
  for (int a = 0; a < 3; a++) out[a] = ft[a] - ktc1dt * slip[a] + ktdt * wall[a];
}

void pairGeneralisedForce(const double n[3], double leverI, double leverJ, const double f[3], double out[12])
{
  const double nxf[3] = {n[1] * f[2] - n[2] * f[1], n[2] * f[0] - n[0] * f[2], n[0] * f[1] - n[1] * f[0]};
  for (int a = 0; a < 3; a++) {
    out[a] = f[a];
    out[3 + a] = -leverI * nxf[a];
    out[6 + a] = -f[a];
    out[9 + a] = -leverJ * nxf[a];
  }
}

void wallGeneralisedForce(const double n[3], double lever, const double f[3], double out[6])
{
  const double nxf[3] = {n[1] * f[2] - n[2] * f[1], n[2] * f[0] - n[0] * f[2], n[0] * f[1] - n[1] * f[0]};
  for (int a = 0; a < 3; a++) {
    out[a] = f[a];
    out[3 + a] = -lever * nxf[a];
  }
}

}  // namespace contact
}  // namespace fdm
