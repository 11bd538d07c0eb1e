#include "fdm/resistance/squeeze_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#ifndef FDM_RESISTANCE_SOURCE_DIR
#define FDM_RESISTANCE_SOURCE_DIR "."
#endif

namespace fdm {
namespace resistance {

namespace {
const double pi = 3.14159265358979323846;
// a/Delta and a2/a1 of a run match a tabulated value within this relative tolerance
const double matchTolerance = 1e-6;

std::string num(double x)
{
    std::ostringstream os;
    os.precision(6);
    os << x;
    return os.str();
}
}  // namespace

double SqueezeCalibration::Block::sHat(double xi) const
{
    if (logXi.empty()) return 0;
    const double t = std::log(std::max(xi, 1e-300));
    if (!(t < logXi.back())) return 0;
    if (t <= logXi.front()) return xiS.front() / xi;  // below the table: the leading 1/xi lubrication
    const size_t k = size_t(std::upper_bound(logXi.begin(), logXi.end(), t) - logXi.begin());
    const double w = (t - logXi[k - 1]) / (logXi[k] - logXi[k - 1]);
    return ((1 - w) * xiS[k - 1] + w * xiS[k]) / xi;
}

SqueezeCalibration SqueezeCalibration::read(const std::string& path)
{
    std::ifstream in(path.c_str());
    if (!in) throw std::runtime_error("squeeze calibration " + path + ": cannot open the file");
    SqueezeCalibration cal;
    cal.path_ = path;
    std::string line;
    int lineNo = 0;
    size_t rowsLeft = 0;
    Block* block = nullptr;
    while (std::getline(in, line)) {
        ++lineNo;
        const std::string where = "squeeze calibration " + path + ", line " + std::to_string(lineNo) + ": ";
        if (line.empty() || line[0] == '#') continue;
        std::istringstream words(line);
        if (rowsLeft == 0) {
            std::string kind;
            double aOverDelta, ratio;
            long rows;
            if (!(words >> kind >> aOverDelta >> ratio >> rows) || (kind != "pair" && kind != "wall") ||
                !(aOverDelta > 0) || !(ratio >= 1) || rows < 2)
                throw std::runtime_error(where + "expected a block header 'pair|wall a/Delta ratio(>=1) rows(>=2) ...', "
                                         "got '" + line + "'");
            Block b;
            b.wall = (kind == "wall");
            b.aOverDelta = aOverDelta;
            b.ratio = ratio;
            for (const Block& o : cal.blocks_)
                if (o.wall == b.wall && std::fabs(o.aOverDelta - aOverDelta) <= matchTolerance * aOverDelta &&
                    std::fabs(o.ratio - ratio) <= matchTolerance * ratio)
                    throw std::runtime_error(where + kind + " a/Delta " + num(aOverDelta) + " ratio " + num(ratio) +
                                             " appears twice");
            cal.blocks_.push_back(b);
            block = &cal.blocks_.back();
            rowsLeft = size_t(rows);
            continue;
        }
        double xi, xiS;
        if (!(words >> xi >> xiS) || !(xi > 0) || !(xiS >= 0) || !std::isfinite(xiS))
            throw std::runtime_error(where + "expected 'xi xi*s_hat' with xi > 0 and xi*s_hat >= 0, got '" + line + "'");
        const double t = std::log(xi);
        if (!block->logXi.empty() && !(t > block->logXi.back()))
            throw std::runtime_error(where + "xi " + num(xi) + " does not increase");
        block->logXi.push_back(t);
        block->xiS.push_back(xiS);
        --rowsLeft;
    }
    if (rowsLeft != 0)
        throw std::runtime_error("squeeze calibration " + path + ": the file ends " + std::to_string(rowsLeft) +
                                 " rows before its last block does");
    if (cal.blocks_.empty()) throw std::runtime_error("squeeze calibration " + path + ": no blocks");
    for (Block& b : cal.blocks_) b.xiS.back() = 0;  // the correction ends at the last row
    return cal;
}

std::string SqueezeCalibration::defaultPath()
{
    const char* root = std::getenv("FDM_ROOT");
    const std::string relative = "/dem/resistance/data/squeeze_calibration.dat";
    if (root && *root) {
        const std::string candidate = std::string(root) + relative;
        if (std::ifstream(candidate.c_str())) return candidate;
    }
    return std::string(FDM_RESISTANCE_SOURCE_DIR) + "/data/squeeze_calibration.dat";
}

const SqueezeCalibration::Stencil& SqueezeCalibration::stencil(bool wall, double aOverDelta, double ratio) const
{
    for (const Stencil& st : stencils_)
        if (st.wall == wall && st.aOverDelta == aOverDelta && st.ratio == ratio) return st;
    Stencil st;
    st.wall = wall;
    st.aOverDelta = aOverDelta;
    st.ratio = ratio;
    st.covered = false;
    st.n = 0;
    st.xiMax = 0;
    // the tabulated a/Delta and ratios of this kind, and the pair of values around the wanted one
    std::vector<double> as, rs;
    for (const Block& b : blocks_)
        if (b.wall == wall) {
            as.push_back(b.aOverDelta);
            rs.push_back(b.ratio);
        }
    auto bracket = [](std::vector<double> v, double x, double* lo, double* hi) {
        std::sort(v.begin(), v.end());
        v.erase(std::unique(v.begin(), v.end()), v.end());
        for (size_t k = 0; k < v.size(); ++k)
            if (std::fabs(v[k] - x) <= matchTolerance * v[k]) {
                *lo = *hi = v[k];
                return true;
            }
        for (size_t k = 0; k + 1 < v.size(); ++k)
            if (v[k] < x && x < v[k + 1]) {
                *lo = v[k];
                *hi = v[k + 1];
                return true;
            }
        return false;
    };
    double a0, a1, r0, r1;
    if (!as.empty() && bracket(as, aOverDelta, &a0, &a1) && bracket(rs, ratio, &r0, &r1)) {
        const double wa = a1 > a0 ? (aOverDelta - a0) / (a1 - a0) : 0;
        const double wr = r1 > r0 ? (ratio - r0) / (r1 - r0) : 0;
        st.covered = true;
        for (int i = 0; i < 2 && st.covered; ++i)
            for (int j = 0; j < 2 && st.covered; ++j) {
                const double w = (i ? wa : 1 - wa) * (j ? wr : 1 - wr);
                if (w == 0) continue;
                const Block* found = nullptr;
                for (const Block& b : blocks_)
                    if (b.wall == wall && b.aOverDelta == (i ? a1 : a0) && b.ratio == (j ? r1 : r0)) found = &b;
                if (!found) {
                    st.covered = false;  // the table is not a full grid around this point
                    break;
                }
                st.block[st.n] = found;
                st.weight[st.n] = w;
                st.xiMax = std::max(st.xiMax, found->xiMax());
                ++st.n;
            }
    }
    if (!st.covered) st.n = 0;
    stencils_.push_back(st);
    return stencils_.back();
}

bool SqueezeCalibration::coversPair(double a1, double a2, double delta) const
{
    const double small = std::min(a1, a2);
    return stencil(false, small / delta, std::max(a1, a2) / small).covered;
}

bool SqueezeCalibration::coversWall(double a, double delta) const { return stencil(true, a / delta, 1.0).covered; }

double SqueezeCalibration::pairSHat(double a1, double a2, double delta, double xi) const
{
    const double small = std::min(a1, a2);
    const Stencil& st = stencil(false, small / delta, std::max(a1, a2) / small);
    if (!st.covered)
        throw std::runtime_error("squeeze calibration " + path_ + ": no calibration for a pair of radii " + num(a1) +
                                 " and " + num(a2) + " at mesh size " + num(delta) + " (a1/Delta " +
                                 num(small / delta) + ", a2/a1 " + num(std::max(a1, a2) / small) + "); the table has " +
                                 coverage());
    double s = 0;
    for (int k = 0; k < st.n; ++k) s += st.weight[k] * st.block[k]->sHat(xi);
    return s;
}

double SqueezeCalibration::wallSHat(double a, double delta, double eps) const
{
    const Stencil& st = stencil(true, a / delta, 1.0);
    if (!st.covered)
        throw std::runtime_error("squeeze calibration " + path_ + ": no wall calibration for radius " + num(a) +
                                 " at mesh size " + num(delta) + " (a/Delta " + num(a / delta) + "); the table has " +
                                 coverage());
    double s = 0;
    for (int k = 0; k < st.n; ++k) s += st.weight[k] * st.block[k]->sHat(eps);
    return s;
}

double SqueezeCalibration::pairRange(double a1, double a2, double delta) const
{
    const double small = std::min(a1, a2);
    return stencil(false, small / delta, std::max(a1, a2) / small).xiMax;
}

double SqueezeCalibration::wallRange(double a, double delta) const { return stencil(true, a / delta, 1.0).xiMax; }

std::string SqueezeCalibration::coverage() const
{
    std::string out;
    for (int wall = 0; wall < 2; ++wall) {
        std::string list;
        for (const Block& b : blocks_)
            if (b.wall == bool(wall))
                list += (list.empty() ? "" : ", ") + std::string("(") + num(b.aOverDelta) +
                        (wall ? "" : ", " + num(b.ratio)) + ")";
        out += (out.empty() ? "" : "; ") + std::string(wall ? "walls a/Delta " : "pairs (a1/Delta, a2/a1) ") +
               (list.empty() ? "none" : list);
    }
    return out;
}

CalibratedSubgridModel::CalibratedSubgridModel(const SqueezeCalibration& calibration, double meshSize,
                                               double cutoffCells, double wallCutoffCells)
    : calibration_(calibration), meshSize_(meshSize), pairCutoff_(meshSize, cutoffCells),
      wallCutoff_(meshSize, wallCutoffCells)
{
    description_ = "calibrated squeeze (Appendix B, " + calibration_.path() +
                   ": pair X21A and wall X^A measured), the other functions from the cut-off model (" +
                   num(cutoffCells) + " cells, walls " + num(wallCutoffCells) + ")";
}

double CalibratedSubgridModel::pairRange(double a1, double a2) const
{
    return std::max(pairCutoff_.pairRange(a1, a2), calibration_.pairRange(a1, a2, meshSize_));
}

double CalibratedSubgridModel::wallRange(double a) const
{
    return std::max(wallCutoff_.wallRange(a), calibration_.wallRange(a, meshSize_));
}

PairSubgridBase CalibratedSubgridModel::pair(double a1, double a2, double xi) const
{
    PairSubgridBase b = pairCutoff_.pair(a1, a2, xi);  // zero beyond the cut-off's range
    // s_hat >= 0 (the reader refuses negative rows, the weights are >= 0): the squeeze stays dissipative,
    // and the other functions are the cut-off model's, already through makeDissipative
    b.f[BaseX21A] = -6 * pi * std::min(a1, a2) * calibration_.pairSHat(a1, a2, meshSize_, std::max(xi, minimumGap));
    return b;
}

WallScalars CalibratedSubgridModel::wall(double a, double eps) const
{
    WallScalars w = wallCutoff_.wall(a, eps);
    w.f[WallXA] = 6 * pi * a * calibration_.wallSHat(a, meshSize_, std::max(eps, minimumGap));
    return w;
}

const char* CalibratedSubgridModel::describe() const { return description_.c_str(); }

}  // namespace resistance
}  // namespace fdm
