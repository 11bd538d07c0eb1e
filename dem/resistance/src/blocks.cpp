#include "fdm/resistance/blocks.hpp"

#include <cmath>
#include <cstring>
#include <stdexcept>

namespace fdm {
namespace resistance {

namespace {

const int symmetricPairs[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};

inline double kronecker(int i, int j) { return i == j ? 1.0 : 0.0; }

// eps_ijk d_k
inline void crossMatrix(const double d[3], double e[3][3])
{
    e[0][0] = 0;     e[0][1] = d[2];  e[0][2] = -d[1];
    e[1][0] = -d[2]; e[1][1] = 0;     e[1][2] = d[0];
    e[2][0] = d[1];  e[2][1] = -d[0]; e[2][2] = 0;
}

// X d d + Y (I - d d), Eq. (A.1) forms of A and C
inline void axialTransverse(double X, double Y, const double d[3], double scale, double (&R)[12][12], int row, int col)
{
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) R[row + i][col + j] = scale * ((X - Y) * d[i] * d[j] + Y * kronecker(i, j));
}

inline void antisymmetric(double Y, const double e[3][3], double scale, double (&R)[12][12], int row, int col)
{
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) R[row + i][col + j] = scale * Y * e[i][j];
}

// G_ijk = X (d_i d_j - delta_ij/3) d_k + Y (d_i delta_jk + d_j delta_ik - 2 d_i d_j d_k)
inline double stressletFromTranslation(double X, double Y, const double d[3], int i, int j, int k)
{
    return X * (d[i] * d[j] - kronecker(i, j) / 3) * d[k] +
           Y * (d[i] * kronecker(j, k) + d[j] * kronecker(i, k) - 2 * d[i] * d[j] * d[k]);
}

// H_ijk = Y (d_i eps_jkm d_m + d_j eps_ikm d_m)
inline double stressletFromRotation(double Y, const double d[3], const double e[3][3], int i, int j, int k)
{
    return Y * (d[i] * e[j][k] + d[j] * e[i][k]);
}

}  // namespace

PairGeometry pairGeometry(const double x1[3], const double x2[3], double a1, double a2)
{
    PairGeometry g;
    const double dx[3] = {x2[0] - x1[0], x2[1] - x1[1], x2[2] - x1[2]};
    g.r = std::sqrt(dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2]);
    if (!(g.r > 0)) throw std::invalid_argument("pairGeometry: coincident centres");
    for (int i = 0; i < 3; ++i) g.d[i] = dx[i] / g.r;
    g.xi = 2 * g.r / (a1 + a2) - 2;
    return g;
}

void buildPairBlock(const PairFunctionValues& v, const double d[3], double eta, PairBlock& out)
{
    double e[3][3];
    crossMatrix(d, e);
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) {
            const int rowF = 6 * a, rowT = 6 * a + 3, colU = 6 * b, colO = 6 * b + 3;
            axialTransverse(v.f[XA][a][b], v.f[YA][a][b], d, eta, out.R, rowF, colU);
            antisymmetric(-v.f[YB][b][a], e, eta, out.R, rowF, colO);  // B-tilde_ab: Y = -Y^B_ba (A.3)
            antisymmetric(v.f[YB][a][b], e, eta, out.R, rowT, colU);
            axialTransverse(v.f[XC][a][b], v.f[YC][a][b], d, eta, out.R, rowT, colO);
            for (int c = 0; c < 6; ++c) {
                const int i = symmetricPairs[c][0], j = symmetricPairs[c][1];
                for (int k = 0; k < 3; ++k) {
                    out.stress[6 * a + c][colU + k] = eta * stressletFromTranslation(v.f[XG][a][b], v.f[YG][a][b], d, i, j, k);
                    out.stress[6 * a + c][colO + k] = eta * stressletFromRotation(v.f[YH][a][b], d, e, i, j, k);
                }
            }
            for (int k = 0; k < 3; ++k) {
                out.stress[12 + a][colU + k] = eta * v.f[XP][a][b] * d[k];
                out.stress[12 + a][colO + k] = 0;
            }
        }
}

void buildWallBlock(const WallScalars& w, const double d[3], double eta, WallBlock& out)
{
    double e[3][3];
    crossMatrix(d, e);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            out.R[i][j] = eta * ((w.f[WallXA] - w.f[WallYA]) * d[i] * d[j] + w.f[WallYA] * kronecker(i, j));
            out.R[i][3 + j] = -eta * w.f[WallYB] * e[i][j];  // B-tilde = -Y^B (A.3)
            out.R[3 + i][j] = eta * w.f[WallYB] * e[i][j];
            out.R[3 + i][3 + j] = eta * ((w.f[WallXC] - w.f[WallYC]) * d[i] * d[j] + w.f[WallYC] * kronecker(i, j));
        }
    for (int c = 0; c < 6; ++c) {
        const int i = symmetricPairs[c][0], j = symmetricPairs[c][1];
        for (int k = 0; k < 3; ++k) {
            out.stress[c][k] = eta * stressletFromTranslation(w.f[WallXG], w.f[WallYG], d, i, j, k);
            out.stress[c][3 + k] = eta * stressletFromRotation(w.f[WallYH], d, e, i, j, k);
        }
    }
    for (int k = 0; k < 3; ++k) {
        out.stress[6][k] = eta * w.f[WallXP] * d[k];
        out.stress[6][3 + k] = 0;
    }
}

bool subgridPairBlock(const SubgridModel& model, const double x1[3], const double x2[3], double a1, double a2,
                      double eta, PairBlock& out)
{
    const PairGeometry g = pairGeometry(x1, x2, a1, a2);
    if (!(g.xi < model.pairRange(a1, a2))) return false;
    buildPairBlock(subgridPairFunctions(model, a1, a2, g.xi, g.r), g.d, eta, out);
    return true;
}

bool subgridWallBlock(const SubgridModel& model, const double x[3], double a, const double wallPoint[3],
                      const double normal[3], double eta, WallBlock& out)
{
    const double norm = std::sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
    if (!(norm > 0)) throw std::invalid_argument("subgridWallBlock: zero normal");
    const double d[3] = {normal[0] / norm, normal[1] / norm, normal[2] / norm};
    const double h = (wallPoint[0] - x[0]) * d[0] + (wallPoint[1] - x[1]) * d[1] + (wallPoint[2] - x[2]) * d[2];
    const double eps = h / a - 1;  // Appendix A.2
    if (!(eps < model.wallRange(a))) return false;
    buildWallBlock(model.wall(a, eps), d, eta, out);
    return true;
}

void theoryPairBlock(TwoSphereTheory& theory, const double x1[3], const double x2[3], double a1, double a2,
                     double eta, PairBlock& out)
{
    const PairGeometry g = pairGeometry(x1, x2, a1, a2);
    buildPairBlock(theory.values(a1, a2, g.xi), g.d, eta, out);
}

void wallVelocityTerm(const WallBlock& block, const double u[3], double forceTorque[6], double stress[7])
{
    for (int i = 0; i < 6; ++i) forceTorque[i] = block.R[i][0] * u[0] + block.R[i][1] * u[1] + block.R[i][2] * u[2];
    for (int i = 0; i < 7; ++i) stress[i] = block.stress[i][0] * u[0] + block.stress[i][1] * u[1] + block.stress[i][2] * u[2];
}

namespace {
struct DenseAdd {
    double* m;
    int n;
    void operator()(int i, int j, double v) const { m[std::size_t(i) * n + j] += v; }
};
}  // namespace

void addPairBlockToDense(const PairBlock& block, int p1, int p2, double* matrix, int size)
{
    DenseAdd add = {matrix, size};
    scatterPairBlock(block, p1, p2, add);
}

}  // namespace resistance
}  // namespace fdm
