// fdmResistance: prints resistance functions and blocks as JSON (docs/resistance.md, "Command line").
//   fdmResistance pair    --a1 A --a2 B --xi X [--theory [--full [--order N]]|--subgrid [--calibrated]] [--delta D] [--cutoff K]
//   fdmResistance matrix  --x1 x y z --x2 x y z --a1 A --a2 B [--delta D [--calibrated]] [--eta E] [--cutoff K]
//   fdmResistance wall    --a A --eps E [--delta D [--calibrated]] [--cutoff K]
//   fdmResistance squeeze --a1 A --a2 B --xi X [--near] [--order N]
//   fdmResistance squeeze --a A --eps E --wall
//   fdmResistance coverage --a1 A [--a2 B] --delta D [--wall]
//   fdmResistance defaults
#include "fdm/resistance/resistance.hpp"
#include "fdm/resistance/subgrid_calibration.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

using namespace fdm::resistance;

namespace {

const char* usage =
    "usage:\n"
    "  fdmResistance pair    --a1 A --a2 B --xi X [--theory [--full [--order N]]|--subgrid [--calibrated]] [--delta D] [--cutoff K]\n"
    "  fdmResistance matrix  --x1 x y z --x2 x y z --a1 A --a2 B [--delta D [--calibrated]] [--eta E] [--cutoff K]\n"
    "  fdmResistance wall    --a A --eps E [--delta D [--calibrated]] [--cutoff K]\n"
    "  fdmResistance squeeze --a1 A --a2 B --xi X [--near] [--order N]\n"
    "  fdmResistance squeeze --a A --eps E --wall\n"
    "  fdmResistance coverage --a1 A [--a2 B] --delta D [--wall]\n"
    "  fdmResistance defaults\n"
    "xi = 2r/(a1+a2) - 2; eps = h/a - 1; --delta: mesh size (sub-grid output); --cutoff: k in xi_c = k*delta/a_mean\n"
    "  (cut-off model, default 1); --calibrated: the sub-grid model pair_style fdm/subgrid uses by default (the shipped\n"
    "  calibration table, the other functions from the cut-off model at the pair style's cut-offs, 0.65 and 0.75 cells)\n"
    "--full: full-range X^A, Y^A, Y^B, X^C, Y^C, X^G, Y^G, Y^H (matched forms, every gap); --order: far-field powers kept (default 100)\n"
    "squeeze: closing velocity under equal and opposite forces F along the line of centres, in units of F/(6 pi eta a1)\n"
    "  (full-range theory; --near: near-field forms); --wall: sphere pushed toward a plane wall, 1/X^A_wall\n"
    "coverage: whether the shipped calibration table (pair_style fdm/subgrid model calibrated) has the pair (a1, a2)\n"
    "  and, with --wall, the sphere a1 against a wall at mesh size D\n"
    "defaults: pair_style fdm/subgrid's default cut-offs (mesh cells) and the calibration table it reads\n";

struct Arguments {
    std::string command;
    std::map<std::string, std::vector<double> > values;
    std::map<std::string, bool> flags;

    bool has(const std::string& k) const { return values.count(k) > 0; }
    double number(const std::string& k) const
    {
        std::map<std::string, std::vector<double> >::const_iterator it = values.find(k);
        if (it == values.end()) throw std::runtime_error("missing --" + k);
        return it->second.at(0);
    }
    double number(const std::string& k, double fallback) const { return has(k) ? number(k) : fallback; }
    void vector3(const std::string& k, double v[3]) const
    {
        std::map<std::string, std::vector<double> >::const_iterator it = values.find(k);
        if (it == values.end() || it->second.size() != 3) throw std::runtime_error("--" + k + " needs three numbers");
        for (int i = 0; i < 3; ++i) v[i] = it->second[i];
    }
};

double parseNumber(const std::string& text)
{
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (end == text.c_str() || *end != '\0' || !std::isfinite(v)) throw std::runtime_error("not a number: '" + text + "'");
    return v;
}

Arguments parse(int argc, char** argv)
{
    if (argc < 2) throw std::runtime_error("no command");
    Arguments a;
    a.command = argv[1];
    const int vectorOptions = 3;
    for (int i = 2; i < argc; ++i) {
        std::string key = argv[i];
        if (key.compare(0, 2, "--") != 0) throw std::runtime_error("unexpected argument '" + key + "'");
        key = key.substr(2);
        if (key == "theory" || key == "subgrid" || key == "full" || key == "near" || key == "wall" ||
            key == "calibrated") {
            a.flags[key] = true;
            continue;
        }
        const int count = (key == "x1" || key == "x2") ? vectorOptions : 1;
        std::vector<double> v;
        for (int c = 0; c < count; ++c) {
            if (i + 1 >= argc) throw std::runtime_error("--" + key + " needs a value");
            v.push_back(parseNumber(argv[++i]));
        }
        a.values[key] = v;
    }
    return a;
}

void positive(double v, const char* name)
{
    if (!(v > 0)) throw std::runtime_error(std::string(name) + " must be positive");
}

// The sub-grid model the options ask for: the cut-off model at --cutoff cells (default 1), or with
// --calibrated the one pair_style fdm/subgrid builds by default (the shipped table; its functions that the
// table lacks from the cut-off model at the pair style's cut-offs, 0.65 cells for pairs and 0.75 for walls;
// --cutoff replaces the one the command is about: the wall's for `wall`, the pair's otherwise).
double cutoffCells(const Arguments& args, bool wall)
{
    if (!args.flags.count("calibrated")) return args.number("cutoff", 1.0);
    return args.number("cutoff", wall ? defaultWallCutoffCells : defaultPairCutoffCells);
}

std::unique_ptr<SubgridModel> subgridModel(const Arguments& args, double delta, bool wall = false)
{
    if (!args.flags.count("calibrated"))
        return std::unique_ptr<SubgridModel>(new CutoffSubgridModel(delta, cutoffCells(args, wall)));
    const SubgridCalibration table = SubgridCalibration::read(SubgridCalibration::defaultPath());
    return std::unique_ptr<SubgridModel>(new CalibratedSubgridModel(
        table, delta, wall ? defaultPairCutoffCells : cutoffCells(args, false),
        wall ? cutoffCells(args, true) : defaultWallCutoffCells));
}

std::string number(double v)
{
    if (!std::isfinite(v)) return "null";
    char buffer[40];
    std::snprintf(buffer, sizeof buffer, "%.15g", v);
    return buffer;
}

template <int R, int C>
void printMatrix(const char* name, const double (&m)[R][C], bool last = false)
{
    std::printf("  \"%s\": [\n", name);
    for (int i = 0; i < R; ++i) {
        std::printf("    [");
        for (int j = 0; j < C; ++j) std::printf("%s%s", number(m[i][j]).c_str(), j + 1 < C ? ", " : "");
        std::printf("]%s\n", i + 1 < R ? "," : "");
    }
    std::printf("  ]%s\n", last ? "" : ",");
}

void printPairValues(const char* name, const PairFunctionValues& v, const PairForms* kkForms, bool withM, bool last)
{
    static const char* index[2][2] = {{"11", "12"}, {"21", "22"}};
    std::printf("  \"%s\": {", name);
    bool first = true;
    for (int f = 0; f < NumPairFunctions; ++f) {
        if (!withM && (f == XM || f == YM || f == ZM || f == XQ)) continue;  // XQ: theory only, built with M
        for (int a = 0; a < 2; ++a)
            for (int b = 0; b < 2; ++b) {
                double value = v.f[f][a][b];
                if (kkForms) value /= kimKarrilaFactor(PairFunction(f), a == 0 ? kkForms->a1 : kkForms->a2);
                std::printf("%s\n    \"%s%s\": %s", first ? "" : ",", pairFunctionName(PairFunction(f)), index[a][b], number(value).c_str());
                first = false;
            }
    }
    std::printf("\n  }%s\n", last ? "" : ",");
}

const char* pairNormalisation =
    "kim_karrila: Kim & Karrila scalars; 11 and 12 divided by eta times 6 pi a1 (A), 4 pi a1^2 (B, G), 8 pi a1^3 (C, H), "
    "20/3 pi a1^3 (M), 6 pi a1^2 (P), 6 pi a1^3 (Q); 21 and 22 by the same with a2 (so that X21(lambda) = X12(1/lambda), paper Eq. A.4). "
    "dimensional_over_eta: the dimensional function divided by the viscosity. XP, XQ: pressure moments (trace of the force dipole), "
    "s_a = -eta sum_b XP_ab d.U_b + eta sum_b XQ_ab d.E.d (paper Eq. 19); 1/xi and ln(1/xi) terms derived by lubrication theory, "
    "O(1) constants from the twin-multipole pressure series (docs/resistance.md); XQ is a theoretical function only (no sub-grid value, paper Eq. 21).";

int fullRangeOrder(const Arguments& args)
{
    const double order = args.number("order", fullRangeDefaultOrder);
    if (!(order >= 10 && order <= 250) || order != std::floor(order)) throw std::runtime_error("--order must be an integer in [10, 250]");
    return int(order);
}

// The full-range forms are converged (< 5e-4 at order 100) for 0.1 <= lambda <= 10 (docs/resistance.md).
void printSizeRatioWarning(double lambda, int order)
{
    if (lambda >= 0.1 - 1e-12 && lambda <= 10 + 1e-12) return;
    std::printf("  \"warning\": \"size ratio outside 0.1..10: the far-field series to order %d are not converged near contact "
                "(at lambda = 100, order 100: errors up to 5 %% in YB, more in YC12); see docs/resistance.md\",\n", order);
}

int pairCommand(const Arguments& args)
{
    const double a1 = args.number("a1"), a2 = args.number("a2"), xi = args.number("xi");
    positive(a1, "--a1");
    positive(a2, "--a2");
    const bool subgrid = args.flags.count("subgrid") > 0, full = args.flags.count("full") > 0;
    if (subgrid && args.flags.count("theory")) throw std::runtime_error("choose one of --theory and --subgrid");
    if (subgrid && full) throw std::runtime_error("--full belongs to --theory, not --subgrid");
    if (args.flags.count("calibrated") && !subgrid) throw std::runtime_error("--calibrated belongs to --subgrid");
    if (args.has("order") && !full) throw std::runtime_error("--order needs --full");
    const int order = fullRangeOrder(args);
    std::printf("{\n  \"command\": \"pair\",\n  \"a1\": %s, \"a2\": %s, \"lambda\": %s, \"xi\": %s, \"xi_used\": %s,\n",
                number(a1).c_str(), number(a2).c_str(), number(a2 / a1).c_str(), number(xi).c_str(),
                number(xi > minimumGap ? xi : minimumGap).c_str());
    if (!subgrid && full) {
        const PairFullRangeForms forms = makeFullRangeForms(a1, a2, true, order);
        const PairFunctionValues v = fullRange(forms, xi);
        std::printf("  \"kind\": \"theory, full range: XA, YA, YB, YC matched forms of Jeffrey & Onishi 1984 and XG, YG, YH the same way with Jeffrey 1992's series (near-field singular terms plus the far-field series to order %d with their expansion subtracted; Townsend 2023 constants), XC exact series (Jeffery 1915); XM, YM, ZM, XP, XQ near-field forms\",\n", order);
        std::printf("  \"full_range_functions\": [\"XA\", \"YA\", \"YB\", \"XC\", \"YC\", \"XG\", \"YG\", \"YH\"], \"order\": %d,\n", order);
        printSizeRatioWarning(a2 / a1, order);
        std::printf("  \"normalisation\": \"%s\",\n", pairNormalisation);
        printPairValues("kim_karrila", v, &forms.nearField, true, false);
        printPairValues("dimensional_over_eta", v, nullptr, true, true);
    } else if (!subgrid) {
        const PairForms forms = makePairForms(a1, a2, true);
        const PairFunctionValues v = evaluate(forms, xi);
        std::printf("  \"kind\": \"theory (near-field forms of Jeffrey & Onishi 1984, Jeffrey 1992, Townsend 2023; XP, XQ derived here, docs/resistance.md)\",\n");
        std::printf("  \"normalisation\": \"%s\",\n", pairNormalisation);
        printPairValues("kim_karrila", v, &forms, true, false);
        printPairValues("dimensional_over_eta", v, nullptr, true, true);
    } else {
        const double delta = args.number("delta");
        positive(delta, "--delta");
        const std::unique_ptr<SubgridModel> model = subgridModel(args, delta);
        const double r = 0.5 * (a1 + a2) * (xi + 2);
        const PairSubgridBase base = model->pair(a1, a2, xi);
        std::printf("  \"kind\": \"sub-grid (%s)\",\n", model->describe());
        std::printf("  \"delta\": %s, \"cutoff_cells\": %s, \"xi_cut\": %s, \"r\": %s,\n", number(delta).c_str(),
                    number(cutoffCells(args, false)).c_str(), number(model->pairRange(a1, a2)).c_str(), number(r).c_str());
        std::printf("  \"normalisation\": \"dimensional_over_eta: dimensional sub-grid function divided by the viscosity. base: the 10 independent functions of paper Appendix C.2 in this labelling; dimensional_over_eta: every function from the C.2 relations, averaged over the two labellings of the pair as the blocks use them (YB: torque from translation; force from rotation uses YBtilde_ab = -YB_ba, Eq. A.3).\",\n");
        std::printf("  \"base\": {");
        for (int i = 0; i < NumSubgridBase; ++i)
            std::printf("%s\n    \"%s\": %s", i ? "," : "", subgridBaseName(SubgridBaseFunction(i)), number(base.f[i]).c_str());
        std::printf("\n  },\n");
        printPairValues("dimensional_over_eta", subgridPairFunctions(*model, a1, a2, xi, r), nullptr, false, true);
    }
    std::printf("}\n");
    return 0;
}

int matrixCommand(const Arguments& args)
{
    double x1[3], x2[3];
    args.vector3("x1", x1);
    args.vector3("x2", x2);
    const double a1 = args.number("a1"), a2 = args.number("a2"), eta = args.number("eta", 1.0);
    positive(a1, "--a1");
    positive(a2, "--a2");
    positive(eta, "--eta");
    const PairGeometry g = pairGeometry(x1, x2, a1, a2);
    PairBlock block = PairBlock();
    std::string kind;
    if (args.has("delta")) {
        const double delta = args.number("delta");
        positive(delta, "--delta");
        const std::unique_ptr<SubgridModel> model = subgridModel(args, delta);
        const bool active = subgridPairBlock(*model, x1, x2, a1, a2, eta, block);
        kind = std::string(active ? "sub-grid, frame invariant (paper Eq. 21, Appendix C.2)"
                                  : "sub-grid: pair beyond the model's range, block is zero") +
               "; " + model->describe();
    } else {
        if (args.flags.count("calibrated")) throw std::runtime_error("--calibrated needs --delta");
        TwoSphereTheory theory;
        theoryPairBlock(theory, x1, x2, a1, a2, eta, block);
        kind = "theory (near-field forms)";
    }
    std::printf("{\n  \"command\": \"matrix\",\n  \"kind\": \"%s\",\n", kind.c_str());
    std::printf("  \"a1\": %s, \"a2\": %s, \"eta\": %s, \"r\": %s, \"xi\": %s, \"d\": [%s, %s, %s],\n", number(a1).c_str(),
                number(a2).c_str(), number(eta).c_str(), number(g.r).c_str(), number(g.xi).c_str(), number(g.d[0]).c_str(),
                number(g.d[1]).c_str(), number(g.d[2]).c_str());
    std::printf("  \"normalisation\": \"dimensional, viscosity included. Forces on the particles F = -R U (paper Eq. 21: M = -eta R U). Unknowns and rows ordered (U1, Omega1, U2, Omega2) / (F1, T1, F2, T2). stress_rows: S = -stress_rows U, rows S1 (xx, xy, xz, yy, yz, zz), S2 (same), s1, s2 (trace of the force dipole).\",\n");
    printMatrix("R", block.R);
    printMatrix("stress_rows", block.stress, true);
    std::printf("}\n");
    return 0;
}

int wallCommand(const Arguments& args)
{
    const double a = args.number("a"), eps = args.number("eps");
    positive(a, "--a");
    if (args.flags.count("calibrated") && !args.has("delta")) throw std::runtime_error("--calibrated needs --delta");
    const WallScalars kk = wallTheory(eps);
    const WallScalars dim = wallTheoryDimensional(a, eps);
    std::printf("{\n  \"command\": \"wall\",\n  \"a\": %s, \"eps\": %s, \"eps_used\": %s,\n", number(a).c_str(), number(eps).c_str(),
                number(eps > minimumGap ? eps : minimumGap).c_str());
    std::printf("  \"normalisation\": \"kim_karrila: divided by eta times 6 pi a (XA, YA), 4 pi a^2 (YB, XG, YG), 8 pi a^3 (XC, YC, YH), 6 pi a^2 (XP); d = unit normal into the wall; YB < 0 with that d. dimensional_over_eta: divided by the viscosity. XG, XP: singular lubrication terms (no O(1) constant); YG, YH: paper Eq. (D.4).\",\n");
    std::printf("  \"kim_karrila\": {");
    for (int i = 0; i < NumWallFunctions; ++i)
        std::printf("%s\n    \"%s\": %s", i ? "," : "", wallFunctionName(WallFunction(i)), number(kk.f[i]).c_str());
    std::printf("\n  },\n  \"dimensional_over_eta\": {");
    for (int i = 0; i < NumWallFunctions; ++i)
        std::printf("%s\n    \"%s\": %s", i ? "," : "", wallFunctionName(WallFunction(i)), number(dim.f[i]).c_str());
    std::printf("\n  }");
    if (args.has("delta")) {
        const double delta = args.number("delta");
        positive(delta, "--delta");
        const std::unique_ptr<SubgridModel> model = subgridModel(args, delta, true);
        const WallScalars sg = model->wall(a, eps);
        std::printf(",\n  \"delta\": %s, \"eps_cut\": %s,\n  \"subgrid_kind\": \"%s\",\n  \"subgrid_dimensional_over_eta\": {",
                    number(delta).c_str(), number(model->wallRange(a)).c_str(), model->describe());
        for (int i = 0; i < NumWallFunctions; ++i)
            std::printf("%s\n    \"%s\": %s", i ? "," : "", wallFunctionName(WallFunction(i)), number(sg.f[i]).c_str());
        std::printf("\n  }");
    }
    std::printf("\n}\n");
    return 0;
}

// Squeeze mobility.  Pair: forces +F d on sphere 1 and -F d on sphere 2 (pushing them together); the
// axisymmetric resistance system [X11A X12A; X21A X22A] (U1, U2) = (F, -F) (dimensional, F = -R U for the
// hydrodynamic forces, so R U balances the applied ones) gives the velocities along d, and the closing
// velocity V = -(U2 - U1).d = U1 - U2, printed in units of F/(6 pi eta a1).  Wall: V = F/(6 pi eta a X^A_wall).
int squeezeCommand(const Arguments& args)
{
    if (args.flags.count("wall")) {
        if (args.has("a1") || args.has("a2") || args.has("xi") || args.flags.count("near") || args.has("order"))
            throw std::runtime_error("squeeze --wall takes --a and --eps");
        const double a = args.number("a"), eps = args.number("eps");
        positive(a, "--a");
        const double xa = wallNormalTranslation(eps);
        std::printf("{\n  \"command\": \"squeeze\",\n  \"geometry\": \"wall\",\n  \"a\": %s, \"eps\": %s, \"eps_used\": %s,\n",
                    number(a).c_str(), number(eps).c_str(), number(eps > minimumGap ? eps : minimumGap).c_str());
        std::printf("  \"kind\": \"X^A_wall: Brenner (1961) exact series, Cox & Brenner (1967) lubrication form below eps = 1e-3\",\n");
        std::printf("  \"normalisation\": \"sphere pushed toward the wall by a force F along the normal: approach velocity V divided by F/(6 pi eta a), i.e. 1/X^A_wall (Kim-Karrila X^A_wall = XA_kim_karrila)\",\n");
        std::printf("  \"XA_kim_karrila\": %s,\n", number(xa).c_str());
        std::printf("  \"closing_velocity_normalised\": %s\n}\n", number(1 / xa).c_str());
        return 0;
    }
    if (args.has("a") || args.has("eps")) throw std::runtime_error("--a and --eps belong to squeeze --wall");
    const double a1 = args.number("a1"), a2 = args.number("a2"), xi = args.number("xi");
    positive(a1, "--a1");
    positive(a2, "--a2");
    const bool near = args.flags.count("near") > 0;
    if (near && args.has("order")) throw std::runtime_error("--order belongs to the full-range forms, not --near");
    const int order = fullRangeOrder(args);
    const PairFunctionValues v = near ? evaluate(makePairForms(a1, a2, false), xi) : fullRange(makeFullRangeForms(a1, a2, false, order), xi);
    const double pi = 3.14159265358979323846;
    const double F = 6 * pi * a1;  // so that the velocities come out in units of F/(6 pi eta a1), eta = 1
    const double A = v.f[XA][0][0], B = v.f[XA][0][1], Bt = v.f[XA][1][0], D = v.f[XA][1][1];
    // det = A D - B Bt = A (B + D) - B (A + Bt); the column sums are the regular rigid-pair parts
    const double det = A * D - B * Bt;
    const double U1 = F * (D + B) / det, U2 = -F * (A + Bt) / det;
    const double lambda = a2 / a1, l1 = 1 + lambda;
    const double xiUsed = xi > minimumGap ? xi : minimumGap;
    std::printf("{\n  \"command\": \"squeeze\",\n  \"geometry\": \"pair\",\n");
    std::printf("  \"a1\": %s, \"a2\": %s, \"lambda\": %s, \"xi\": %s, \"xi_used\": %s,\n", number(a1).c_str(),
                number(a2).c_str(), number(lambda).c_str(), number(xi).c_str(), number(xiUsed).c_str());
    if (near)
        std::printf("  \"kind\": \"near-field forms of X^A (Jeffrey & Onishi 1984, Townsend 2023): lubrication only, not valid far from contact\",\n");
    else {
        std::printf("  \"kind\": \"full-range X^A: matched forms of Jeffrey & Onishi 1984, far-field series to order %d\",\n", order);
        printSizeRatioWarning(lambda, order);
    }
    std::printf("  \"normalisation\": \"forces +F d on sphere 1 and -F d on sphere 2 (d = (x2 - x1)/|x2 - x1|, pushing them together), no torques: "
                "closing velocity V = -(U2 - U1).d and the velocities U1.d, U2.d divided by F/(6 pi eta a1); from [X11A X12A; X21A X22A] (U1, U2) = (F, -F), "
                "dimensional. lubrication_leading_order = xi (1+lambda)^3 / (2 lambda^2), the limit of V at xi -> 0\",\n");
    std::printf("  \"U1_normalised\": %s, \"U2_normalised\": %s,\n", number(U1).c_str(), number(U2).c_str());
    std::printf("  \"lubrication_leading_order\": %s,\n", number(xiUsed * l1 * l1 * l1 / (2 * lambda * lambda)).c_str());
    std::printf("  \"closing_velocity_normalised\": %s\n}\n", number(U1 - U2).c_str());
    return 0;
}

// What pair_style fdm/subgrid's default model (calibrated) needs of the shipped table for a pair of
// radii, or a radius against a wall, at mesh size delta: the same test the pair style makes at the start
// of a run, for scripts that want to know before they launch one.
int coverageCommand(const Arguments& args)
{
    const double a1 = args.number("a1"), delta = args.number("delta");
    positive(a1, "--a1");
    positive(delta, "--delta");
    const SubgridCalibration table = SubgridCalibration::read(SubgridCalibration::defaultPath());
    std::printf("{\n  \"command\": \"coverage\",\n  \"table\": \"%s\",\n  \"a1\": %s, \"delta\": %s,\n",
                table.path().c_str(), number(a1).c_str(), number(delta).c_str());
    if (args.has("a2")) {
        const double a2 = args.number("a2");
        positive(a2, "--a2");
        double k[4];  // the pair's tangential correction at one gap: only whether the table has it
        std::printf("  \"a2\": %s, \"pair\": %s, \"pair_tangential\": %s,\n", number(a2).c_str(),
                    table.coversPair(a1, a2, delta) ? "true" : "false",
                    table.pairInternalCorrection(a1, a2, delta, 0.1, k) ? "true" : "false");
    }
    if (args.flags.count("wall"))
        std::printf("  \"wall\": %s,\n", table.coversWall(a1, delta) ? "true" : "false");
    std::printf("  \"coverage\": \"%s\"\n}\n", table.coverage().c_str());
    return 0;
}

// pair_style fdm/subgrid's defaults that scripts need to reproduce its blocks with this tool (--cutoff K),
// from the library's constants, so that no script repeats them
int defaultsCommand()
{
    std::printf("{\n  \"command\": \"defaults\",\n  \"pair_cutoff_cells\": %s,\n  \"wall_cutoff_cells\": %s,\n"
                "  \"calibration_table\": \"%s\"\n}\n",
                number(defaultPairCutoffCells).c_str(), number(defaultWallCutoffCells).c_str(),
                SubgridCalibration::defaultPath().c_str());
    return 0;
}

}  // namespace

int main(int argc, char** argv)
{
    try {
        const Arguments args = parse(argc, argv);
        if (args.command == "pair") return pairCommand(args);
        if (args.command == "matrix") return matrixCommand(args);
        if (args.command == "wall") return wallCommand(args);
        if (args.command == "squeeze") return squeezeCommand(args);
        if (args.command == "coverage") return coverageCommand(args);
        if (args.command == "defaults") return defaultsCommand();
        if (args.command == "-h" || args.command == "--help") {
            std::fputs(usage, stdout);
            return 0;
        }
        throw std::runtime_error("unknown command '" + args.command + "'");
    } catch (const std::exception& e) {
        std::fprintf(stderr, "fdmResistance: error: %s\n%s", e.what(), usage);
        return 2;
    }
}
