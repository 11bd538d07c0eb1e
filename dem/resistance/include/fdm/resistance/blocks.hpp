// Resistance blocks built from the scalar functions with the tensor forms of paper Eq. (A.1).
//
// Sign convention (paper Eqs. 19, 21, A.6): stress moments M = -eta R . U, i.e. the force and torque on
// the particles are F = -R U.  The blocks stored here already contain the viscosity eta.
//
// Pair block (Eq. 21): unknowns ordered per pair (U1, Omega1, U2, Omega2) = local indices 0-2, 3-5,
// 6-8, 9-11; rows in the same order (F1, T1, F2, T2).  Rows: F_a = -sum_b (A_ab U_b + Btilde_ab Omega_b),
// T_a = -sum_b (B_ab U_b + C_ab Omega_b).
// Stress rows (Eq. 13 corrections): S_a,ij = -sum_b (G_ab,ijk U_b,k + H_ab,ijk Omega_b,k) for
// ij = xx, xy, xz, yy, yz, zz (rows 0-5: particle 1, 6-11: particle 2), and the dipole trace
// s_a = -sum_b X^P_ab d.U_b (row 12: particle 1, row 13: particle 2).
//
// Wall block (Eq. D.6): unknowns (U, Omega) of the particle; F = -R (U - U_w, Omega), so the wall
// velocity enters as the right-hand side R[:, 0:3] U_w (wallVelocityTerm).  Stress rows: S (6), s (1).
#ifndef FDM_RESISTANCE_BLOCKS_HPP
#define FDM_RESISTANCE_BLOCKS_HPP

#include "fdm/resistance/subgrid.hpp"

namespace fdm {
namespace resistance {

struct PairGeometry {
    double r;       // centre distance
    double d[3];    // (x2 - x1)/r
    double xi;      // 2r/(a1 + a2) - 2
};
PairGeometry pairGeometry(const double x1[3], const double x2[3], double a1, double a2);

struct PairBlock {
    double R[12][12];
    double stress[14][12];
};

struct WallBlock {
    double R[6][6];
    double stress[7][6];
};

// Generic assembly from a full set of functions (theory or sub-grid), dimensional / eta.
void buildPairBlock(const PairFunctionValues& v, const double d[3], double eta, PairBlock& out);
// d: unit normal into the wall.
void buildWallBlock(const WallScalars& dimensional, const double d[3], double eta, WallBlock& out);

// Frame-invariant sub-grid pair block (Eq. 21 with Appendix C.2).  Returns false (and leaves out
// untouched) when the pair is beyond the model's range, so callers can skip it.
bool subgridPairBlock(const SubgridModel& model, const double x1[3], const double x2[3], double a1, double a2,
                      double eta, PairBlock& out);
// Sub-grid wall block (Eq. D.6).  wallPoint: any point of the wall; normal: unit normal into the wall.
bool subgridWallBlock(const SubgridModel& model, const double x[3], double a, const double wallPoint[3],
                      const double normal[3], double eta, WallBlock& out);

// The theory blocks (near-field forms), for checks and the command-line tool.
void theoryPairBlock(TwoSphereTheory& theory, const double x1[3], const double x2[3], double a1, double a2,
                     double eta, PairBlock& out);

// Right-hand side of a moving wall: F = -R (U, Omega) + rhs.  forceTorque[6] and stress[7] receive
// R[:,0:3] U_w and stress[:,0:3] U_w.
void wallVelocityTerm(const WallBlock& block, const double wallVelocity[3], double forceTorque[6], double stress[7]);

// Scatter into a global 6N system where particle p owns unknowns 6p..6p+5 = (U_p, Omega_p).
// add(row, column, value) is called for the 144 entries.
template <class Add>
void scatterPairBlock(const PairBlock& block, int particle1, int particle2, Add add)
{
    const int base[2] = {6 * particle1, 6 * particle2};
    for (int i = 0; i < 12; ++i)
        for (int j = 0; j < 12; ++j) add(base[i / 6] + i % 6, base[j / 6] + j % 6, block.R[i][j]);
}
template <class Add>
void scatterWallBlock(const WallBlock& block, int particle, Add add)
{
    for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j) add(6 * particle + i, 6 * particle + j, block.R[i][j]);
}
// Dense row-major 6N x 6N helper.
void addPairBlockToDense(const PairBlock& block, int particle1, int particle2, double* matrix, int size);

}  // namespace resistance
}  // namespace fdm

#endif
