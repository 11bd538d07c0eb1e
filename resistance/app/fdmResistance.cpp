// fdmResistance: prints resistance functions and blocks as JSON (docs/resistance.md, "Command line").
//   fdmResistance pair   --a1 A --a2 B --xi X [--theory|--subgrid] [--delta D] [--cutoff K]
//   fdmResistance matrix --x1 x y z --x2 x y z --a1 A --a2 B [--delta D] [--eta E] [--cutoff K]
//   fdmResistance wall   --a A --eps E [--delta D] [--cutoff K]
#include "fdm/resistance/resistance.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

using namespace fdm::resistance;

namespace {

const char* usage =
    "usage:\n"
    "  fdmResistance pair   --a1 A --a2 B --xi X [--theory|--subgrid] [--delta D] [--cutoff K]\n"
    "  fdmResistance matrix --x1 x y z --x2 x y z --a1 A --a2 B [--delta D] [--eta E] [--cutoff K]\n"
    "  fdmResistance wall   --a A --eps E [--delta D] [--cutoff K]\n"
    "xi = 2r/(a1+a2) - 2; eps = h/a - 1; --delta: mesh size (sub-grid output); --cutoff: k in xi_c = k*delta/a_mean\n";

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
        if (key == "theory" || key == "subgrid") {
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
        if (!withM && (f == XM || f == YM || f == ZM)) continue;
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

int pairCommand(const Arguments& args)
{
    const double a1 = args.number("a1"), a2 = args.number("a2"), xi = args.number("xi");
    positive(a1, "--a1");
    positive(a2, "--a2");
    const bool subgrid = args.flags.count("subgrid") > 0;
    if (subgrid && args.flags.count("theory")) throw std::runtime_error("choose one of --theory and --subgrid");
    std::printf("{\n  \"command\": \"pair\",\n  \"a1\": %s, \"a2\": %s, \"lambda\": %s, \"xi\": %s, \"xi_used\": %s,\n",
                number(a1).c_str(), number(a2).c_str(), number(a2 / a1).c_str(), number(xi).c_str(),
                number(xi > minimumGap ? xi : minimumGap).c_str());
    if (!subgrid) {
        const PairForms forms = makePairForms(a1, a2, true);
        const PairFunctionValues v = evaluate(forms, xi);
        std::printf("  \"kind\": \"theory (near-field forms of Jeffrey & Onishi 1984, Jeffrey 1992, Townsend 2023)\",\n");
        std::printf("  \"normalisation\": \"kim_karrila: Kim & Karrila scalars; 11 and 12 divided by eta times 6 pi a1 (A), 4 pi a1^2 (B, G), 8 pi a1^3 (C, H), 20/3 pi a1^3 (M), 6 pi a1^2 (P); 21 and 22 by the same with a2 (so that X21(lambda) = X12(1/lambda), paper Eq. A.4). dimensional_over_eta: the dimensional function divided by the viscosity. XP: leading lubrication term only.\",\n");
        printPairValues("kim_karrila", v, &forms, true, false);
        printPairValues("dimensional_over_eta", v, nullptr, true, true);
    } else {
        const double delta = args.number("delta");
        positive(delta, "--delta");
        const CutoffSubgridModel model(delta, args.number("cutoff", 1.0));
        const double r = 0.5 * (a1 + a2) * (xi + 2);
        const PairSubgridBase base = model.pair(a1, a2, xi);
        std::printf("  \"kind\": \"sub-grid (%s)\",\n", model.describe());
        std::printf("  \"delta\": %s, \"cutoff_cells\": %s, \"xi_cut\": %s, \"r\": %s,\n", number(delta).c_str(),
                    number(model.cutoffCells()).c_str(), number(model.pairRange(a1, a2)).c_str(), number(r).c_str());
        std::printf("  \"normalisation\": \"dimensional_over_eta: dimensional sub-grid function divided by the viscosity. base: the 10 independent functions of paper Appendix C.2; all: every function from the C.2 relations (YB: torque from translation; force from rotation uses YBtilde_ab = -YB_ba, Eq. A.3).\",\n");
        std::printf("  \"base\": {");
        for (int i = 0; i < NumSubgridBase; ++i)
            std::printf("%s\n    \"%s\": %s", i ? "," : "", subgridBaseName(SubgridBaseFunction(i)), number(base.f[i]).c_str());
        std::printf("\n  },\n");
        printPairValues("dimensional_over_eta", expandAppendixC2(base, r), nullptr, false, true);
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
        const CutoffSubgridModel model(delta, args.number("cutoff", 1.0));
        const bool active = subgridPairBlock(model, x1, x2, a1, a2, eta, block);
        kind = active ? "sub-grid, frame invariant (paper Eq. 21, Appendix C.2)" : "sub-grid: pair beyond the cut-off, block is zero";
    } else {
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
    const WallScalars kk = wallTheory(eps);
    const WallScalars dim = wallTheoryDimensional(a, eps);
    std::printf("{\n  \"command\": \"wall\",\n  \"a\": %s, \"eps\": %s, \"eps_used\": %s,\n", number(a).c_str(), number(eps).c_str(),
                number(eps > minimumGap ? eps : minimumGap).c_str());
    std::printf("  \"normalisation\": \"kim_karrila: divided by eta times 6 pi a (XA, YA), 4 pi a^2 (YB, XG, YG), 8 pi a^3 (XC, YC, YH), 6 pi a^2 (XP); d = unit normal into the wall; YB < 0 with that d. dimensional_over_eta: divided by the viscosity. XG, XP: leading lubrication terms; YG, YH: paper Eq. (D.4).\",\n");
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
        const CutoffSubgridModel model(delta, args.number("cutoff", 1.0));
        const WallScalars sg = model.wall(a, eps);
        std::printf(",\n  \"delta\": %s, \"eps_cut\": %s,\n  \"subgrid_dimensional_over_eta\": {", number(delta).c_str(),
                    number(model.wallRange(a)).c_str());
        for (int i = 0; i < NumWallFunctions; ++i)
            std::printf("%s\n    \"%s\": %s", i ? "," : "", wallFunctionName(WallFunction(i)), number(sg.f[i]).c_str());
        std::printf("\n  }");
    }
    std::printf("\n}\n");
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
