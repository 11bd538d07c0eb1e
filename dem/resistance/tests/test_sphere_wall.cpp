// Sphere-wall functions against the reference numbers in tests/data/sphere_wall (sources in
// tests/data/README.md): the exact bipolar-coordinate table (haloless/StupidCFD WallSphereResTab.csv),
// Goldman-Cox-Brenner (1967) and Chaoui-Feuillebois (2003).
#include "fdm/resistance/resistance.hpp"
#include "reference_data.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

using namespace fdm::resistance;

// Columns h/a, Fxt, Fxr, Tyt, Tyr, Fzt, Tzr, all divided by 6 pi mu (a = 1).
TEST(SphereWall, MatchesExactTableNearContactAndFarFieldTrend)
{
    const reference::Csv table = reference::readCsv("sphere_wall/WallSphereResTab.csv", false);
    double worstNear[5] = {0}, worstFar[5] = {0};
    const char* names[5] = {"YA (Fxt)", "YB (Fxr)", "YC (Tyr)", "XA (Fzt)", "XC (Tzr)"};
    double previous[5] = {1e300, 1e300, 1e300, 1e300, 1e300};
    for (std::size_t r = 0; r < table.rows.size(); ++r) {
        const std::vector<double>& row = table.rows[r];
        const double eps = row[0] - 1;
        const WallScalars w = wallTheory(eps);
        const double mine[5] = {w.f[WallYA], -w.f[WallYB] * 4.0 / 6.0, w.f[WallYC] * 8.0 / 6.0, w.f[WallXA], w.f[WallXC] * 8.0 / 6.0};
        const double ref[5] = {row[1], row[2], row[4], row[5], row[6]};
        for (int i = 0; i < 5; ++i) {
            const double error = std::fabs(mine[i] - ref[i]) / std::fabs(ref[i]);
            if (eps <= 0.05 + 1e-12) {
                worstNear[i] = std::max(worstNear[i], error);
                EXPECT_LT(error, 0.01) << names[i] << " eps " << eps;
            } else {
                worstFar[i] = std::max(worstFar[i], error);
                EXPECT_LT(error, 0.01) << names[i] << " eps " << eps;
            }
            // monotone decrease towards the single-sphere (Stokes) value
            EXPECT_LE(mine[i], previous[i] * (1 + 1e-12)) << names[i] << " not monotone at eps " << eps;
            previous[i] = mine[i];
        }
    }
    const WallScalars far = wallTheory(1e4);
    EXPECT_NEAR(far.f[WallXA], 1.0, 1e-3);
    EXPECT_NEAR(far.f[WallYA], 1.0, 1e-3);
    EXPECT_NEAR(far.f[WallYC], 1.0, 1e-3);
    EXPECT_NEAR(far.f[WallXC], 1.0, 1e-3);
    EXPECT_NEAR(far.f[WallYB], 0.0, 1e-3);
    for (int i = 0; i < 5; ++i) std::printf("[worst] wall table %s: eps <= 0.05 %.2e, eps in (0.05, 3] %.2e\n", names[i], worstNear[i], worstFar[i]);
}

// Goldman, Cox & Brenner (1967) factors: Ft = F/(6 pi mu a U), Tt = T/(8 pi mu a^2 U),
// Fr = F/(6 pi mu a^2 Omega), Tr = T/(8 pi mu a^3 Omega): within 0.5 %.
TEST(SphereWall, MatchesGoldmanCoxBrenner)
{
    const reference::Csv gcb = reference::readCsv("sphere_wall/gcb1967/gcb1967_all_factors_from_phasicflow_reduced_tables_DERIVED.csv", true);
    double worst = 0;
    for (std::size_t r = 0; r < gcb.rows.size(); ++r) {
        const std::vector<double>& row = gcb.rows[r];
        const double eps = row[gcb.column("eps")];
        const WallScalars w = wallTheory(eps);
        const double mine[4] = {w.f[WallYA], -w.f[WallYB] / 2, -w.f[WallYB] * 4.0 / 6.0, w.f[WallYC]};
        const char* columns[4] = {"Ft_star", "Tt_star", "Fr_star", "Tr_star"};
        for (int i = 0; i < 4; ++i) {
            const double ref = row[gcb.column(columns[i])];
            const double error = std::fabs(mine[i] - ref) / std::fabs(ref);
            worst = std::max(worst, error);
            EXPECT_LT(error, 0.005) << columns[i] << " eps " << eps << ": " << mine[i] << " vs " << ref;
        }
    }
    std::printf("[worst] Goldman-Cox-Brenner factors: %.2e relative\n", worst);
}

// Chaoui & Feuillebois (2003): our evaluation of their small-gap (eps < 0.1) and Pade (eps >= 0.1)
// forms reproduces the reference evaluation; the two forms agree where they overlap.
TEST(SphereWall, MatchesChaouiFeuillebois)
{
    const reference::Csv cf = reference::readCsv("sphere_wall/chaoui_feuillebois2003/cf2003_resistance_translation_rotation_near_wall_DERIVED.csv", true);
    double worst = 0;
    for (std::size_t r = 0; r < cf.rows.size(); ++r) {
        const std::vector<double>& row = cf.rows[r];
        const double eps = row[cf.column("eps")];
        const std::string form = eps < 0.08 ? "_poly" : "_pade";
        const double mine[3] = {wallParallelTranslation(eps), wallCouplingMagnitude(eps), wallParallelRotation(eps)};
        const char* columns[3] = {"fxx_t", "cyx_t", "cyy_r"};
        for (int i = 0; i < 3; ++i) {
            const double ref = row[cf.column(std::string(columns[i]) + form)];
            const double error = std::fabs(mine[i] - ref) / std::fabs(ref);
            worst = std::max(worst, error);
            EXPECT_LT(error, 1e-5) << columns[i] << " eps " << eps;
        }
    }
    std::printf("[worst] Chaoui-Feuillebois forms: %.2e relative\n", worst);
}

// The lubrication form used for X^A below eps = 1e-3 continues Brenner's series.
TEST(SphereWall, NormalTranslationLubricationMatchesBrennerSeries)
{
    const double eps = 1e-3;
    const double series = brennerNormalTranslationSeries(eps);
    EXPECT_NEAR(wallNormalTranslation(eps * (1 - 1e-9)), series, 1e-6 * series);
    EXPECT_NEAR(brennerNormalTranslationSeries(0.01), 1 / 0.01 + 0.2 * std::log(100.0) + 0.971264, 0.01);
}

// The leading lubrication coefficients of the wall are the lambda -> infinity limits of the two-sphere
// ones (eps = xi (1 + lambda)/2): a consistency check of normalisation and signs (Y^B < 0, d into the wall).
TEST(SphereWall, ConsistentWithLargeSphereLimitOfTwoSphereForms)
{
    const double lambda = 1e6;
    const NearFieldConstants k = computeNearFieldConstants(lambda, false);
    EXPECT_NEAR(k.f11[XA].inv * (1 + lambda) / 2, 1.0, 1e-5);               // 1/eps
    EXPECT_NEAR(k.f11[XA].log, 0.2, 1e-5);                                 // (1/5) ln(1/eps)
    EXPECT_NEAR(k.f11[YA].log, 8.0 / 15.0, 1e-5);                          // CF phi_0
    EXPECT_NEAR(k.f11[YB].log, -0.2, 1e-5);                                // Y^B = -2 c_yx, c_yx ~ 0.1 ln(1/eps)
    EXPECT_NEAR(k.f11[YC].log, 0.4, 1e-5);
    EXPECT_NEAR(k.f11[XG].inv * (1 + lambda) / 2, 1.5, 1e-5);
    EXPECT_NEAR(k.f11[XG].log, -1.2, 1e-5);
    // Eq. (D.4) reproduces the wall's Y^G and Y^H logarithms: 0.7 and -0.1
    EXPECT_NEAR(k.f11[YG].log, 1.5 * 8.0 / 15.0 + 0.5 * (-0.2), 1e-5);
    EXPECT_NEAR(k.f11[YH].log, -0.5 * (-0.2) - 0.5 * 0.4, 1e-5);
    const WallScalars w = wallTheory(1e-4), w2 = wallTheory(2e-4);
    EXPECT_NEAR((w.f[WallYA] - w2.f[WallYA]) / std::log(2.0), 8.0 / 15.0, 1e-3);
    EXPECT_LT(w.f[WallYB], 0);
}
