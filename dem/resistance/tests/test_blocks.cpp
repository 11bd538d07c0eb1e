// Properties of the assembled blocks: frame invariance (paper Eq. 24), Lorentz symmetry (A.2),
// positive semi-definiteness, Newton's third law, the wall block of Eq. (D.6), the global scatter.
#include "fdm/resistance/resistance.hpp"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "block_matrices.hpp"

using namespace fdm::resistance;

namespace {

Eigen::Matrix<double, 14, 12> stressToEigen(const PairBlock& b)
{
    Eigen::Matrix<double, 14, 12> m;
    for (int i = 0; i < 14; ++i)
        for (int j = 0; j < 12; ++j) m(i, j) = b.stress[i][j];
    return m;
}

struct RandomPair {
    double a1, a2, x1[3], x2[3], delta;
};

// Random radii 0.5-2, random orientation and position, gap inside the correction range (xi < xi_c).
RandomPair randomPair(std::mt19937& rng)
{
    std::uniform_real_distribution<double> radius(0.5, 2.0), unit(-1, 1), position(-10, 10), cells(0.05, 0.5);
    RandomPair p;
    p.a1 = radius(rng);
    p.a2 = radius(rng);
    const double aMean = 0.5 * (p.a1 + p.a2);
    p.delta = cells(rng) * aMean;  // mesh size: a/Delta between 2 and 20
    const double xiCut = p.delta / aMean;
    std::uniform_real_distribution<double> logGap(std::log(1e-6), std::log(xiCut));
    const double xi = std::exp(logGap(rng));
    double d[3], n2 = 0;
    do {
        n2 = 0;
        for (int i = 0; i < 3; ++i) {
            d[i] = unit(rng);
            n2 += d[i] * d[i];
        }
    } while (n2 < 1e-2 || n2 > 1);
    const double r = aMean * (xi + 2);
    for (int i = 0; i < 3; ++i) {
        p.x1[i] = position(rng);
        p.x2[i] = p.x1[i] + r * d[i] / std::sqrt(n2);
    }
    return p;
}

Vector12 rigidMotion(const RandomPair& p, const double U0[3], const double W0[3])
{
    Vector12 u;
    const double* x[2] = {p.x1, p.x2};
    for (int a = 0; a < 2; ++a) {
        const double* y = x[a];
        u(6 * a + 0) = U0[0] + W0[1] * y[2] - W0[2] * y[1];
        u(6 * a + 1) = U0[1] + W0[2] * y[0] - W0[0] * y[2];
        u(6 * a + 2) = U0[2] + W0[0] * y[1] - W0[1] * y[0];
        for (int i = 0; i < 3; ++i) u(6 * a + 3 + i) = W0[i];
    }
    return u;
}

}  // namespace

// Eq. (24): a pair in rigid-body motion gets no sub-grid force, torque, stresslet or dipole trace.
TEST(SubgridPairBlock, FrameInvariantUnderRigidMotions)
{
    std::mt19937 rng(20230101);
    std::uniform_real_distribution<double> velocity(-1, 1);
    double worst = 0;
    int active = 0;
    for (int trial = 0; trial < 2000; ++trial) {
        const RandomPair p = randomPair(rng);
        const CutoffSubgridModel model(p.delta, 1.0);
        PairBlock block;
        ASSERT_TRUE(subgridPairBlock(model, p.x1, p.x2, p.a1, p.a2, 1.3, block));
        ++active;
        const double U0[3] = {velocity(rng), velocity(rng), velocity(rng)};
        const double W0[3] = {velocity(rng), velocity(rng), velocity(rng)};
        const Vector12 u = rigidMotion(p, U0, W0);
        const Matrix12 R = pairMatrix(block);
        const Eigen::Matrix<double, 14, 12> S = stressToEigen(block);
        const double scale = std::max(R.norm(), S.norm()) * u.norm();
        const double forces = (R * u).norm() / scale, stresses = (S * u).norm() / scale;
        worst = std::max(worst, std::max(forces, stresses));
        EXPECT_LT(forces, 1e-10) << "trial " << trial;
        EXPECT_LT(stresses, 1e-10) << "trial " << trial;
    }
    EXPECT_EQ(active, 2000);
    std::printf("[worst] frame invariance, |R u_rigid| / (|R| |u|) over 2000 random pairs: %.2e\n", worst);
}

// The block of a pair does not depend on which sphere is called 1: the pair given as (x2, x1, a2, a1)
// gives the same matrix with the two particles' rows and columns exchanged. Appendix C.2's expansion
// alone does not (it derives Y^C_22 from Y^C_11, ...): subgridPairFunctions averages the two labellings.
TEST(SubgridPairBlock, IndependentOfLabelling)
{
    std::mt19937 rng(29);
    double worst = 0;
    for (int trial = 0; trial < 2000; ++trial) {
        const RandomPair p = randomPair(rng);
        const CutoffSubgridModel model(p.delta, 1.0);
        PairBlock block, swapped;
        ASSERT_TRUE(subgridPairBlock(model, p.x1, p.x2, p.a1, p.a2, 1.0, block));
        ASSERT_TRUE(subgridPairBlock(model, p.x2, p.x1, p.a2, p.a1, 1.0, swapped));
        const double scale = pairMatrix(block).norm() + stressToEigen(block).norm();
        double difference = 0;
        for (int i = 0; i < 12; ++i)
            for (int j = 0; j < 12; ++j)
                difference = std::max(difference, std::fabs(block.R[i][j] - swapped.R[(i + 6) % 12][(j + 6) % 12]));
        for (int row = 0; row < 14; ++row) {
            const int other = row < 12 ? (row + 6) % 12 : 25 - row;  // S1 <-> S2, s1 <-> s2
            for (int j = 0; j < 12; ++j)
                difference = std::max(difference, std::fabs(block.stress[row][j] - swapped.stress[other][(j + 6) % 12]));
        }
        worst = std::max(worst, difference / scale);
        EXPECT_LT(difference / scale, 1e-13) << "trial " << trial << " a1 " << p.a1 << " a2 " << p.a2;
    }
    std::printf("[worst] relabelled pair block, largest difference / norm over 2000 random pairs: %.2e\n", worst);

    // what the averaging removes: equal spheres at xi 0.1, a/Delta 3 (Y^C_11 5.41 against Y^C_22 3.72 from
    // the C.2 expansion of one labelling)
    const CutoffSubgridModel model(1.0 / 3, 1.0);
    const double r = 2.1;
    const PairFunctionValues oneLabelling = expandAppendixC2(model.pair(1, 1, 0.1), r);
    EXPECT_GT(oneLabelling.f[YC][0][0] - oneLabelling.f[YC][1][1], 0.3 * oneLabelling.f[YC][1][1]);
    const PairFunctionValues both = subgridPairFunctions(model, 1, 1, 0.1, r);
    EXPECT_NEAR(both.f[YC][0][0], both.f[YC][1][1], 1e-12 * both.f[YC][0][0]);
    EXPECT_NEAR(both.f[YB][0][0], -both.f[YB][1][1], 1e-12 * std::fabs(both.f[YB][0][0]));
    EXPECT_NEAR(both.f[XG][0][0], -both.f[XG][1][1], 1e-12 * std::fabs(both.f[XG][0][0]));
}

// Lorentz reciprocity (A.2): symmetric; dissipation never negative: positive semi-definite.
TEST(SubgridPairBlock, SymmetricAndPositiveSemiDefinite)
{
    std::mt19937 rng(7);
    double worstAsymmetry = 0, worstEigen = 0;
    for (int trial = 0; trial < 2000; ++trial) {
        const RandomPair p = randomPair(rng);
        const CutoffSubgridModel model(p.delta, 1.0);
        PairBlock block;
        ASSERT_TRUE(subgridPairBlock(model, p.x1, p.x2, p.a1, p.a2, 1.0, block));
        const Matrix12 R = pairMatrix(block);
        const double asymmetry = (R - R.transpose()).norm() / R.norm();
        worstAsymmetry = std::max(worstAsymmetry, asymmetry);
        EXPECT_LT(asymmetry, 1e-14);
        Eigen::SelfAdjointEigenSolver<Matrix12> eig(R);
        const double smallest = eig.eigenvalues().minCoeff() / R.norm();
        worstEigen = std::min(worstEigen, smallest);
        EXPECT_GE(smallest, -1e-12) << "trial " << trial << " a1 " << p.a1 << " a2 " << p.a2;
    }
    std::printf("[worst] sub-grid pair block: asymmetry %.2e, smallest eigenvalue / norm %.2e\n", worstAsymmetry, worstEigen);
}

// How much the dissipation safeguard changes: measured over random pairs (docs/resistance.md).
TEST(SubgridModel, DissipationSafeguardIsBounded)
{
    std::mt19937 rng(11);
    int clipped = 0, total = 0;
    double largestChange = 0, smallestClippedFraction = 1;
    for (int trial = 0; trial < 4000; ++trial) {
        const RandomPair p = randomPair(rng);
        const CutoffSubgridModel model(p.delta, 1.0);
        const PairGeometry g = pairGeometry(p.x1, p.x2, p.a1, p.a2);
        const PairForms forms = makePairForms(p.a1, p.a2);
        NearFieldForm base[NumSubgridBase];
        selectSubgridBaseForms(forms, base);
        const double xiCut = model.pairRange(p.a1, p.a2);
        PairSubgridBase raw;
        for (int i = 0; i < NumSubgridBase; ++i) raw.f[i] = base[i](std::max(g.xi, minimumGap)) - base[i](xiCut);
        PairSubgridBase safe = raw;
        ++total;
        if (makeDissipative(safe, g.r)) {
            ++clipped;
            smallestClippedFraction = std::min(smallestClippedFraction, g.xi / xiCut);
            // the change, relative to the shear-rotation block's scale sqrt(Y11A Y11C)
            largestChange = std::max(largestChange, std::fabs(safe.f[BaseY21B] - raw.f[BaseY21B]) /
                                                        std::sqrt(-raw.f[BaseY21A] * raw.f[BaseY11C]));
        }
        const PairSubgridBase fromModel = model.pair(p.a1, p.a2, g.xi);
        for (int i = 0; i < NumSubgridBase; ++i) EXPECT_NEAR(fromModel.f[i], safe.f[i], 1e-9 * (1 + std::fabs(safe.f[i])));
    }
    std::printf("[safeguard] clipped %d of %d random pairs (smallest xi/xi_c clipped %.1e); largest change of Y21B %.1f%% of sqrt(Y11A Y11C)\n",
                clipped, total, smallestClippedFraction, 100 * largestChange);
    EXPECT_LT(clipped, total / 4);
    EXPECT_LT(largestChange, 0.25);
}

// The theory blocks too, over the range where the near-field forms are used.
TEST(TheoryPairBlock, SymmetricAndPositiveDefiniteNearContact)
{
    TwoSphereTheory theory;
    const double radii[][2] = {{1, 1}, {1, 1.4}, {1.4, 1}, {1, 0.1}, {1, 10}, {0.5, 2}};
    for (int c = 0; c < 6; ++c)
        for (double xi = 1e-5; xi <= 0.1; xi *= 3) {
            const double a1 = radii[c][0], a2 = radii[c][1], r = 0.5 * (a1 + a2) * (2 + xi);
            const double x1[3] = {0.3, -0.2, 0.1}, x2[3] = {0.3 + 0.6 * r, -0.2 + 0.8 * r, 0.1};
            PairBlock block;
            theoryPairBlock(theory, x1, x2, a1, a2, 1.0, block);
            const Matrix12 R = pairMatrix(block);
            // 12 and 21 come from different series (lambda, 1/lambda): equal to round-off
            EXPECT_LT((R - R.transpose()).norm() / R.norm(), 1e-12);
            Eigen::SelfAdjointEigenSolver<Matrix12> eig(R);
            EXPECT_GT(eig.eigenvalues().minCoeff(), 0) << "a1 " << a1 << " a2 " << a2 << " xi " << xi;
        }
}

// Newton's third law for unequal radii: the sub-grid forces on the two spheres are equal and opposite
// for any motion (squeeze in particular), to round-off.
TEST(SubgridPairBlock, ForcesEqualAndOppositeForUnequalRadii)
{
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> velocity(-1, 1);
    for (int trial = 0; trial < 500; ++trial) {
        const RandomPair p = randomPair(rng);
        const CutoffSubgridModel model(p.delta, 1.0);
        PairBlock block;
        ASSERT_TRUE(subgridPairBlock(model, p.x1, p.x2, p.a1, p.a2, 1.0, block));
        Vector12 u;
        for (int i = 0; i < 12; ++i) u(i) = velocity(rng);
        const Vector12 f = -pairMatrix(block) * u;
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(f(k) + f(6 + k), 0, 1e-12 * f.norm());
    }
    // squeeze, radii 1 and 1.4: F1 = -F2 along d
    const double a1 = 1, a2 = 1.4, xi = 1e-3, r = 0.5 * (a1 + a2) * (2 + xi);
    const double x1[3] = {0, 0, 0}, x2[3] = {r, 0, 0};
    const CutoffSubgridModel model(0.1, 1.0);
    PairBlock block;
    ASSERT_TRUE(subgridPairBlock(model, x1, x2, a1, a2, 1.0, block));
    Vector12 u = Vector12::Zero();
    u(0) = 1;
    u(6) = -1;
    const Vector12 f = -pairMatrix(block) * u;
    EXPECT_LT(f(0), 0);  // sphere 1 pushed back
    EXPECT_NEAR(f(0), -f(6), 1e-12 * std::fabs(f(0)));
}

// Appendix C.2 is built from the theory: below the cut-off the squeeze coefficient is the theory minus
// its value at the cut-off; it vanishes at and beyond the cut-off, and is frozen below xi = 1e-5.
TEST(SubgridModel, CutoffDefinition)
{
    const double a1 = 1, a2 = 1.4, delta = 0.12;
    const CutoffSubgridModel model(delta, 1.0);
    const double xiCut = delta / 1.2;
    EXPECT_DOUBLE_EQ(model.pairRange(a1, a2), xiCut);
    const PairForms forms = makePairForms(a1, a2);
    const double xi = 0.01;
    EXPECT_NEAR(model.pair(a1, a2, xi).f[BaseX21A], forms.f[XA][1][0](xi) - forms.f[XA][1][0](xiCut), 1e-12);
    EXPECT_NEAR(model.pair(a1, a2, xi).f[BaseY11C], forms.f[YC][0][0](xi) - forms.f[YC][0][0](xiCut), 1e-12);
    for (int i = 0; i < NumSubgridBase; ++i) {
        EXPECT_EQ(model.pair(a1, a2, xiCut).f[i], 0.0);
        EXPECT_NEAR(model.pair(a1, a2, xiCut * (1 - 1e-9)).f[i], 0.0, 1e-6);
        EXPECT_EQ(model.pair(a1, a2, 1e-7).f[i], model.pair(a1, a2, 1e-5).f[i]);
    }
    const double x1[3] = {0, 0, 0}, x2[3] = {0.5 * (a1 + a2) * (2 + 1.01 * xiCut), 0, 0};
    PairBlock block;
    EXPECT_FALSE(subgridPairBlock(model, x1, x2, a1, a2, 1.0, block));
    // the cut-off is configurable in mesh cells
    EXPECT_DOUBLE_EQ(CutoffSubgridModel(delta, 2.5).pairRange(a1, a2), 2.5 * xiCut);
    EXPECT_THROW(CutoffSubgridModel(0.0), std::invalid_argument);
}

// Eq. (D.6): a particle translating with the wall feels nothing; the block is symmetric and PSD;
// Y^G, Y^H obey Eq. (D.4).
TEST(SubgridWallBlock, TranslatingWithWallFeelsNothing)
{
    const CutoffSubgridModel model(0.1, 1.0);
    const double a = 0.8, eps = 0.01;
    const double normal[3] = {0.0, 0.0, -2.0};  // wall below, normal into the wall (not unit on purpose)
    const double wallPoint[3] = {5, 7, 0};
    const double x[3] = {1, 2, a * (1 + eps)};
    WallBlock block;
    ASSERT_TRUE(subgridWallBlock(model, x, a, wallPoint, normal, 1.7, block));
    const double Uw[3] = {0.3, -1.1, 0.4};
    double rhsForce[6], rhsStress[7];
    wallVelocityTerm(block, Uw, rhsForce, rhsStress);
    const double u[6] = {Uw[0], Uw[1], Uw[2], 0, 0, 0};
    double norm = 0;
    for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j) norm = std::max(norm, std::fabs(block.R[i][j]));
    for (int i = 0; i < 6; ++i) {
        double f = rhsForce[i];
        for (int j = 0; j < 6; ++j) f -= block.R[i][j] * u[j];
        EXPECT_NEAR(f, 0, 1e-13 * norm);
    }
    for (int i = 0; i < 7; ++i) {
        double s = rhsStress[i];
        for (int j = 0; j < 6; ++j) s -= block.stress[i][j] * u[j];
        EXPECT_NEAR(s, 0, 1e-13 * norm);
    }
    Eigen::Matrix<double, 6, 6> R;
    for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j) R(i, j) = block.R[i][j];
    EXPECT_LT((R - R.transpose()).norm(), 1e-14 * R.norm());
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6> > eig(R);
    EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-12 * R.norm());
    // approaching the wall: repelled (force away from the wall, i.e. along -d = +z)
    double f = 0;
    for (int j = 0; j < 6; ++j) f -= block.R[2][j] * (j == 2 ? -1.0 : 0.0);
    EXPECT_GT(f, 0);
    const WallScalars w = model.wall(a, eps);
    EXPECT_NEAR(w.f[WallYG], (1 + eps) * a * w.f[WallYA] + 0.5 * w.f[WallYB], 1e-12 * std::fabs(w.f[WallYG]));
    EXPECT_NEAR(w.f[WallYH], -(1 + eps) * a * w.f[WallYB] - 0.5 * w.f[WallYC], 1e-12 * std::fabs(w.f[WallYH]));
    // beyond the cut-off: no block
    const double far[3] = {1, 2, a * (1 + 1.01 * 0.1 / a)};
    EXPECT_FALSE(subgridWallBlock(model, far, a, wallPoint, normal, 1.7, block));
}

// Eq. (D.3)/(D.4) make the shear-flow (ambient) part of the wall correction vanish: a particle at rest
// in a simple shear along the wall gets F = T = 0 from the rigid-motion term of Eq. (D.1).
TEST(SubgridWallBlock, NoCorrectionForFixedSphereInWallShear)
{
    const CutoffSubgridModel model(0.1, 1.0);
    const double a = 1.0, eps = 0.02;
    const WallScalars w = model.wall(a, eps);
    const double h = (1 + eps) * a;
    // D.3 first line: (1+eps) a Y^A - 1/2 Y^Btilde - Y^Gtilde = 0 with Y^Btilde = -Y^B, Y^Gtilde = Y^G
    EXPECT_NEAR(h * w.f[WallYA] + 0.5 * w.f[WallYB] - w.f[WallYG], 0, 1e-12 * std::fabs(w.f[WallYG]));
    EXPECT_NEAR(h * w.f[WallYB] + 0.5 * w.f[WallYC] + w.f[WallYH], 0, 1e-12 * std::fabs(w.f[WallYH]));
}

TEST(Blocks, ScatterIntoGlobalSystem)
{
    const CutoffSubgridModel model(0.1, 1.0);
    const double x1[3] = {0, 0, 0}, x2[3] = {2.05, 0.1, 0};
    PairBlock block;
    ASSERT_TRUE(subgridPairBlock(model, x1, x2, 1.0, 1.0, 1.0, block));
    const int n = 4, size = 6 * n;
    std::vector<double> global(size * size, 0.0);
    addPairBlockToDense(block, 3, 1, global.data(), size);
    for (int i = 0; i < 12; ++i)
        for (int j = 0; j < 12; ++j) {
            const int gi = (i < 6 ? 18 : 6) + i % 6, gj = (j < 6 ? 18 : 6) + j % 6;
            EXPECT_EQ(global[gi * size + gj], block.R[i][j]);
        }
    double total = 0;
    for (int k = 0; k < size * size; ++k) total += std::fabs(global[k]);
    double blockTotal = 0;
    for (int i = 0; i < 12; ++i)
        for (int j = 0; j < 12; ++j) blockTotal += std::fabs(block.R[i][j]);
    EXPECT_DOUBLE_EQ(total, blockTotal);
}

// Dimensional convention: eta multiplies everything; the squeeze entry is eta * X11A.
TEST(Blocks, ViscosityAndKimKarrilaFactors)
{
    TwoSphereTheory theory;
    const double a1 = 1.0, a2 = 1.4, xi = 0.01, r = 0.5 * (a1 + a2) * (2 + xi), eta = 2.5;
    const double x1[3] = {0, 0, 0}, x2[3] = {0, 0, r};
    PairBlock block;
    theoryPairBlock(theory, x1, x2, a1, a2, eta, block);
    const NearFieldConstants k = computeNearFieldConstants(a2 / a1);
    const double pi = 3.14159265358979323846;
    EXPECT_NEAR(block.R[2][2], eta * 6 * pi * a1 * k.f11[XA](xi), 1e-12 * block.R[2][2]);
    EXPECT_NEAR(block.R[0][0], eta * 6 * pi * a1 * k.f11[YA](xi), 1e-12 * block.R[0][0]);
    EXPECT_NEAR(block.R[5][5], eta * 8 * pi * a1 * a1 * a1 * k.f11[XC](xi), 1e-12 * block.R[5][5]);
    // torque on 1 from translation of 1 along x, d = z: T = -eta Y11B (U x d) = +eta Y11B e_y, so
    // R[T_y][U_x] = -eta Y11B > 0 and T_y = -R U < 0: the gap's drag at the top of sphere 1 turns it back
    EXPECT_NEAR(block.R[4][0], -eta * 4 * pi * a1 * a1 * k.f11[YB](xi), 1e-12 * std::fabs(block.R[4][0]));
    EXPECT_GT(block.R[4][0], 0);
}
