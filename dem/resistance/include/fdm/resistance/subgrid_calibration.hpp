// The solver's own resistance, measured (paper section 2.2 and Appendix B): R^SG = R^th - R^FDM, instead of
// the cut-off model's assumption of what the mesh resolves.
//
// The table is written by `python3 -m fdmsubgrid.calibration` (scripts/fdmsubgrid/calibration.py for the
// squeeze functions, wallcalibration.py for the tangential wall functions; both explain the measurement:
// the solver run with the sub-grid lubrication off, the box effect extrapolated away, averaged over
// positions in the mesh cell). Per (function, a1/Delta, a2/a1) it holds xi * s_hat(xi) on a logarithmic
// grid, s_hat the sub-grid function in Kim-Karrila units (a1 the smaller sphere):
//     pair     (squeeze)  X21A^SG = -6 pi a1 s_hat(xi)
//     wall     (squeeze)  X^A_SG  =  6 pi a  s_hat(eps)
//     wall_YA, wall_YB, wall_YC, wall_XC: Y^A_SG = 6 pi a s_hat, Y^B_SG = 4 pi a^2 s_hat,
//                         Y^C_SG = 8 pi a^3 s_hat, X^C_SG = 8 pi a^3 s_hat (d into the wall, Y^B < 0)
//     pair_K11, pair_K12, pair_K22, pair_Ktw: the correction K on the pair's internal modes other than the
//                         squeeze (scripts/fdmsubgrid/pairtangential.py), in eta a1, a1^2, a1^3, a1^3
//                         (sphere 1 the smaller; docs/resistance.md, "Tangential pair calibration")
// (squeeze: by Sherman-Morrison the block s e e^T, e = (1, -1), adds s to the solver's resistance F/V;
// every block adds to the solver's resistance matrix in Eq. 31, so R^SG = R^th - R^FDM holds for the
// tangential 2x2 block as a whole). Between tabulated a1/Delta and a2/a1 s_hat is interpolated linearly;
// outside them a squeeze function does not apply and the model says so (std::runtime_error naming the
// values and what the table covers); a tangential wall or pair function the table lacks stays the
// cut-off model's.
#ifndef FDM_RESISTANCE_SUBGRID_CALIBRATION_HPP
#define FDM_RESISTANCE_SUBGRID_CALIBRATION_HPP

#include "fdm/resistance/subgrid.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <string>
#include <vector>

namespace fdm {
namespace resistance {

// What a block of the table calibrates (its kind in the file: pair, wall, wall_YA, ...).
enum CalibratedFunction { PairSqueeze, WallSqueeze, WallTangentialYA, WallTangentialYB, WallTangentialYC,
                          WallTangentialXC, PairSliding, PairSlidingRolling, PairRolling, PairTwist,
                          NumCalibratedFunctions };
inline bool isPairFunction(CalibratedFunction f) { return f == PairSqueeze || f >= PairSliding; }
const char* calibratedFunctionName(CalibratedFunction f);  // the kind written in the table

class SubgridCalibration {
public:
    struct Block {
        CalibratedFunction function;
        double aOverDelta, ratio;
        std::vector<double> logXi, xiS;  // ln xi and xi * s_hat(xi), increasing xi; the last xiS is 0
        bool wall() const { return !isPairFunction(function); }
        double xiMax() const { return logXi.empty() ? 0 : std::exp(logXi.back()); }
        double sHat(double xi) const { return sHatAt(std::log(std::max(xi, 1e-300)), xi); }
        double sHatAt(double logXi, double xi) const;  // sHat with ln xi already taken
    };

    SubgridCalibration() {}
    // a copy shares no cached stencil (they point into their own object's blocks)
    SubgridCalibration(const SubgridCalibration& other) : blocks_(other.blocks_), path_(other.path_) {}
    SubgridCalibration& operator=(const SubgridCalibration& other)
    {
        blocks_ = other.blocks_;
        path_ = other.path_;
        stencils_.clear();
        lastPair_ = LastPair();
        return *this;
    }

    // Reads the table; std::runtime_error with the file and line on anything malformed.
    static SubgridCalibration read(const std::string& path);
    // The table shipped in the repository: $FDM_ROOT/dem/resistance/data/subgrid_calibration.dat, else the
    // source tree this library was built from.
    static std::string defaultPath();

    // s_hat of a pair (radii in any order) or a sphere and a wall, mesh size delta; std::runtime_error
    // if a/Delta or the ratio is outside the table (`covers` says whether it is).
    double pairSHat(double a1, double a2, double delta, double xi) const;
    double wallSHat(double a, double delta, double eps) const;
    bool coversPair(double a1, double a2, double delta) const;
    bool coversWall(double a, double delta) const;
    // a tangential wall function (WallTangentialYA ... XC): false where the table lacks it, else s_hat
    bool wallFunctionSHat(CalibratedFunction f, double a, double delta, double eps, double& sHat) const;
    bool coversWallFunction(CalibratedFunction f, double a, double delta) const;
    // the pair's K = [K11, K12, K22, K_twist] at xi, dimensional (eta = 1) for sphere 1 of radius a1 (K12
    // changes sign with the labels: the sliding mode q1 does); false where the table lacks them
    bool pairInternalCorrection(double a1, double a2, double delta, double xi, double K[4]) const;
    double pairRange(double a1, double a2, double delta) const;  // largest xi with a correction
    double wallRange(double a, double delta) const;             // over every wall function covered
    std::string coverage() const;  // "pairs (a1/Delta, a2/a1) (3, 1), ...; walls a/Delta (3), ...; ..."
    const std::string& path() const { return path_; }
    const std::vector<Block>& blocks() const { return blocks_; }

private:
    // The blocks around (aOverDelta, ratio) and their bilinear weights, found once per radius pair
    // (cached: a suspension has a few radius pairs; the cache makes the class not thread-safe, as
    // the cut-off model).
    struct Stencil {
        CalibratedFunction function;
        double aOverDelta, ratio;
        bool covered;
        int n;
        const Block* block[4];
        double weight[4];
        double xiMax;
    };
    const Stencil& stencil(CalibratedFunction function, double aOverDelta, double ratio) const;
    std::vector<Block> blocks_;
    std::string path_;
    mutable std::deque<Stencil> stencils_;  // a deque: references to its elements survive push_back
    // the pair's stencils (squeeze, then sliding, coupling, rolling, twist) and their range for the last
    // radius pair asked: a suspension asks for the same few pairs over and over, so no search per block
    struct LastPair {
        double small = -1, large = -1, delta = -1;
        const Stencil* squeeze = nullptr;
        const Stencil* internal[4] = {nullptr, nullptr, nullptr, nullptr};
        double range = 0;
    };
    mutable LastPair lastPair_;
    const LastPair& pairStencils(double a1, double a2, double delta) const;
};

// Appendix C.2's tangential base functions of the block P^T K P, K = [K11, K12, K22, K_twist] on the
// internal modes q1 = (U1 - U2).e + (r/2)(W1 + W2).n, q2 = (W1 - W2).n and the twist (W1 - W2).d
// (r the centre distance; any radii): Y21A = -K11, Y21B = K12 + (r/2) Y21A,
// Y11C = K22 + r Y21B - (3 r^2/4) Y21A, X21C = -K_twist.
void pairBaseFromInternal(const double K[4], double r, PairSubgridBase& base);

// The cut-off model with the functions the table calibrates replaced: the squeeze functions (pair X21A,
// wall X^A; required) and, where the table has them, the tangential wall functions Y^A, Y^B, Y^C, X^C and
// the pair's Y21A, Y21B, Y11C, X21C (from K on the internal modes: pairBaseFromInternal). The base stresslet
// functions (X11G, Y11G, X12P, X21P) stay the cut-off model's; through C.2 and the average over the
// labellings the squeeze stresslet the pair style applies still follows the calibrated X21A (for equal
// spheres X^G_11 = -r X21A/2: within 5 % of the theory, measured; docs/resistance.md, "The pair's squeeze
// stresslet"), and so does the sliding mode's. Y21H is the cut-off model's plus what keeps the rolling
// mode's stresslet the cut-off model's when Y21A, Y21B are calibrated (docs/resistance.md, "The pair's
// shear-mode stresslets"). A wall's X^G is the cut-off model's.
// Dissipation rule for a wall (docs/resistance.md): the correction may take away at most half of what
// the solver itself resolves, R^SG + R^FDM/2 >= 0 with R^FDM = R^th - R^SG, i.e. R^th + R^SG positive
// semi-definite for the tangential block [[Y^A, -Y^B], [-Y^B, Y^C]] (dimensional) and X^C. Y^A, Y^C,
// X^C are clipped at minus the theory and |Y^B_th + Y^B_SG| at sqrt((Y^A_th + Y^A_SG)(Y^C_th + Y^C_SG));
// wallClipped() counts the calls that changed anything. (The correction alone may be indefinite: the
// solver over-couples translation and rotation at gaps of about 0.3 cell, and taking that coupling
// away is what makes a free sphere turn at the theory's rate.)
class CalibratedSubgridModel : public SubgridModel {
public:
    CalibratedSubgridModel(const SubgridCalibration& calibration, double meshSize, double cutoffCells,
                           double wallCutoffCells);
    double pairRange(double a1, double a2) const;
    double wallRange(double a) const;
    PairSubgridBase pair(double a1, double a2, double xi) const;
    WallScalars wall(double a, double eps) const;
    const char* describe() const;
    long wallClipped() const { return wallClipped_; }

private:
    SubgridCalibration calibration_;
    double meshSize_;
    CutoffSubgridModel pairCutoff_, wallCutoff_;
    std::string description_;
    mutable long wallClipped_ = 0;
};

}  // namespace resistance
}  // namespace fdm

#endif
