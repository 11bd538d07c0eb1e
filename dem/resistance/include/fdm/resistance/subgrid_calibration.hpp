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
// (squeeze: by Sherman-Morrison the block s e e^T, e = (1, -1), adds s to the solver's resistance F/V;
// every block adds to the solver's resistance matrix in Eq. 31, so R^SG = R^th - R^FDM holds for the
// tangential 2x2 block as a whole). Between tabulated a1/Delta and a2/a1 s_hat is interpolated linearly;
// outside them a squeeze function does not apply and the model says so (std::runtime_error naming the
// values and what the table covers); a tangential wall function the table lacks stays the cut-off
// model's.
#ifndef FDM_RESISTANCE_SUBGRID_CALIBRATION_HPP
#define FDM_RESISTANCE_SUBGRID_CALIBRATION_HPP

#include "fdm/resistance/subgrid.hpp"

#include <cmath>
#include <string>
#include <vector>

namespace fdm {
namespace resistance {

// What a block of the table calibrates (its kind in the file: pair, wall, wall_YA, ...).
enum CalibratedFunction { PairSqueeze, WallSqueeze, WallTangentialYA, WallTangentialYB, WallTangentialYC,
                          WallTangentialXC, NumCalibratedFunctions };
const char* calibratedFunctionName(CalibratedFunction f);  // the kind written in the table

class SubgridCalibration {
public:
    struct Block {
        CalibratedFunction function;
        double aOverDelta, ratio;
        std::vector<double> logXi, xiS;  // ln xi and xi * s_hat(xi), increasing xi; the last xiS is 0
        bool wall() const { return function != PairSqueeze; }
        double xiMax() const { return logXi.empty() ? 0 : std::exp(logXi.back()); }
        double sHat(double xi) const;    // 0 from xiMax; below the first row xi * s_hat is held
    };

    SubgridCalibration() {}
    // a copy shares no cached stencil (they point into their own object's blocks)
    SubgridCalibration(const SubgridCalibration& other) : blocks_(other.blocks_), path_(other.path_) {}
    SubgridCalibration& operator=(const SubgridCalibration& other)
    {
        blocks_ = other.blocks_;
        path_ = other.path_;
        stencils_.clear();
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
    mutable std::vector<Stencil> stencils_;
};

// The cut-off model with the functions the table calibrates replaced: the squeeze functions (pair X21A,
// wall X^A; required) and, where the table has them, the tangential wall functions Y^A, Y^B, Y^C, X^C.
// The other functions stay the cut-off model's until their calibration exists (docs/resistance.md).
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
