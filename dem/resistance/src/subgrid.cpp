#include "fdm/resistance/subgrid.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace fdm {
namespace resistance {

const char* subgridBaseName(SubgridBaseFunction f)
{
    static const char* names[NumSubgridBase] = {"X21A", "Y21A", "Y21B", "X21C", "Y11C",
                                                "X11G", "Y11G", "Y21H", "X12P", "X21P"};
    return names[f];
}

PairFunctionValues expandAppendixC2(const PairSubgridBase& b, double r)
{
    const double xa = b.f[BaseX21A], ya = b.f[BaseY21A], yb = b.f[BaseY21B], xc = b.f[BaseX21C];
    const double yc = b.f[BaseY11C], xg = b.f[BaseX11G], yg = b.f[BaseY11G], yh = b.f[BaseY21H];
    PairFunctionValues v;
    for (int f = 0; f < NumPairFunctions; ++f)
        for (int i = 0; i < 2; ++i)
            for (int j = 0; j < 2; ++j) v.f[f][i][j] = 0;
    // A: rigid translations of the pair carry no correction
    v.f[XA][0][0] = -xa; v.f[XA][0][1] = xa; v.f[XA][1][0] = xa; v.f[XA][1][1] = -xa;
    v.f[YA][0][0] = -ya; v.f[YA][0][1] = ya; v.f[YA][1][0] = ya; v.f[YA][1][1] = -ya;
    // C
    v.f[XC][0][0] = -xc; v.f[XC][0][1] = xc; v.f[XC][1][0] = xc; v.f[XC][1][1] = -xc;
    v.f[YC][0][0] = yc;
    v.f[YC][0][1] = v.f[YC][1][0] = -yc + r * yb - r * r * ya;
    v.f[YC][1][1] = yc - 2 * r * yb + r * r * ya;
    // B (torque from translation); B-tilde follows from Eq. (A.3)
    v.f[YB][0][0] = -yb + r * ya;
    v.f[YB][0][1] = yb - r * ya;
    v.f[YB][1][0] = yb;
    v.f[YB][1][1] = -yb;
    // G (stresslet from translation)
    v.f[XG][0][0] = xg; v.f[XG][0][1] = -xg;
    v.f[XG][1][0] = -xg - r * xa; v.f[XG][1][1] = xg + r * xa;
    v.f[YG][0][0] = yg; v.f[YG][0][1] = -yg;
    v.f[YG][1][0] = -yg - 0.5 * r * ya; v.f[YG][1][1] = yg + 0.5 * r * ya;
    // H (stresslet from rotation)
    v.f[YH][0][0] = -yh - 0.5 * r * r * ya + 0.5 * r * yb;
    v.f[YH][0][1] = yh + 0.5 * r * r * ya + r * yg - 0.5 * r * yb;
    v.f[YH][1][0] = yh;
    v.f[YH][1][1] = -yh - 0.5 * r * r * ya - r * yg;
    // P (trace of the force dipole)
    v.f[XP][0][0] = -b.f[BaseX12P]; v.f[XP][0][1] = b.f[BaseX12P];
    v.f[XP][1][0] = b.f[BaseX21P]; v.f[XP][1][1] = -b.f[BaseX21P];
    return v;
}

PairFunctionValues subgridPairFunctions(const SubgridModel& model, double a1, double a2, double xi, double r)
{
    const PairSubgridBase base = model.pair(a1, a2, xi);
    const PairFunctionValues mine = expandAppendixC2(base, r);
    // equal radii: the relabelled pair has the same independent functions
    const PairFunctionValues relabelled = expandAppendixC2(a1 == a2 ? base : model.pair(a2, a1, xi), r);
    // sign of each tensor form of Eq. (A.1) under d -> -d: A, C (d d, I), H (d eps.d) even; B (eps.d),
    // G (three d's or d delta), P (d) odd. M and Q are not sub-grid functions (zero in both).
    double parity[NumPairFunctions];
    for (int f = 0; f < NumPairFunctions; ++f) parity[f] = 1;
    parity[YB] = parity[XG] = parity[YG] = parity[XP] = -1;
    PairFunctionValues v;
    for (int f = 0; f < NumPairFunctions; ++f)
        for (int i = 0; i < 2; ++i)
            for (int j = 0; j < 2; ++j)
                v.f[f][i][j] = 0.5 * (mine.f[f][i][j] + parity[f] * relabelled.f[f][1 - i][1 - j]);
    return v;
}

bool makeDissipative(PairSubgridBase& b, double r)
{
    bool changed = false;
    const SubgridBaseFunction mustBeNonPositive[3] = {BaseX21A, BaseY21A, BaseX21C};
    for (int i = 0; i < 3; ++i)
        if (b.f[mustBeNonPositive[i]] > 0) {
            b.f[mustBeNonPositive[i]] = 0;
            changed = true;
        }
    if (b.f[BaseY11C] < 0) {
        b.f[BaseY11C] = 0;
        changed = true;
    }
    const double y11a = -b.f[BaseY21A], y11c = b.f[BaseY11C];
    const double y11b = -b.f[BaseY21B] + r * b.f[BaseY21A];
    const double bound = std::sqrt(y11a * y11c);
    if (std::fabs(y11b) > bound) {
        const double clipped = y11b > 0 ? bound : -bound;
        b.f[BaseY21B] = -clipped + r * b.f[BaseY21A];
        changed = true;
    }
    return changed;
}

void selectSubgridBaseForms(const PairForms& p, NearFieldForm out[NumSubgridBase])
{
    out[BaseX21A] = p.f[XA][1][0];
    out[BaseY21A] = p.f[YA][1][0];
    out[BaseY21B] = p.f[YB][1][0];
    out[BaseX21C] = p.f[XC][1][0];
    out[BaseY11C] = p.f[YC][0][0];
    out[BaseX11G] = p.f[XG][0][0];
    out[BaseY11G] = p.f[YG][0][0];
    out[BaseY21H] = p.f[YH][1][0];
    out[BaseX12P] = p.f[XP][0][1];
    out[BaseX21P] = p.f[XP][1][0];
}

CutoffSubgridModel::CutoffSubgridModel(double meshSize, double cutoffCells)
    : meshSize_(meshSize), cutoffCells_(cutoffCells), theory_(false)
{
    if (!(meshSize > 0) || !(cutoffCells > 0))
        throw std::invalid_argument("CutoffSubgridModel: mesh size and cut-off (in cells) must be positive");
}

double CutoffSubgridModel::pairRange(double a1, double a2) const { return cutoffCells_ * meshSize_ / (0.5 * (a1 + a2)); }
double CutoffSubgridModel::wallRange(double a) const { return cutoffCells_ * meshSize_ / a; }

const char* CutoffSubgridModel::describe() const
{
    return "cut-off model: f_SG(xi) = f_th(max(xi,1e-5)) - f_th(xi_c) for xi < xi_c = k*Delta/a_mean, else 0";
}

const CutoffSubgridModel::PairEntry& CutoffSubgridModel::entry(double a1, double a2) const
{
    if (last_ && last_->a1 == a1 && last_->a2 == a2) return *last_;
    const std::pair<double, double> key(a1, a2);
    std::map<std::pair<double, double>, PairEntry>::iterator it = cache_.find(key);
    if (it == cache_.end()) {
        PairEntry e;
        e.a1 = a1;
        e.a2 = a2;
        e.xiCut = pairRange(a1, a2);
        selectSubgridBaseForms(theory_.forms(a1, a2), e.base);
        const double xiFrozen = std::max(e.xiCut, minimumGap);
        for (int i = 0; i < NumSubgridBase; ++i) e.frozen[i] = e.base[i](xiFrozen);
        it = cache_.insert(std::make_pair(key, e)).first;
    }
    last_ = &it->second;
    return *last_;
}

PairSubgridBase CutoffSubgridModel::pair(double a1, double a2, double xi) const
{
    const PairEntry& e = entry(a1, a2);
    PairSubgridBase b;
    if (!(xi < e.xiCut)) {
        for (int i = 0; i < NumSubgridBase; ++i) b.f[i] = 0;
        return b;
    }
    const double xiUsed = std::max(xi, minimumGap);
    const double logInvXi = std::log(1 / xiUsed);
    for (int i = 0; i < NumSubgridBase; ++i) b.f[i] = e.base[i](xiUsed, logInvXi) - e.frozen[i];
    makeDissipative(b, 0.5 * (a1 + a2) * (2 + xi));  // r of the actual (not floored) gap, as in C.2
    return b;
}

WallScalars CutoffSubgridModel::wall(double a, double eps) const
{
    WallScalars w;
    const double epsCut = wallRange(a);
    if (!(eps < epsCut)) {
        for (int i = 0; i < NumWallFunctions; ++i) w.f[i] = 0;
        return w;
    }
    if (a != lastWallRadius_) {
        lastWallFrozen_ = wallTheoryDimensional(a, std::max(epsCut, minimumGap));
        lastWallRadius_ = a;
    }
    w = wallTheoryDimensional(a, eps);
    for (int i = 0; i < NumWallFunctions; ++i) w.f[i] -= lastWallFrozen_.f[i];
    applyWallClosureD4(w, a, eps);  // Y^G, Y^H of the sub-grid matrix: Eq. (D.4)
    return w;
}

}  // namespace resistance
}  // namespace fdm
