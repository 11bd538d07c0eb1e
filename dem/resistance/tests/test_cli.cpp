// The command-line tool prints JSON with a normalisation field and rejects bad input.
#include "fdm/resistance/resistance.hpp"
#include "fdm/resistance/subgrid_calibration.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <sys/wait.h>

namespace {
struct Result {
    int status;
    std::string output;
};
Result run(const std::string& arguments)
{
    const std::string command = std::string(FDM_RESISTANCE_TOOL) + " " + arguments + " 2>&1";
    FILE* pipe = popen(command.c_str(), "r");
    Result r = {-1, ""};
    if (!pipe) return r;
    char buffer[4096];
    std::size_t n;
    while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0) r.output.append(buffer, n);
    const int status = pclose(pipe);
    r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}
// The number after "key": in the tool's JSON (NaN if absent).
double field(const std::string& json, const std::string& key)
{
    const std::string tag = "\"" + key + "\": ";
    const std::size_t at = json.find(tag);
    if (at == std::string::npos) return std::nan("");
    return std::strtod(json.c_str() + at + tag.size(), nullptr);
}
double squeeze(const std::string& arguments)
{
    const Result r = run("squeeze " + arguments);
    EXPECT_EQ(r.status, 0) << arguments << ": " << r.output;
    return field(r.output, "closing_velocity_normalised");
}
}  // namespace

TEST(Cli, PairTheoryPrintsEveryFunction)
{
    const Result r = run("pair --a1 1 --a2 1 --xi 1e-5 --theory");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("\"normalisation\""), std::string::npos);
    EXPECT_NE(r.output.find("\"XA11\": 25003.5858"), std::string::npos) << r.output;
    for (const char* f : {"YA21", "YB22", "XC12", "YC11", "XG21", "YG12", "YH22", "XM11", "YM12", "ZM21", "XP12"})
        EXPECT_NE(r.output.find(std::string("\"") + f + "\""), std::string::npos) << f;
}

// X^Q (pressure moment from the strain) is printed with the theory, as the library gives it in both units
// (Kim-Karrila: 6 pi a^3), and not with the sub-grid functions (the paper drops the strain columns, Eq. 21).
TEST(Cli, PairTheoryPrintsPressureMomentQ)
{
    const Result r = run("pair --a1 1 --a2 1.4 --xi 0.02 --theory");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("6 pi a1^3 (Q)"), std::string::npos);
    const std::string kimKarrila = r.output.substr(0, r.output.find("\"dimensional_over_eta\""));
    const std::string dimensional = r.output.substr(r.output.find("\"dimensional_over_eta\""));
    const fdm::resistance::PairForms forms = fdm::resistance::makePairForms(1, 1.4, true);
    const fdm::resistance::PairFunctionValues v = fdm::resistance::evaluate(forms, 0.02);
    const char* index[2][2] = {{"11", "12"}, {"21", "22"}};
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) {
            const std::string key = std::string("XQ") + index[a][b];
            const double value = v.f[fdm::resistance::XQ][a][b];
            EXPECT_GT(value, 0) << key;  // strain along d pulls the gap open: s > 0 on both spheres
            EXPECT_NEAR(field(dimensional, key), value, 1e-12 * std::fabs(value)) << key;
            const double kk = value / (6 * M_PI * std::pow(a == 0 ? 1.0 : 1.4, 3));
            EXPECT_NEAR(field(kimKarrila, key), kk, 1e-12 * std::fabs(kk)) << key;
        }
    const Result sub = run("pair --a1 1 --a2 1.4 --xi 0.02 --subgrid --delta 0.1");
    ASSERT_EQ(sub.status, 0) << sub.output;
    EXPECT_EQ(sub.output.find("\"XQ11\""), std::string::npos);
}

TEST(Cli, PairSubgridMatrixAndWall)
{
    Result r = run("pair --a1 1 --a2 1.4 --xi 0.01 --subgrid --delta 0.1");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("\"X21A\""), std::string::npos);
    EXPECT_NE(r.output.find("\"xi_cut\""), std::string::npos);
    r = run("matrix --x1 0 0 0 --x2 2.01 0 0 --a1 1 --a2 1 --delta 0.1 --eta 2");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("\"R\""), std::string::npos);
    EXPECT_NE(r.output.find("\"stress_rows\""), std::string::npos);
    EXPECT_NE(r.output.find("\"normalisation\""), std::string::npos);
    r = run("wall --a 1 --eps 0.001 --delta 0.1");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("\"XA\": 1002.35"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("\"subgrid_dimensional_over_eta\""), std::string::npos);
}

// --calibrated: the sub-grid model pair_style fdm/subgrid builds by default (the shipped table, the other
// functions from the cut-off model at the pair style's cut-offs), so a user sees what a run applies
TEST(Cli, CalibratedIsThePairStylesDefaultModel)
{
    namespace res = fdm::resistance;
    const double delta = 1.0 / 3, xi = 0.3, a2 = 1.4, r = 0.5 * (1 + a2) * (2 + xi);
    const res::SubgridCalibration table = res::SubgridCalibration::read(res::SubgridCalibration::defaultPath());
    const res::CalibratedSubgridModel model(table, delta, res::defaultPairCutoffCells, res::defaultWallCutoffCells);
    Result out = run("pair --a1 1 --a2 1.4 --xi 0.3 --subgrid --calibrated --delta 0.33333333333333333");
    ASSERT_EQ(out.status, 0) << out.output;
    const res::PairSubgridBase base = model.pair(1, a2, xi);
    EXPECT_LT(base.f[res::BaseX21A], 0);  // beyond the cut-off model's range, the calibrated squeeze acts
    EXPECT_NEAR(field(out.output, "X21A"), base.f[res::BaseX21A], 1e-12 * std::fabs(base.f[res::BaseX21A]));
    const double xg = res::subgridPairFunctions(model, 1, a2, xi, r).f[res::XG][0][0];
    EXPECT_NEAR(field(out.output, "XG11"), xg, 1e-12 * std::fabs(xg));
    out = run("wall --a 1 --eps 0.3 --delta 0.33333333333333333 --calibrated");
    ASSERT_EQ(out.status, 0) << out.output;
    const std::string subgrid = out.output.substr(out.output.find("\"subgrid_dimensional_over_eta\""));
    const double ya = model.wall(1, 0.3).f[res::WallYA];
    EXPECT_NE(ya, 0);
    EXPECT_NEAR(field(subgrid, "YA"), ya, 1e-12 * std::fabs(ya));
    EXPECT_EQ(run("pair --a1 1 --a2 1 --xi 0.3 --calibrated").status, 2);                     // needs --subgrid
    EXPECT_EQ(run("matrix --x1 0 0 0 --x2 2.3 0 0 --a1 1 --a2 1 --calibrated").status, 2);    // needs --delta
    EXPECT_EQ(run("wall --a 1 --eps 0.1 --calibrated").status, 2);                           // needs --delta
    out = run("pair --a1 1 --a2 1 --xi 0.3 --subgrid --calibrated --delta 0.5");             // a/Delta 2: no table
    EXPECT_EQ(out.status, 2);
    EXPECT_NE(out.output.find("no calibration for a pair of radii 1 and 1"), std::string::npos) << out.output;
}

// the pair style's default cut-offs, which scripts read here rather than repeat (fdmsubgrid.theory)
TEST(Cli, DefaultsAreThePairStylesCutoffs)
{
    const Result out = run("defaults");
    ASSERT_EQ(out.status, 0) << out.output;
    EXPECT_EQ(field(out.output, "pair_cutoff_cells"), fdm::resistance::defaultPairCutoffCells);
    EXPECT_EQ(field(out.output, "wall_cutoff_cells"), fdm::resistance::defaultWallCutoffCells);
}

TEST(Cli, RejectsBadInput)
{
    EXPECT_EQ(run("pair --a1 -1 --a2 1 --xi 0.1").status, 2);
    EXPECT_EQ(run("pair --a1 1 --a2 1").status, 2);
    EXPECT_EQ(run("matrix --x1 0 0 --a1 1").status, 2);
    EXPECT_EQ(run("wall --a 1 --eps abc").status, 2);
    EXPECT_EQ(run("frobnicate").status, 2);
    EXPECT_EQ(run("pair --a1 1 --a2 1 --xi 0.1 --subgrid").status, 2);  // --delta required
    EXPECT_EQ(run("pair --a1 1 --a2 1 --xi 0.1 --subgrid --delta 0.1 --full").status, 2);
    EXPECT_EQ(run("pair --a1 1 --a2 1 --xi 0.1 --theory --order 120").status, 2);  // --order needs --full
    EXPECT_EQ(run("pair --a1 1 --a2 1 --xi 0.1 --theory --full --order 5").status, 2);
    EXPECT_EQ(run("squeeze --a1 1 --a2 1").status, 2);
    EXPECT_EQ(run("squeeze --a1 1 --a2 0 --xi 0.1").status, 2);
    EXPECT_EQ(run("squeeze --a 1 --eps 0.1").status, 2);              // --wall missing
    EXPECT_EQ(run("squeeze --a 1 --eps 0.1 --wall --near").status, 2);
    EXPECT_EQ(run("squeeze --a1 1 --a2 1 --xi 0.1 --near --order 150").status, 2);
}

// pair --theory --full: same layout, full-range values.  Townsend's table (tests/data/two_sphere_townsend):
// lambda = 1, s' = 3: XA11 = 1.36847960 (Lamb's method, where the near-field form is 3 % off).
TEST(Cli, PairTheoryFullPrintsFullRangeValues)
{
    const Result r = run("pair --a1 1 --a2 1 --xi 1 --theory --full");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("\"normalisation\""), std::string::npos);
    EXPECT_NE(r.output.find("\"full_range_functions\""), std::string::npos);
    EXPECT_NEAR(field(r.output, "XA11"), 1.36847960, 1e-6) << r.output;
    for (const char* f : {"XA22", "YA21", "YB22", "XC12", "YC11", "XG21", "YG12", "YH22", "XM11", "YM12", "ZM21", "XP12"})
        EXPECT_FALSE(std::isnan(field(r.output, f))) << f;
    // unequal spheres: every full-range value (11, 12, 21, 22) as the library gives it, in both units
    const Result full = run("pair --a1 1 --a2 1.4 --xi 0.03 --theory --full");
    ASSERT_EQ(full.status, 0) << full.output;
    const std::string kimKarrila = full.output.substr(0, full.output.find("\"dimensional_over_eta\""));
    const std::string dimensional = full.output.substr(full.output.find("\"dimensional_over_eta\""));
    const fdm::resistance::PairFunctionValues v = fdm::resistance::fullRange(fdm::resistance::makeFullRangeForms(1, 1.4), 0.03);
    const char* index[2][2] = {{"11", "12"}, {"21", "22"}};
    for (int f = 0; f < fdm::resistance::NumPairFunctions; ++f) {
        const fdm::resistance::PairFunction family = fdm::resistance::PairFunction(f);
        if (!fdm::resistance::hasFullRangeForm(family)) continue;
        for (int a = 0; a < 2; ++a)
            for (int b = 0; b < 2; ++b) {
                const std::string key = std::string(fdm::resistance::pairFunctionName(family)) + index[a][b];
                EXPECT_NEAR(field(dimensional, key), v.f[f][a][b], 1e-12 * std::max(1.0, std::fabs(v.f[f][a][b]))) << key;
                const double kk = v.f[f][a][b] / fdm::resistance::kimKarrilaFactor(family, a == 0 ? 1.0 : 1.4);
                EXPECT_NEAR(field(kimKarrila, key), kk, 1e-12 * std::max(1.0, std::fabs(kk))) << key;
            }
    }
    // size ratios beyond 0.1..10 are flagged (the far-field sums are not converged there)
    EXPECT_NE(run("squeeze --a1 1 --a2 100 --xi 0.1").output.find("\"warning\""), std::string::npos);
    EXPECT_EQ(run("squeeze --a1 1 --a2 10 --xi 0.1").output.find("\"warning\""), std::string::npos);
}

// Squeeze near contact.  With the two leading terms of X^A (J&O (3.16)), g1 = 2 lambda^2/(1+lambda)^3 and
// g2 = lambda (1 + 7 lambda + lambda^2)/(5 (1+lambda)^3), the squeeze force is
// F = 6 pi eta a1 (g1/xi + g2 ln(1/xi)) V + O(1) U: V / (F/(6 pi eta a1)) = 1/(g1/xi + g2 ln(1/xi)) (1 + O(xi)),
// whose leading order is the printed lubrication_leading_order xi/g1.
TEST(Cli, SqueezeTendsToLubricationLimit)
{
    const double lambdas[] = {1, 1.4, 0.5};
    for (int l = 0; l < 3; ++l) {
        const double lambda = lambdas[l], l1 = 1 + lambda;
        const double g1 = 2 * lambda * lambda / (l1 * l1 * l1), g2 = lambda * (1 + 7 * lambda + lambda * lambda) / (5 * l1 * l1 * l1);
        for (double xi = 1e-5; xi < 2e-3; xi *= 10) {
            char arguments[128];
            std::snprintf(arguments, sizeof arguments, "--a1 1 --a2 %.17g --xi %.17g", lambda, xi);
            const Result r = run(std::string("squeeze ") + arguments);
            ASSERT_EQ(r.status, 0) << r.output;
            const double v = field(r.output, "closing_velocity_normalised");
            EXPECT_NEAR(field(r.output, "lubrication_leading_order"), xi / g1, 1e-12 * xi / g1);
            EXPECT_NEAR(v * (g1 / xi + g2 * std::log(1 / xi)), 1, 5 * xi) << arguments;
            EXPECT_NEAR(v / (xi / g1), 1, 2 * (g2 / g1) * xi * std::log(1 / xi)) << arguments;
            // the near-field forms give the same closing velocity there
            EXPECT_NEAR(squeeze(std::string(arguments) + " --near"), v, 5 * xi * v) << arguments;
        }
    }
}

// Squeeze far apart, equal spheres: the two-sphere mobility (Batchelor, J. Fluid Mech. 74 (1976) 1),
// x11a = 1 - 15/(4 r^4) + O(r^-6), x12a = 3/(2 r) - 1/r^3 + O(r^-7) (r in radii): under +F and -F,
// V = 2 (x11a - x12a) F/(6 pi eta a).  The difference must fall like r^-6.
TEST(Cli, SqueezeFarFieldMatchesTwoSphereMobility)
{
    for (double xi = 8; xi < 100; xi = 2 * xi + 2) {
        char arguments[128];
        std::snprintf(arguments, sizeof arguments, "--a1 1 --a2 1 --xi %.17g", xi);
        const double r = 2 + xi, r3 = r * r * r;
        const double farField = 2 * (1 - 15 / (4 * r3 * r) - 1.5 / r + 1 / r3);
        EXPECT_NEAR(squeeze(arguments), farField, 10 / (r3 * r3) * farField) << arguments;
    }
    // the near-field forms are not meant for this: they must differ visibly (documents --near)
    EXPECT_GT(std::fabs(squeeze("--a1 1 --a2 1 --xi 1 --near") - squeeze("--a1 1 --a2 1 --xi 1")), 0.05);
}

// Sphere toward a wall: 1/X^A_wall.  Near contact V/(F/(6 pi eta a)) = eps (1 + O(eps ln eps)) (Cox & Brenner
// 1967); far away the method-of-reflections series 1 - 9/(8h) + 1/(2h^3) - 57/(100h^4) + 1/(5h^5) + 7/(200h^11)
// - 1/(25h^12) (h = 1 + eps, in radii; Happel & Brenner), whose first omitted terms are below 1e-6 at h >= 10.
TEST(Cli, SqueezeTowardWall)
{
    for (double eps = 1e-5; eps < 2e-3; eps *= 10) {
        char arguments[128];
        std::snprintf(arguments, sizeof arguments, "--a 1 --eps %.17g --wall", eps);
        EXPECT_NEAR(squeeze(arguments) / eps, 1, eps * (0.2 * std::log(1 / eps) + 1)) << arguments;
    }
    for (double h = 10; h < 50; h *= 2) {
        char arguments[128];
        std::snprintf(arguments, sizeof arguments, "--a 2 --eps %.17g --wall", h - 1);
        const double reflections = 1 - 9 / (8 * h) + 1 / (2 * h * h * h) - 57 / (100 * std::pow(h, 4)) + 1 / (5 * std::pow(h, 5)) +
                                   7 / (200 * std::pow(h, 11)) - 1 / (25 * std::pow(h, 12));
        EXPECT_NEAR(squeeze(arguments), reflections, 1e-5) << arguments;
    }
    const Result r = run("squeeze --a 1 --eps 0.001 --wall");
    EXPECT_NEAR(field(r.output, "XA_kim_karrila"), 1002.35, 0.01) << r.output;  // Fzt at h/a = 1.001, tests/data/sphere_wall/WallSphereResTab.csv
}
