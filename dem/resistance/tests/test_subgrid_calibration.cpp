// The squeeze calibration (paper Appendix B; subgrid_calibration.hpp): reading the table, interpolating
// it, refusing what it does not cover, the calibrated sub-grid model built on it, and the table shipped
// in the repository against the lubrication limit of the theory.
#include "fdm/resistance/resistance.hpp"
#include "fdm/resistance/subgrid_calibration.hpp"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

#include "block_matrices.hpp"

using namespace fdm::resistance;

namespace {

const double pi = 3.14159265358979323846;

std::string writeTable(const std::string& name, const std::string& text)
{
    const std::string path = std::string(::testing::TempDir()) + name;
    std::ofstream(path.c_str()) << text;
    return path;
}

// Two a/Delta, two ratios and a wall: xi * s_hat = c (1 - xi) on xi = 1e-5 ... 1 (values chosen by hand).
std::string syntheticTable()
{
    std::string text = "# synthetic\n";
    const double corners[4][3] = {{3, 1, 0.25}, {3, 1.4, 0.30}, {5, 1, 0.35}, {5, 1.4, 0.40}};
    for (int k = 0; k < 5; ++k) {
        const bool wall = (k == 4);
        const double ad = wall ? 3 : corners[k][0], ratio = wall ? 1 : corners[k][1], c = wall ? 1.0 : corners[k][2];
        text += std::string(wall ? "wall " : "pair ") + std::to_string(ad) + " " + std::to_string(ratio) + " 6 1 1 1 1 0\n";
        const double xis[6] = {1e-5, 1e-4, 1e-3, 1e-2, 0.1, 1.0};
        for (double xi : xis) {
            char row[64];
            std::snprintf(row, sizeof row, "%.10e %.10e\n", xi, c * (1 - xi));
            text += row;
        }
    }
    return text;
}

}  // namespace

TEST(SubgridCalibration, InterpolatesTheTableAndEndsAtItsLastRow)
{
    const SubgridCalibration cal = SubgridCalibration::read(writeTable("squeeze_synthetic.dat", syntheticTable()));
    const double delta = 1.0 / 3;
    // at the nodes: the table itself
    EXPECT_NEAR(cal.pairSHat(1, 1, delta, 1e-3) * 1e-3, 0.25 * (1 - 1e-3), 1e-12);
    EXPECT_NEAR(cal.wallSHat(1, delta, 1e-2) * 1e-2, 1.0 * (1 - 1e-2), 1e-12);
    // radii in either order are the same pair
    EXPECT_DOUBLE_EQ(cal.pairSHat(1, 1.4, delta, 0.05), cal.pairSHat(1.4, 1, delta, 0.05));
    // between nodes: linear in ln xi
    const double xi = std::sqrt(1e-3 * 1e-2);
    EXPECT_NEAR(cal.pairSHat(1, 1, delta, xi) * xi, 0.25 * (1 - 0.5 * (1e-3 + 1e-2)), 1e-12);
    // bilinear between a/Delta 3 and 5 and ratios 1 and 1.4: the middle is the mean of the corners
    EXPECT_NEAR(cal.pairSHat(1, 1.2, 0.25, 1e-4) * 1e-4, 0.325 * (1 - 1e-4), 1e-12);
    // the correction ends at the last row, and below the first it keeps xi * s_hat
    EXPECT_EQ(cal.pairSHat(1, 1, delta, 1.0), 0.0);
    EXPECT_EQ(cal.pairSHat(1, 1, delta, 2.0), 0.0);
    EXPECT_NEAR(cal.pairSHat(1, 1, delta, 1e-7) * 1e-7, 0.25 * (1 - 1e-5), 1e-12);
    EXPECT_DOUBLE_EQ(cal.pairRange(1, 1, delta), 1.0);
}

TEST(SubgridCalibration, RefusesWhatItDoesNotCover)
{
    const SubgridCalibration cal = SubgridCalibration::read(writeTable("squeeze_synthetic.dat", syntheticTable()));
    EXPECT_TRUE(cal.coversPair(1, 1.4, 0.25));
    EXPECT_FALSE(cal.coversPair(1, 1, 0.5));   // a/Delta 2
    EXPECT_FALSE(cal.coversPair(1, 2, 0.25));  // ratio 2
    EXPECT_FALSE(cal.coversWall(1, 0.25));     // walls only at a/Delta 3
    try {
        cal.pairSHat(1, 2, 0.25, 0.01);
        FAIL() << "no exception";
    } catch (const std::runtime_error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("a2/a1 2"), std::string::npos) << what;
        EXPECT_NE(what.find("(3, 1.4)"), std::string::npos) << what;
    }
}

TEST(SubgridCalibration, MalformedTablesNameTheFileAndLine)
{
    const char* bad[] = {
        "pair 3 1 2 0 0 0 0 0\n1e-3 0.2\n",                 // one row short
        "pair 3 1 2 0 0 0 0 0\n1e-3 0.2\n1e-4 0.1\n",       // xi not increasing
        "pair 3 0.7 2 0 0 0 0 0\n1e-3 0.2\n1e-2 0.1\n",     // ratio below 1
        "pair 3 1 2 0 0 0 0 0\n1e-3 -0.2\n1e-2 0.1\n",      // negative correction
        "sphere 3 1 2\n",                                    // unknown kind
    };
    for (const char* text : bad) {
        const std::string path = writeTable("squeeze_bad.dat", text);
        try {
            SubgridCalibration::read(path);
            FAIL() << "accepted: " << text;
        } catch (const std::runtime_error& e) {
            EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
        }
    }
    EXPECT_THROW(SubgridCalibration::read("/nonexistent/squeeze.dat"), std::runtime_error);
}

// The calibrated model changes the squeeze functions only, and keeps the block frame-invariant,
// symmetric and positive semi-definite.
TEST(CalibratedSubgridModel, ReplacesTheSqueezeFunctionsOnly)
{
    const SubgridCalibration cal = SubgridCalibration::read(writeTable("squeeze_synthetic.dat", syntheticTable()));
    const double delta = 0.25;
    const CalibratedSubgridModel model(cal, delta, 0.65, 0.75);
    const CutoffSubgridModel cutoff(delta, 0.65);
    const double a1 = 1.4, a2 = 1.0, xi = 0.02;
    const PairSubgridBase b = model.pair(a1, a2, xi), c = cutoff.pair(a1, a2, xi);
    EXPECT_NEAR(b.f[BaseX21A], -6 * pi * 1.0 * cal.pairSHat(a1, a2, delta, xi), 1e-12);
    for (int f = 1; f < NumSubgridBase; ++f) EXPECT_EQ(b.f[f], c.f[f]) << subgridBaseName(SubgridBaseFunction(f));
    // beyond the cut-off, only the squeeze
    const PairSubgridBase far = model.pair(1, 1, 0.5);
    EXPECT_LT(far.f[BaseX21A], 0);
    for (int f = 1; f < NumSubgridBase; ++f) EXPECT_EQ(far.f[f], 0.0);
    EXPECT_DOUBLE_EQ(model.pairRange(1, 1), 1.0);

    const CalibratedSubgridModel wallModel(cal, 1.0 / 3, 0.65, 0.75);
    const WallScalars w = wallModel.wall(1.0, 1e-3);
    EXPECT_NEAR(w.f[WallXA], 6 * pi * cal.wallSHat(1.0, 1.0 / 3, 1e-3), 1e-12);

    PairBlock block;
    const double x1[3] = {0.3, 0.1, -0.2}, x2[3] = {0.3 + 0.6 * (a1 + a2) / 2 * (2 + xi), 0.8 * (a1 + a2) / 2 * (2 + xi), -0.2};
    ASSERT_TRUE(subgridPairBlock(model, x1, x2, a1, a2, 1.0, block));
    const Matrix12 R = pairMatrix(block);
    EXPECT_LT((R - R.transpose()).norm(), 1e-12 * R.norm());
    Eigen::SelfAdjointEigenSolver<Matrix12> eig(R);
    EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-12 * R.norm());
    // a rigid translation of the pair meets no resistance
    Vector12 u = Vector12::Zero();
    u(0) = u(6) = 0.3;
    u(1) = u(7) = -0.7;
    EXPECT_LT((R * u).norm(), 1e-12 * R.norm());
}

// The table shipped in the repository: the sizes the suspension runs need, and at small gaps the
// correction is the theory's lubrication singularity (the solver's own resistance stays finite):
// xi * s_hat -> 2 lambda^2/(1 + lambda)^3 for a pair (Jeffrey & Onishi's leading term of the squeeze
// resistance in units of 6 pi eta a1), eps * s_hat -> 1 for a wall (Cox & Brenner).
TEST(SubgridCalibration, ShippedTableHasTheLubricationLimit)
{
    const SubgridCalibration cal = SubgridCalibration::read(SubgridCalibration::defaultPath());
    for (double ad : {3.0, 4.0, 5.0}) {
        const double delta = 1 / ad;
        for (double ratio : {1.0, 1.4}) {
            ASSERT_TRUE(cal.coversPair(1, ratio, delta)) << "a/Delta " << ad << " ratio " << ratio;
            const double lead = 2 * ratio * ratio / std::pow(1 + ratio, 3);
            EXPECT_NEAR(cal.pairSHat(1, ratio, delta, 1e-5) * 1e-5 / lead, 1.0, 2e-3) << ad << " " << ratio;
            EXPECT_GT(cal.pairSHat(1, ratio, delta, 0.3), 0.0);
        }
        ASSERT_TRUE(cal.coversWall(1, delta)) << "a/Delta " << ad;
        EXPECT_NEAR(cal.wallSHat(1, delta, 1e-5) * 1e-5, 1.0, 2e-3) << ad;
        EXPECT_GT(cal.wallSHat(1, delta, 0.3), 0.0);
    }
    // the bidisperse suspension at a1/Delta = 3 (a2 = 1.4 a1): every pair and wall gap is covered
    EXPECT_TRUE(cal.coversPair(1.4, 1.4, 1.0 / 3));
    EXPECT_TRUE(cal.coversWall(1.4, 1.0 / 3));
}

namespace {

// The synthetic table plus the tangential wall functions at a/Delta = 3 only: s_hat constant
// (xi * s_hat = s xi) at the rows up to xi = 0.5 (the last row 0), the given values of Y^A, Y^B, Y^C,
// X^C (Kim-Karrila units).
std::string tableWithTangential(double yA, double yB, double yC, double xC)
{
    std::string text = syntheticTable();
    const char* names[4] = {"wall_YA", "wall_YB", "wall_YC", "wall_XC"};
    const double values[4] = {yA, yB, yC, xC};
    for (int k = 0; k < 4; ++k) {
        text += std::string(names[k]) + " 3 1 5 0 0 0 0 0\n";
        for (double xi : {1e-5, 1e-2, 0.02, 0.25, 0.5}) {
            char row[64];
            std::snprintf(row, sizeof row, "%.10e %.10e\n", xi, values[k] * xi);
            text += row;
        }
    }
    return text;
}

}  // namespace

// Where the table has them, the tangential wall functions replace the cut-off model's (with Y^G, Y^H
// following from them by Eq. D.4); elsewhere (a/Delta = 5 here) the cut-off model's stay. The range is
// the longest of the wall functions'.
TEST(CalibratedSubgridModel, ReplacesTheTangentialWallFunctionsWhereTabulated)
{
    const SubgridCalibration cal =
        SubgridCalibration::read(writeTable("tangential_synthetic.dat", tableWithTangential(0.6, -0.15, 0.4, 0.05)));
    EXPECT_TRUE(cal.coversWallFunction(WallTangentialYB, 1.0, 1.0 / 3));
    EXPECT_FALSE(cal.coversWallFunction(WallTangentialYB, 1.0, 1.0 / 5));
    const double a = 1.0, eps = 0.02;
    const CalibratedSubgridModel model(cal, a / 3, 0.65, 0.75);
    const WallScalars w = model.wall(a, eps);
    EXPECT_NEAR(w.f[WallXA], 6 * pi * a * cal.wallSHat(a, a / 3, eps), 1e-12);
    EXPECT_NEAR(w.f[WallYA], 6 * pi * 0.6, 1e-9);
    EXPECT_NEAR(w.f[WallYB], 4 * pi * -0.15, 1e-9);
    EXPECT_NEAR(w.f[WallYC], 8 * pi * 0.4, 1e-9);
    EXPECT_NEAR(w.f[WallXC], 8 * pi * 0.05, 1e-9);
    EXPECT_NEAR(w.f[WallYG], (1 + eps) * a * w.f[WallYA] + 0.5 * w.f[WallYB], 1e-12);
    EXPECT_NEAR(w.f[WallYH], -(1 + eps) * a * w.f[WallYB] - 0.5 * w.f[WallYC], 1e-12);
    EXPECT_EQ(model.wallClipped(), 0);
    EXPECT_GE(model.wallRange(a), 0.5 * (1 - 1e-12));
    // beyond the cut-off model's range the calibrated tangential functions still act
    const WallScalars mid = model.wall(a, 0.25);
    EXPECT_NEAR(mid.f[WallYA], 6 * pi * 0.6, 1e-9);

    // a table without the tangential functions: they are the cut-off model's
    const CalibratedSubgridModel wall3(SubgridCalibration::read(writeTable("squeeze_only3.dat", syntheticTable())), a / 3,
                                       0.65, 0.75);
    const CutoffSubgridModel cutoff3(a / 3, 0.75);
    const WallScalars w3 = wall3.wall(a, eps), c3 = cutoff3.wall(a, eps);
    for (WallFunction f : {WallYA, WallYB, WallYC, WallXC, WallYG, WallYH}) EXPECT_EQ(w3.f[f], c3.f[f]) << f;

    // the block stays symmetric, positive semi-definite and frame-invariant (a wall moving with the
    // sphere: no force)
    WallBlock block;
    const double x[3] = {0.2, a * (1 + eps), -0.4}, wallPoint[3] = {0, 0, 0}, normal[3] = {0, -1, 0};
    ASSERT_TRUE(subgridWallBlock(model, x, a, wallPoint, normal, 1.0, block));
    const Eigen::Matrix<double, 6, 6> R = wallMatrix(block);
    EXPECT_LT((R - R.transpose()).norm(), 1e-12 * R.norm());
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6> > eig(R);
    EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-12 * R.norm());
}

// The dissipation rule for a wall: R^th + R^SG positive semi-definite (the correction takes away at
// most half of what the solver resolves). A correction that is indefinite on its own but leaves the
// theory's block positive passes unchanged; one beyond it is clipped (Y^A, Y^C, X^C at minus the
// theory, |Y^B_th + Y^B_SG| at sqrt((Y^A_th + Y^A_SG)(Y^C_th + Y^C_SG))) and counted.
TEST(CalibratedSubgridModel, WallDissipationRuleClipsAndCounts)
{
    const double a = 1.0;
    // the solver's excess coupling taken away: Y^B_SG > 0 with Y^A_SG = Y^C_SG = 0, kept
    const CalibratedSubgridModel allowed(
        SubgridCalibration::read(writeTable("tangential_coupling.dat", tableWithTangential(0, 0.2, 0, 0))), a / 3,
        0.65, 0.75);
    const WallScalars kept = allowed.wall(a, 0.25);  // a row of the table
    EXPECT_EQ(allowed.wallClipped(), 0);
    EXPECT_NEAR(kept.f[WallYB], 4 * pi * 0.2, 1e-9);
    EXPECT_LT(kept.f[WallYA] * kept.f[WallYC], kept.f[WallYB] * kept.f[WallYB]);  // indefinite alone

    const CalibratedSubgridModel model(
        SubgridCalibration::read(writeTable("tangential_clip.dat", tableWithTangential(0.3, -5, 0.4, -2))), a / 3,
        0.65, 0.75);
    const double eps = 0.05;
    const WallScalars w = model.wall(a, eps), th = wallTheoryDimensional(a, eps);
    EXPECT_EQ(model.wallClipped(), 1);
    EXPECT_NEAR(w.f[WallXC], -th.f[WallXC], 1e-12);
    EXPECT_NEAR(std::fabs(th.f[WallYB] + w.f[WallYB]),
                std::sqrt((th.f[WallYA] + w.f[WallYA]) * (th.f[WallYC] + w.f[WallYC])), 1e-12);
    EXPECT_LT(th.f[WallYB] + w.f[WallYB], 0);  // the sign is kept
    // the coupled block R^th + R^SG is positive semi-definite
    WallBlock block;
    const double x[3] = {0, a * (1 + eps), 0}, wallPoint[3] = {0, 0, 0}, normal[3] = {0, -1, 0};
    ASSERT_TRUE(subgridWallBlock(model, x, a, wallPoint, normal, 1.0, block));
    struct Theory : SubgridModel {
        double pairRange(double, double) const { return 0; }
        double wallRange(double) const { return 1; }
        PairSubgridBase pair(double, double, double) const { return PairSubgridBase(); }
        WallScalars wall(double a, double eps) const { return wallTheoryDimensional(a, eps); }
        const char* describe() const { return "theory"; }
    } theory;
    WallBlock theoryBlock;
    ASSERT_TRUE(subgridWallBlock(theory, x, a, wallPoint, normal, 1.0, theoryBlock));
    const Eigen::Matrix<double, 6, 6> total = wallMatrix(block) + wallMatrix(theoryBlock);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6> > eig(total);
    EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-10 * total.norm());
}

namespace {

// The synthetic table plus the pair's internal-mode blocks at a1/Delta = 3 and ratios 1 and 1.4: K
// constant (xi * K = K xi) up to xi = 0.5, the given [K11, K12, K22, K_twist] (eta a1^n), K12 as given
// for the unequal pair and 0 for equal spheres (zero by symmetry).
std::string tableWithPairTangential(const double K[4])
{
    std::string text = syntheticTable();
    const char* names[4] = {"pair_K11", "pair_K12", "pair_K22", "pair_Ktw"};
    for (double ratio : {1.0, 1.4})
        for (int k = 0; k < 4; ++k) {
            text += std::string(names[k]) + " 3 " + std::to_string(ratio) + " 5 0 0 0\n";
            const double value = (k == 1 && ratio == 1.0) ? 0.0 : K[k];
            for (double xi : {1e-5, 1e-2, 0.02, 0.25, 0.5}) {
                char row[64];
                std::snprintf(row, sizeof row, "%.10e %.10e\n", xi, value * xi);
                text += row;
            }
        }
    return text;
}

// The six internal modes of a pair (scripts/fdmsubgrid/pairtangential.py) for the line of centres d and
// centre distance r, columns U1 W1 U2 W2: squeeze, twist, and (q1, q2) for two transverse directions.
Eigen::Matrix<double, 6, 12> internalModes(const Eigen::Vector3d& d, double r)
{
    Eigen::Vector3d e1 = d.unitOrthogonal(), e2 = d.cross(e1);
    Eigen::Matrix<double, 6, 12> P = Eigen::Matrix<double, 6, 12>::Zero();
    P.block<1, 3>(0, 0) = d.transpose();
    P.block<1, 3>(0, 6) = -d.transpose();
    P.block<1, 3>(1, 3) = d.transpose();
    P.block<1, 3>(1, 9) = -d.transpose();
    int row = 2;
    for (const Eigen::Vector3d& e : {e1, e2}) {
        const Eigen::Vector3d n = d.cross(e);
        P.block<1, 3>(row, 0) = e.transpose();
        P.block<1, 3>(row, 6) = -e.transpose();
        P.block<1, 3>(row, 3) = 0.5 * r * n.transpose();
        P.block<1, 3>(row, 9) = 0.5 * r * n.transpose();
        P.block<1, 3>(row + 1, 3) = n.transpose();
        P.block<1, 3>(row + 1, 9) = -n.transpose();
        row += 2;
    }
    return P;
}

}  // namespace

// The pair's tangential functions from K on the internal modes: the block the pair style builds
// (Appendix C.2, averaged with the relabelled pair) is exactly P^T K P, for radii in either order (K12
// changes sign with the labels) and any line of centres; a table without them keeps the cut-off model's.
TEST(CalibratedSubgridModel, PairTangentialBlockIsTheTabulatedInternalCorrection)
{
    const double K[4] = {2.5, -0.8, 1.3, 0.2};  // K11 K12 K22 K_twist in eta a1^n; positive definite
    const SubgridCalibration cal =
        SubgridCalibration::read(writeTable("pair_tangential_synthetic.dat", tableWithPairTangential(K)));
    const double a = 0.5, delta = a / 3, xi = 0.02;  // a1 = 0.5: K scales with a1^n
    const CalibratedSubgridModel model(cal, delta, 0.65, 0.75);
    for (double a2 : {a, 1.4 * a})
        for (bool swapped : {false, true}) {
            const double r1 = swapped ? a2 : a, r2 = swapped ? a : a2;
            const Eigen::Vector3d d = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
            const double r = 0.5 * (r1 + r2) * (2 + xi);
            const double x1[3] = {0.1, 0.2, -0.3}, x2[3] = {x1[0] + r * d[0], x1[1] + r * d[1], x1[2] + r * d[2]};
            PairBlock block;
            ASSERT_TRUE(subgridPairBlock(model, x1, x2, r1, r2, 1.0, block));
            const Matrix12 R = pairMatrix(block);
            const Eigen::Matrix<double, 6, 12> P = internalModes(d, r);
            const Eigen::Matrix<double, 6, 6> G = (P * P.transpose()).inverse();
            const Eigen::Matrix<double, 6, 6> Kfound = G * P * R * P.transpose() * G;
            EXPECT_LT((R - P.transpose() * Kfound * P).norm(), 1e-12 * R.norm()) << a2 << " " << swapped;
            const double k12 = (a2 == a ? 0.0 : K[1]) * a * a * (swapped ? -1 : 1);
            EXPECT_NEAR(Kfound(0, 0), 6 * pi * a * cal.pairSHat(r1, r2, delta, xi), 1e-10);  // the squeeze
            EXPECT_NEAR(Kfound(1, 1), K[3] * a * a * a, 1e-10);
            for (int row : {2, 4}) {
                EXPECT_NEAR(Kfound(row, row), K[0] * a, 1e-10) << a2 << " " << swapped;
                EXPECT_NEAR(Kfound(row, row + 1), k12, 1e-10) << a2 << " " << swapped;
                EXPECT_NEAR(Kfound(row + 1, row + 1), K[2] * a * a * a, 1e-10) << a2 << " " << swapped;
            }
            EXPECT_NEAR(Kfound(2, 4), 0, 1e-10);  // the two transverse directions do not couple
        }
    // beyond the cut-off model's range the calibrated functions still act; past the table, nothing
    EXPECT_NEAR(model.pair(a, a, 0.25).f[BaseY21A], -K[0] * a, 1e-10);
    EXPECT_EQ(model.pair(a, a, 0.6).f[BaseY21A], 0.0);
    // a1/Delta 5 has no tangential pair blocks in this table: the cut-off model's functions stay
    const CalibratedSubgridModel model5(cal, a / 5, 0.65, 0.75);
    const CutoffSubgridModel cutoff5(a / 5, 0.65);
    for (int f = 1; f < NumSubgridBase; ++f)
        EXPECT_EQ(model5.pair(a, a, 0.05).f[f], cutoff5.pair(a, a, 0.05).f[f]) << subgridBaseName(SubgridBaseFunction(f));
}

// The stresslet rows on the rolling mode (W1 - W2 along n, q1 = 0) stay the cut-off model's when the table
// calibrates the tangential forces: through C.2 the calibrated Y21A, Y21B alone would move them (Y21H takes
// the change back: CalibratedSubgridModel::pair). Equal spheres, where each sphere's is fixed by symmetry.
TEST(CalibratedSubgridModel, RollingModeStressletStaysTheCutoffModels)
{
    const double K[4] = {2.5, -0.8, 1.3, 0.2};
    const SubgridCalibration cal =
        SubgridCalibration::read(writeTable("pair_rolling_synthetic.dat", tableWithPairTangential(K)));
    const double a = 0.5, delta = a / 3;
    const CalibratedSubgridModel model(cal, delta, 0.65, 0.75);
    const CutoffSubgridModel cutoff(delta, 0.65);
    for (double xi : {1e-3, 0.02, 0.1}) {
        const double r = a * (2 + xi);
        const Eigen::Vector3d d = Eigen::Vector3d(0.3, -0.5, 0.8).normalized(), e = d.unitOrthogonal(), n = d.cross(e);
        const double x1[3] = {0.1, 0.2, -0.3}, x2[3] = {x1[0] + r * d[0], x1[1] + r * d[1], x1[2] + r * d[2]};
        PairBlock calibrated, cut;
        ASSERT_TRUE(subgridPairBlock(model, x1, x2, a, a, 1.0, calibrated));
        ASSERT_TRUE(subgridPairBlock(cutoff, x1, x2, a, a, 1.0, cut));
        // the table acts: the force blocks differ (by more than rounding; the squeeze dominates their norm)
        EXPECT_GT((pairMatrix(calibrated) - pairMatrix(cut)).norm(), 1e-4 * pairMatrix(cut).norm()) << xi;
        Vector12 rolling = Vector12::Zero();
        rolling.segment<3>(3) = n;
        rolling.segment<3>(9) = -n;
        double scale = 0, largestDifference = 0;
        for (int row = 0; row < 14; ++row) {
            double sCalibrated = 0, sCutoff = 0;
            for (int j = 0; j < 12; ++j) {
                sCalibrated += calibrated.stress[row][j] * rolling(j);
                sCutoff += cut.stress[row][j] * rolling(j);
            }
            scale = std::max(scale, std::fabs(sCutoff));
            largestDifference = std::max(largestDifference, std::fabs(sCalibrated - sCutoff));
        }
        EXPECT_GT(scale, 0) << xi;
        EXPECT_LT(largestDifference, 1e-12 * scale) << xi;
    }
}

// The shipped table's pair blocks: every size the suspension runs need is covered, and the dissipation
// rule holds: the full-range theory's block plus the sub-grid block is positive semi-definite (the
// correction takes away at most what the solver resolves), at the tabulated sizes and in between.
TEST(SubgridCalibration, ShippedPairTangentialBlocksKeepTheCoupledPairDissipative)
{
    const SubgridCalibration cal = SubgridCalibration::read(SubgridCalibration::defaultPath());
    TwoSphereTheory theory;
    double K[4];
    int checked = 0;
    for (double ad : {3.0, 3.5, 4.0, 5.0})
        for (double ratio : {1.0, 1.2, 1.4, 1 / 1.4}) {
            const double a1 = 1, a2 = ratio, delta = std::min(a1, a2) / ad;
            ASSERT_TRUE(cal.pairInternalCorrection(a1, a2, delta, 0.01, K)) << ad << " " << ratio;
            EXPECT_GT(K[0], 0) << ad << " " << ratio;  // the solver misses sliding resistance near contact
            const CalibratedSubgridModel model(cal, delta, 0.65, 0.75);
            for (double xi : {1e-4, 1e-3, 0.01, 0.03, 0.1, 0.2, 0.4, 0.8}) {
                const double r = 0.5 * (a1 + a2) * (2 + xi);
                const double x1[3] = {0, 0, 0}, x2[3] = {0.6 * r, 0, 0.8 * r};
                PairBlock sg, th;
                ASSERT_TRUE(subgridPairBlock(model, x1, x2, a1, a2, 1.0, sg));
                buildPairBlock(theory.fullValues(a1, a2, xi), pairGeometry(x1, x2, a1, a2).d, 1.0, th);
                const Matrix12 total = pairMatrix(sg) + pairMatrix(th);
                Eigen::SelfAdjointEigenSolver<Matrix12> eig(total);
                EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-10 * total.norm()) << ad << " " << ratio << " " << xi;
                ++checked;
            }
        }
    EXPECT_EQ(checked, 128);
}
