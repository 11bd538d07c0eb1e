// Two-sphere theoretical functions against the reference numbers in tests/data (sources in its README.md):
// Townsend's tabulated scalars (Pecnut/stokesian-dynamics), his generator's general-lambda constants,
// and the reciprocity / size-ratio relations of paper Eqs. (A.3)-(A.4).
#include "fdm/resistance/resistance.hpp"
#include "reference_data.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

using namespace fdm::resistance;

namespace {

// Shared because the X^M, Y^M, Z^M recurrences take ~2 s to build.
const NearFieldConstants& constantsWithM(double lambda)
{
    static std::map<double, NearFieldConstants> cache;
    std::map<double, NearFieldConstants>::iterator it = cache.find(lambda);
    if (it == cache.end()) it = cache.insert(std::make_pair(lambda, computeNearFieldConstants(lambda, true))).first;
    return it->second;
}

}  // namespace

TEST(ReferenceData, FolderIsPresent)
{
    EXPECT_TRUE(reference::folderExists()) << "missing " << reference::folder()
                                           << ": the tests' reference numbers (dem/resistance/tests/data in the repository)";
}

// Townsend's table (near-field part, s' <= 2.02) for lambda = 0.1, 1, 10: every function within 1e-3
// relative, or 1e-3 absolute where the value is O(1) or smaller.
TEST(TwoSphereTheory, MatchesTownsendTableNearContact)
{
    const std::vector<std::vector<double> > rows =
        reference::readTable("two_sphere_townsend/scalars_general_resistance.txt", 2);
    double worst[NumPairFunctions] = {0};
    int compared = 0;
    for (std::size_t r = 0; r < rows.size(); ++r) {
        const std::vector<double>& row = rows[r];
        const double sDash = row[0], lambda = row[1];
        const int gamma = int(row[2]);
        if (sDash > 2.02 + 1e-12) continue;
        if (!(std::fabs(lambda - 0.1) < 1e-12 || std::fabs(lambda - 1) < 1e-12 || std::fabs(lambda - 10) < 1e-12)) continue;
        const NearFieldConstants& k = constantsWithM(lambda);
        const double xi = sDash - 2;
        for (int f = XA; f <= ZM; ++f) {
            const double mine = gamma == 0 ? k.f11[f](xi) : k.f12[f](xi);
            const double ref = row[3 + f];
            const double error = std::fabs(mine - ref) / std::max(std::fabs(ref), 1.0);
            worst[f] = std::max(worst[f], error);
            EXPECT_LT(error, 1e-3) << pairFunctionName(PairFunction(f)) << (gamma ? "12" : "11") << " lambda " << lambda
                                   << " s' " << sDash << ": " << mine << " vs " << ref;
            ++compared;
        }
    }
    EXPECT_EQ(compared, 3 * 2 * 11 * 11);
    for (int f = XA; f <= ZM; ++f)
        std::printf("[worst] Townsend near field %s: %.2e (relative, absolute below 1)\n", pairFunctionName(PairFunction(f)), worst[f]);
}

// Eq. (A.4): the 21 and 22 functions of (a1, a2) are the 12 and 11 functions at 1/lambda (Townsend's
// lambda = 0.1 rows against our lambda = 10 pair, in a2 units, with the B, G sign change).
TEST(TwoSphereTheory, SwappedFunctionsMatchTownsendAtInverseLambda)
{
    const std::vector<std::vector<double> > rows =
        reference::readTable("two_sphere_townsend/scalars_general_resistance.txt", 2);
    const double a1 = 1, a2 = 10;
    const PairForms forms = makePairForms(a1, a2, false);
    int compared = 0;
    for (std::size_t r = 0; r < rows.size(); ++r) {
        const std::vector<double>& row = rows[r];
        if (row[0] > 2.02 + 1e-12 || std::fabs(row[1] - 0.1) > 1e-12) continue;
        const int gamma = int(row[2]);
        const double xi = row[0] - 2;
        for (int f = XA; f <= YH; ++f) {
            const double sign = (f == YB || f == XG || f == YG) ? -1 : 1;
            const double mine = sign * forms.f[f][1][gamma == 0 ? 1 : 0](xi) / kimKarrilaFactor(PairFunction(f), a2);
            EXPECT_LT(std::fabs(mine - row[3 + f]) / std::max(std::fabs(row[3 + f]), 1.0), 1e-3)
                << pairFunctionName(PairFunction(f)) << " gamma " << gamma << " xi " << xi;
            ++compared;
        }
    }
    EXPECT_EQ(compared, 2 * 11 * 8);
}

// The bidisperse pair of the paper: O(1) constants and singular coefficients to 1e-4 relative.
TEST(TwoSphereTheory, GeneralLambdaConstantsMatchGenerator)
{
    const reference::Csv constants = reference::readCsv("two_sphere_general_lambda/nearfield_O1_constants.csv", true);
    const reference::Csv singular = reference::readCsv("two_sphere_general_lambda/nearfield_singular_coeffs_g.csv", true);
    double worst = 0;
    for (std::size_t r = 0; r < constants.rows.size(); ++r) {
        const std::vector<double>& row = constants.rows[r];
        const double lambda = row[constants.column("lambda")];
        const NearFieldConstants k = computeNearFieldConstants(lambda, false);
        const double l1 = 1 + lambda;
        std::map<std::string, double> mine;
        mine["AX11"] = k.f11[XA].c0;
        mine["AX12"] = k.f12[XA].c0 * 2 / l1;
        mine["AY11"] = k.f11[YA].c0;
        mine["AY12"] = k.f12[YA].c0 * 2 / l1;
        mine["BY11"] = k.f11[YB].c0;
        mine["BY12"] = k.f12[YB].c0 * 4 / (l1 * l1);
        mine["CY11"] = k.f11[YC].c0;
        mine["CY12"] = k.f12[YC].c0 * 8 / (l1 * l1 * l1);
        mine["GX11"] = k.f11[XG].c0;
        mine["GX12"] = k.f12[XG].c0 * 4 / (l1 * l1);
        mine["GY11"] = k.f11[YG].c0;
        mine["GY12"] = k.f12[YG].c0 * 4 / (l1 * l1);
        mine["HY11"] = k.f11[YH].c0;
        mine["HY12"] = k.f12[YH].c0 * 8 / (l1 * l1 * l1);
        mine["X11C_zeta_const"] = k.f11[XC].c0;
        mine["X12C_zeta_const"] = k.f12[XC].c0;
        for (std::map<std::string, double>::const_iterator it = mine.begin(); it != mine.end(); ++it) {
            const double ref = row[constants.column(it->first)];
            const double error = std::fabs(it->second - ref) / std::fabs(ref);
            worst = std::max(worst, error);
            EXPECT_LT(error, 1e-4) << it->first << " lambda " << lambda << ": " << it->second << " vs " << ref;
        }
    }
    double worstG = 0;
    for (std::size_t r = 0; r < singular.rows.size(); ++r) {
        const std::vector<double>& row = singular.rows[r];
        const double lambda = row[singular.column("lambda")];
        const NearFieldConstants k = computeNearFieldConstants(lambda, false);
        std::map<std::string, double> mine;
        mine["G1xa"] = k.f11[XA].inv; mine["G2xa"] = k.f11[XA].log; mine["G3xa"] = k.f11[XA].xlog;
        mine["G2ya"] = k.f11[YA].log; mine["G3ya"] = k.f11[YA].xlog;
        mine["G2yb"] = k.f11[YB].log; mine["G3yb"] = k.f11[YB].xlog;
        mine["G2yc"] = k.f11[YC].log; mine["G3yc"] = k.f11[YC].xlog;
        mine["G4yc"] = k.f12[YC].log; mine["G5yc"] = k.f12[YC].xlog;
        mine["G1xg"] = k.f11[XG].inv; mine["G2xg"] = k.f11[XG].log; mine["G3xg"] = k.f11[XG].xlog;
        mine["G2yg"] = k.f11[YG].log; mine["G3yg"] = k.f11[YG].xlog;
        mine["G2yh"] = k.f11[YH].log; mine["G3yh"] = k.f11[YH].xlog;
        mine["G5yh"] = k.f12[YH].log; mine["G6yh"] = k.f12[YH].xlog;
        for (std::map<std::string, double>::const_iterator it = mine.begin(); it != mine.end(); ++it) {
            const double ref = row[singular.column(it->first)];
            const double error = std::fabs(it->second - ref) / std::max(std::fabs(ref), 1e-9);
            if (std::fabs(ref) > 1e-12) worstG = std::max(worstG, error);
            EXPECT_TRUE(error < 1e-4 || std::fabs(it->second - ref) < 1e-12) << it->first << " lambda " << lambda;
        }
    }
    std::printf("[worst] general-lambda O(1) constants: %.2e relative; singular coefficients: %.2e relative\n", worst, worstG);
}

TEST(TwoSphereTheory, FarFieldSeriesCoefficientsMatchGenerator)
{
    const reference::Csv fk = reference::readCsv("two_sphere_general_lambda/farfield_fk.csv", true);
    const char* names[] = {"Fxa", "Fya", "Fyb", "Fyc", "Fxg", "Fyg", "Fyh"};
    const PairFunction families[] = {XA, YA, YB, YC, XG, YG, YH};
    double worst = 0;
    for (std::size_t r = 0; r < fk.rows.size(); ++r) {
        const double lambda = fk.rows[r][fk.column("lambda")];
        const int k = int(fk.rows[r][fk.column("k")]);
        for (int i = 0; i < 7; ++i) {
            const double ref = fk.rows[r][fk.column(names[i])];
            const double mine = farFieldCoefficient(families[i], k, lambda);
            const double error = std::fabs(mine - ref) / std::max(std::fabs(ref), 1.0);
            worst = std::max(worst, error);
            EXPECT_LT(error, 1e-9) << names[i] << " k " << k << " lambda " << lambda;
        }
    }
    std::printf("[worst] far-field f_k(lambda), k <= 10: %.2e relative\n", worst);
}

// Lorentz reciprocity, Eq. (A.3): the dimensional 12 and 21 functions are computed from different
// series (lambda and 1/lambda) and must agree.
TEST(TwoSphereTheory, ReciprocityOfTwelveAndTwentyOne)
{
    const double radii[][2] = {{1, 1.4}, {1.4, 1}, {1, 0.1}, {0.5, 2}, {1, 7.3}};
    for (int c = 0; c < 5; ++c) {
        const PairForms p = makePairForms(radii[c][0], radii[c][1], false);
        const PairFunction symmetric[] = {XA, YA, XC, YC};
        for (int i = 0; i < 4; ++i) {
            const PairFunction f = symmetric[i];
            for (double xi = 1e-5; xi < 1; xi *= 7) {
                const double v12 = p.f[f][0][1](xi), v21 = p.f[f][1][0](xi);
                EXPECT_NEAR(v12, v21, 1e-5 * std::max(std::fabs(v12), 1e-3 * kimKarrilaFactor(f, radii[c][0])))
                    << pairFunctionName(f) << " a1 " << radii[c][0] << " a2 " << radii[c][1] << " xi " << xi;
            }
        }
    }
}

// Eq. (A.4) in the dimensional form: swapping the spheres swaps 11 <-> 22 and 12 <-> 21, with a sign
// change for B, G, P.
TEST(TwoSphereTheory, SizeRatioInversionRelations)
{
    const PairForms p = makePairForms(1.0, 1.4, false);
    const PairForms q = makePairForms(1.4, 1.0, false);
    for (int f = 0; f < NumPairFunctions; ++f) {
        if (f == XM || f == YM || f == ZM) continue;
        const double sign = (f == YB || f == XG || f == YG || f == XP) ? -1 : 1;
        for (int a = 0; a < 2; ++a)
            for (int b = 0; b < 2; ++b)
                for (double xi = 1e-4; xi < 1; xi *= 10) {
                    const double v = p.f[f][a][b](xi), w = sign * q.f[f][1 - a][1 - b](xi);
                    EXPECT_NEAR(v, w, 1e-12 * std::max(1.0, std::fabs(v))) << pairFunctionName(PairFunction(f)) << a << b;
                }
    }
}

// Newton's third law for the squeeze singularity with unequal radii: the 1/xi and log terms of the
// forces on the two spheres cancel exactly (a 4 a1 a2 vs (a1+a2)^2 slip would show here).
TEST(TwoSphereTheory, SqueezeSingularitiesEqualAndOpposite)
{
    const double radii[][2] = {{1, 1.4}, {1, 0.1}, {0.7, 1.9}};
    for (int c = 0; c < 3; ++c) {
        const PairForms p = makePairForms(radii[c][0], radii[c][1], false);
        // force on 1 + force on 2 when sphere 1 moves along d: (X11A + X21A)
        const double inv = p.f[XA][0][0].inv + p.f[XA][1][0].inv, log = p.f[XA][0][0].log + p.f[XA][1][0].log;
        EXPECT_NEAR(inv, 0, 1e-13 * p.f[XA][0][0].inv);
        EXPECT_NEAR(log, 0, 1e-13 * std::fabs(p.f[XA][0][0].log));
        // shear: Y11A + Y21A has no log singularity
        EXPECT_NEAR(p.f[YA][0][0].log + p.f[YA][1][0].log, 0, 1e-13 * std::fabs(p.f[YA][0][0].log));
    }
}

TEST(TwoSphereTheory, HurwitzZeta)
{
    EXPECT_NEAR(hurwitzZeta3(1.0), 1.2020569031595942854, 1e-13);
    EXPECT_NEAR(hurwitzZeta3(0.5), 7 * 1.2020569031595942854, 1e-12);
}

// Documents how far the near-field forms can be trusted: error against Townsend's full table (Lamb's
// method beyond s' = 2.02), per size ratio.  The asserted bounds are the measured ones rounded up (equal
// spheres, xi <= 0.1); see docs/resistance.md for the table.
TEST(TwoSphereTheory, NearFieldFormsAgainstMidFieldTable)
{
    const std::vector<std::vector<double> > rows =
        reference::readTable("two_sphere_townsend/scalars_general_resistance.txt", 2);
    const double lambdas[] = {1, 0.1, 10};
    const double xiLimits[] = {0.05, 0.1, 0.2, 0.5};
    for (int l = 0; l < 3; ++l) {
        const NearFieldConstants& k = constantsWithM(lambdas[l]);
        for (int L = 0; L < 4; ++L) {
            double worst[NumPairFunctions] = {0};
            for (std::size_t r = 0; r < rows.size(); ++r) {
                const std::vector<double>& row = rows[r];
                const double xi = row[0] - 2;
                if (std::fabs(row[1] - lambdas[l]) > 1e-12 || xi <= 0.02 + 1e-12 || xi > xiLimits[L] + 1e-12) continue;
                for (int f = XA; f <= ZM; ++f) {
                    const double mine = int(row[2]) == 0 ? k.f11[f](xi) : k.f12[f](xi);
                    worst[f] = std::max(worst[f], std::fabs(mine - row[3 + f]) / std::max(std::fabs(row[3 + f]), 1.0));
                }
            }
            std::printf("[validity] lambda %g, xi in (0.02, %.2f]:", lambdas[l], xiLimits[L]);
            for (int f = XA; f <= ZM; ++f) std::printf(" %s %.1e", pairFunctionName(PairFunction(f)), worst[f]);
            std::printf("\n");
            if (l == 0 && L == 1) {
                const double bound[] = {0.01, 0.02, 0.03, 0.02, 0.05, 0.05, 0.05, 0.05};
                for (int f = XA; f <= YH; ++f) EXPECT_LT(worst[f], bound[f]) << pairFunctionName(PairFunction(f));
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Full-range forms (two_sphere.hpp fullRange, docs/resistance.md "Full-range forms").

namespace {

const PairFunction fullRangeFamilies[] = {XA, YA, YB, XC, YC};

// Gap over the smaller radius, h / min(a1, a2), for a1 = 1, a2 = lambda: the scale of the O(xi) terms
// that the near-field asymptotic forms leave out.
double gapOverSmallerRadius(double lambda, double xi) { return 0.5 * (1 + lambda) * xi / std::min(1.0, lambda); }

// Bound against Townsend's table: 1e-3 (relative, absolute below 1) where the table is exact (Lamb's
// method, s' >= 2.025); at s' <= 2.02 the table holds the near-field asymptotic forms, which omit O(xi)
// terms: there the bound is max(1e-3, h/min(a1, a2)).
double tableBound(double lambda, double sDash)
{
    return sDash > 2.02 + 1e-12 ? 1e-3 : std::max(1e-3, gapOverSmallerRadius(lambda, sDash - 2));
}

}  // namespace

// Every tabulated s' (2.00001 .. 4.5) for lambda = 0.1, 1, 10: X^A, Y^A, Y^B, X^C, Y^C, 11 and 12.
TEST(TwoSphereTheory, FullRangeMatchesTownsendTable)
{
    const std::vector<std::vector<double> > rows =
        reference::readTable("two_sphere_townsend/scalars_general_resistance.txt", 2);
    const double lambdas[] = {0.1, 1, 10};
    int compared = 0;
    for (int l = 0; l < 3; ++l) {
        const FullRangeConstants k = computeFullRangeConstants(lambdas[l]);
        double worstLamb[NumPairFunctions] = {0}, worstNear[NumPairFunctions] = {0}, worstNearScaled[NumPairFunctions] = {0};
        int nearAbove = 0;
        for (std::size_t r = 0; r < rows.size(); ++r) {
            const std::vector<double>& row = rows[r];
            if (std::fabs(row[1] - lambdas[l]) > 1e-12) continue;
            const double sDash = row[0], xi = sDash - 2;
            const bool twelve = int(row[2]) == 1;
            for (int i = 0; i < 5; ++i) {
                const PairFunction f = fullRangeFamilies[i];
                const double mine = fullRangeScalar(k, f, twelve, xi), ref = row[3 + f];
                const double error = std::fabs(mine - ref) / std::max(std::fabs(ref), 1.0);
                EXPECT_LT(error, tableBound(lambdas[l], sDash)) << pairFunctionName(f) << (twelve ? "12" : "11") << " lambda "
                                                                << lambdas[l] << " s' " << sDash << ": " << mine << " vs " << ref;
                if (sDash > 2.02 + 1e-12)
                    worstLamb[f] = std::max(worstLamb[f], error);
                else {
                    worstNear[f] = std::max(worstNear[f], error);
                    worstNearScaled[f] = std::max(worstNearScaled[f], error / gapOverSmallerRadius(lambdas[l], xi));
                    if (error > 1e-3) ++nearAbove;
                }
                ++compared;
            }
        }
        std::printf("[worst] full range vs Townsend, lambda %g, s' >= 2.025 (Lamb):", lambdas[l]);
        for (int i = 0; i < 5; ++i) std::printf(" %s %.1e", pairFunctionName(fullRangeFamilies[i]), worstLamb[fullRangeFamilies[i]]);
        std::printf("\n[worst] full range vs Townsend, lambda %g, s' <= 2.02 (asymptotic forms):", lambdas[l]);
        for (int i = 0; i < 5; ++i)
            std::printf(" %s %.1e (%.2f h/a_min)", pairFunctionName(fullRangeFamilies[i]), worstNear[fullRangeFamilies[i]],
                        worstNearScaled[fullRangeFamilies[i]]);
        std::printf("; %d of 110 above 1e-3\n", nearAbove);
    }
    EXPECT_EQ(compared, 3 * 38 * 2 * 5);
}

// The stresslet functions X^G, Y^G, Y^H matched the same way (full_range_forms.cpp): every tabulated s' for
// lambda = 0.1, 1, 10, 11 and 12, within the same bounds, and continuous with the near-field forms at contact.
TEST(TwoSphereTheory, FullRangeStressletMatchesTownsendTable)
{
    const std::vector<std::vector<double> > rows =
        reference::readTable("two_sphere_townsend/scalars_general_resistance.txt", 2);
    const PairFunction stresslet[] = {XG, YG, YH};
    const double lambdas[] = {0.1, 1, 10};
    int compared = 0;
    for (int l = 0; l < 3; ++l) {
        const FullRangeConstants k = computeFullRangeConstants(lambdas[l]);
        double worstLamb[NumPairFunctions] = {0}, worstNear[NumPairFunctions] = {0};
        for (std::size_t r = 0; r < rows.size(); ++r) {
            const std::vector<double>& row = rows[r];
            if (std::fabs(row[1] - lambdas[l]) > 1e-12) continue;
            const double sDash = row[0], xi = sDash - 2;
            const bool twelve = int(row[2]) == 1;
            for (PairFunction f : stresslet) {
                const double mine = fullRangeScalar(k, f, twelve, xi), ref = row[3 + f];
                const double error = std::fabs(mine - ref) / std::max(std::fabs(ref), 1.0);
                EXPECT_LT(error, tableBound(lambdas[l], sDash)) << pairFunctionName(f) << (twelve ? "12" : "11") << " lambda "
                                                                << lambdas[l] << " s' " << sDash << ": " << mine << " vs " << ref;
                double& worst = sDash > 2.02 + 1e-12 ? worstLamb[f] : worstNear[f];
                worst = std::max(worst, error);
                ++compared;
            }
        }
        std::printf("[worst] full-range stresslet vs Townsend, lambda %g: Lamb (s' >= 2.025) X^G %.1e Y^G %.1e Y^H %.1e; "
                    "asymptotic (s' <= 2.02) %.1e %.1e %.1e\n", lambdas[l], worstLamb[XG], worstLamb[YG], worstLamb[YH],
                    worstNear[XG], worstNear[YG], worstNear[YH]);
    }
    EXPECT_EQ(compared, 3 * 38 * 2 * 3);
    // near contact the matched form is the near-field form (same singular terms and constant)
    const double lambda = 1.4;
    const FullRangeConstants k = computeFullRangeConstants(lambda);
    const NearFieldConstants near = computeNearFieldConstants(lambda, false);
    for (PairFunction f : stresslet)
        for (int twelve = 0; twelve < 2; ++twelve) {
            const double xi = 1e-6, L = std::log(1 / xi);
            const NearFieldForm& n = twelve ? near.f12[f] : near.f11[f];
            EXPECT_NEAR(fullRangeScalar(k, f, twelve != 0, xi), n(xi, L), 1e-4 * std::max(1.0, std::fabs(n(xi, L))))
                << pairFunctionName(f) << (twelve ? "12" : "11");
        }
}

// Eq. (A.4) through the pair machinery: the 21 and 22 functions of (1, 10) are Townsend's 12 and 11 at
// lambda = 0.1 (in a2 units, minus sign for Y^B), and those of (1, 0.1) his lambda = 10 rows.
TEST(TwoSphereTheory, FullRangeSwappedFunctionsMatchTownsendAtInverseLambda)
{
    const std::vector<std::vector<double> > rows =
        reference::readTable("two_sphere_townsend/scalars_general_resistance.txt", 2);
    const double radii[][2] = {{1, 10}, {1, 0.1}};
    int compared = 0;
    double worstLamb = 0;
    for (int c = 0; c < 2; ++c) {
        const double a1 = radii[c][0], a2 = radii[c][1], inverse = a1 / a2;
        const PairFullRangeForms forms = makeFullRangeForms(a1, a2);
        for (std::size_t r = 0; r < rows.size(); ++r) {
            const std::vector<double>& row = rows[r];
            if (std::fabs(row[1] - inverse) > 1e-12) continue;
            const double xi = row[0] - 2;
            const int gamma = int(row[2]);
            const PairFunctionValues v = fullRange(forms, xi);
            for (int i = 0; i < 5; ++i) {
                const PairFunction f = fullRangeFamilies[i];
                const double sign = (f == YB) ? -1 : 1;
                const double mine = sign * v.f[f][1][gamma == 0 ? 1 : 0] / kimKarrilaFactor(f, a2);
                const double error = std::fabs(mine - row[3 + f]) / std::max(std::fabs(row[3 + f]), 1.0);
                EXPECT_LT(error, tableBound(inverse, row[0])) << pairFunctionName(f) << " gamma " << gamma << " a2 " << a2 << " xi " << xi;
                if (row[0] > 2.02 + 1e-12) worstLamb = std::max(worstLamb, error);
                ++compared;
            }
        }
    }
    EXPECT_EQ(compared, 2 * 38 * 2 * 5);
    std::printf("[worst] full range 21, 22 vs Townsend at 1/lambda, s' >= 2.025: %.1e\n", worstLamb);
}

// Eq. (A.3): the dimensional 12 and 21 functions come from different series (lambda and 1/lambda) and
// must agree; Eq. (A.4): swapping the spheres swaps 11 <-> 22 and 12 <-> 21 (minus sign for Y^B).
TEST(TwoSphereTheory, FullRangeReciprocityAndSizeRatioInversion)
{
    const double radii[][2] = {{1, 1.4}, {1.4, 1}, {1, 0.1}, {0.5, 2}, {1, 7.3}};
    const PairFunction symmetric[] = {XA, YA, XC, YC};
    double worst = 0;
    for (int c = 0; c < 5; ++c) {
        const double a1 = radii[c][0], a2 = radii[c][1];
        const PairFullRangeForms p = makeFullRangeForms(a1, a2), q = makeFullRangeForms(a2, a1);
        for (double xi = 1e-5; xi < 20; xi *= 3) {
            const PairFunctionValues v = fullRange(p, xi), w = fullRange(q, xi);
            for (int i = 0; i < 4; ++i) {
                const PairFunction f = symmetric[i];
                const double v12 = v.f[f][0][1], v21 = v.f[f][1][0];
                const double scale = std::max(std::fabs(v12), 1e-3 * kimKarrilaFactor(f, std::min(a1, a2)));
                worst = std::max(worst, std::fabs(v12 - v21) / scale);
                EXPECT_NEAR(v12, v21, 1e-10 * scale) << pairFunctionName(f) << " a1 " << a1 << " a2 " << a2 << " xi " << xi;
            }
            for (int i = 0; i < 5; ++i) {
                const PairFunction f = fullRangeFamilies[i];
                const double sign = (f == YB) ? -1 : 1;
                for (int a = 0; a < 2; ++a)
                    for (int b = 0; b < 2; ++b)
                        EXPECT_NEAR(v.f[f][a][b], sign * w.f[f][1 - a][1 - b], 1e-12 * std::max(1.0, std::fabs(v.f[f][a][b])))
                            << pairFunctionName(f) << a << b << " xi " << xi;
            }
        }
    }
    std::printf("[worst] full range reciprocity |f12 - f21| (A.3): %.1e relative\n", worst);
}

// The two limits of the matched forms.  Near contact: the full-range form minus the near-field form is
// the O(xi) part the latter omits (plus the truncation of the sums, the same at order 100 as in the
// near-field constants).  Far away (s' >= 10): the subtracted singular functions S1-S3 cancel exactly and
// what remains is the plain far-field series (J&O (3.13)-(3.14) and analogues), summed here from
// farFieldCoefficient.  The other families are untouched (near-field forms).
TEST(TwoSphereTheory, FullRangeTendsToNearFieldAndFarFieldForms)
{
    const double lambdas[] = {1, 1.4, 1 / 1.4, 0.1, 10};
    double worstNear = 0, worstFar = 0;
    for (int l = 0; l < 5; ++l) {
        const double lambda = lambdas[l];
        const FullRangeConstants k = computeFullRangeConstants(lambda);
        const NearFieldConstants n = computeNearFieldConstants(lambda, false);
        for (double xi = 1e-5; xi <= 1e-3; xi *= 10)
            for (int i = 0; i < 5; ++i)
                for (int g = 0; g < 2; ++g) {
                    const PairFunction f = fullRangeFamilies[i];
                    const double full = fullRangeScalar(k, f, g == 1, xi), near = g ? n.f12[f](xi) : n.f11[f](xi);
                    const double error = std::fabs(full - near) / std::max(std::fabs(near), 1.0);
                    worstNear = std::max(worstNear, error);
                    EXPECT_LT(error, 1e-5 + 2 * gapOverSmallerRadius(lambda, xi)) << pairFunctionName(f) << g << " lambda " << lambda << " xi " << xi;
                }
        // far field: X11A = sum_even a_m t^m, X12A = -sum_odd, Y^A likewise, Y11B = sum_odd, Y12B = -sum_even,
        // Y11C = sum_even, Y12C = +sum_odd, a_m = f_m / (2 (1 + lambda))^m, t = 2/s'
        const PairFunction series[] = {XA, YA, YB, YC};
        const bool oddFor11[] = {false, false, true, false};
        const double signFor12[] = {-1, -1, -1, 1};
        for (double sDash = 10; sDash < 1000; sDash *= 3) {
            const double t = 2 / sDash;
            for (int i = 0; i < 4; ++i) {
                double even = 0, odd = 0;
                for (int m = 0; m <= 60; ++m) {
                    const double term = farFieldCoefficient(series[i], m, lambda) / std::pow(2 * (1 + lambda), m) * std::pow(t, m);
                    (m % 2 ? odd : even) += term;
                }
                const double ref11 = oddFor11[i] ? odd : even, ref12 = signFor12[i] * (oddFor11[i] ? even : odd);
                const double v11 = fullRangeScalar(k, series[i], false, sDash - 2), v12 = fullRangeScalar(k, series[i], true, sDash - 2);
                worstFar = std::max(worstFar, std::max(std::fabs(v11 - ref11), std::fabs(v12 - ref12)));
                EXPECT_NEAR(v11, ref11, 1e-12) << pairFunctionName(series[i]) << "11 lambda " << lambda << " s' " << sDash;
                EXPECT_NEAR(v12, ref12, 1e-12) << pairFunctionName(series[i]) << "12 lambda " << lambda << " s' " << sDash;
            }
        }
    }
    // the families without a full-range form keep the near-field values
    const PairFullRangeForms p = makeFullRangeForms(1, 1.4);
    for (double xi = 1e-4; xi < 5; xi *= 10) {
        const PairFunctionValues v = fullRange(p, xi), w = evaluate(p.nearField, xi);
        for (int f = 0; f < NumPairFunctions; ++f)
            if (!hasFullRangeForm(PairFunction(f)))
                for (int a = 0; a < 2; ++a)
                    for (int b = 0; b < 2; ++b) EXPECT_EQ(v.f[f][a][b], w.f[f][a][b]) << pairFunctionName(PairFunction(f));
    }
    std::printf("[worst] full range vs near-field forms (xi <= 1e-3): %.1e; vs plain far-field series (s' >= 10): %.1e absolute\n",
                worstNear, worstFar);
}

// X^C: the exact series (Jeffery 1915) against two limits of its own: the closed-form contact values of
// J&O (6.9)-(6.10) (zeta functions), and a small sphere near a very large one, which is the sphere-wall
// rotation of wallNormalRotation (Jeffery's wall series, gap over the small radius eps = (1+lambda) xi/2).
TEST(TwoSphereTheory, ExactRotationAboutLineOfCentresLimits)
{
    const double lambdas[] = {0.1, 1, 1.4, 10};
    for (int l = 0; l < 4; ++l) {
        const NearFieldConstants n = computeNearFieldConstants(lambdas[l], false);
        double x11, x12;
        exactRotationAboutLineOfCentres(lambdas[l], 1e-9, x11, x12);
        EXPECT_NEAR(x11, n.f11[XC].c0, 1e-6 * n.f11[XC].c0) << lambdas[l];
        EXPECT_NEAR(x12, n.f12[XC].c0, 1e-6 * std::fabs(n.f12[XC].c0)) << lambdas[l];
    }
    const double big = 1e7;
    for (double eps = 1e-3; eps < 10; eps *= 4) {
        double x11, x12;
        exactRotationAboutLineOfCentres(big, 2 * eps / (1 + big), x11, x12);
        EXPECT_NEAR(x11, wallNormalRotation(eps), 1e-5 * wallNormalRotation(eps)) << "eps " << eps;
    }
}

// Truncation of the far-field sums: order 100 (default) against 150, over the whole range of gaps.
TEST(TwoSphereTheory, FullRangeConvergedInOrder)
{
    const double lambdas[] = {1, 1.4, 0.1, 10};
    double worst[4] = {0};
    for (int l = 0; l < 4; ++l) {
        const FullRangeConstants k100 = computeFullRangeConstants(lambdas[l], 100);
        const FullRangeConstants k150 = computeFullRangeConstants(lambdas[l], 150);
        for (double xi = 1e-5; xi < 10; xi *= 1.5)
            for (int i = 0; i < 5; ++i)
                for (int g = 0; g < 2; ++g) {
                    const PairFunction f = fullRangeFamilies[i];
                    const double a = fullRangeScalar(k100, f, g == 1, xi), b = fullRangeScalar(k150, f, g == 1, xi);
                    worst[l] = std::max(worst[l], std::fabs(a - b) / std::max(std::fabs(b), 1.0));
                }
        EXPECT_LT(worst[l], 5e-4) << "lambda " << lambdas[l];
        std::printf("[convergence] full range, lambda %g: |order 100 - order 150| <= %.1e\n", lambdas[l], worst[l]);
    }
}

// The three entry points give the same values: fullRange(PairFullRangeForms), the convenience
// fullRange(PairForms) and the cached TwoSphereTheory::fullValues; values() keeps the near-field forms.
TEST(TwoSphereTheory, FullRangeEntryPointsAgree)
{
    TwoSphereTheory theory;
    const PairFullRangeForms p = makeFullRangeForms(1, 1.4);
    const PairForms near = makePairForms(1, 1.4);
    for (double xi = 1e-6; xi < 10; xi *= 7) {
        const PairFunctionValues a = fullRange(p, xi), b = fullRange(near, xi), c = theory.fullValues(1, 1.4, xi);
        const PairFunctionValues d = theory.values(1, 1.4, xi), e = evaluate(near, xi);
        for (int f = 0; f < NumPairFunctions; ++f)
            for (int i = 0; i < 2; ++i)
                for (int j = 0; j < 2; ++j) {
                    EXPECT_EQ(a.f[f][i][j], b.f[f][i][j]);
                    EXPECT_EQ(a.f[f][i][j], c.f[f][i][j]);
                    EXPECT_EQ(d.f[f][i][j], e.f[f][i][j]);
                }
    }
    EXPECT_EQ(theory.cachedPairs(), 1u);
}
