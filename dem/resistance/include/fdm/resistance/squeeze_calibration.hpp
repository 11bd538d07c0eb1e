// The solver's own squeeze resistance, measured (paper section 2.2 and Appendix B): R^SG = R^th - R^FDM
// for the squeeze modes, instead of the cut-off model's assumption of what the mesh resolves.
//
// The table is written by `python3 -m fdmsubgrid.calibration` (scripts/fdmsubgrid/calibration.py, which
// explains the measurement: two spheres, or a sphere and a wall, pushed together with the sub-grid
// lubrication off, box effect extrapolated away, averaged over positions in the mesh cell). Per
// (kind, a1/Delta, a2/a1) it holds xi * s_hat(xi) on a logarithmic grid, s_hat the squeeze resistance the
// block must add in units of 6 pi eta a1 (a1 the smaller sphere):
//     pair: X21A^SG = -6 pi a1 s_hat(xi)      wall: X^A_SG = 6 pi a s_hat(eps)
// (by Sherman-Morrison, the block s e e^T, e = (1, -1), adds s to the solver's squeeze resistance F/V).
// Between tabulated a1/Delta and a2/a1 s_hat is interpolated linearly; outside them the table does not
// apply and the model says so (std::runtime_error naming the values and what the table covers).
#ifndef FDM_RESISTANCE_SQUEEZE_CALIBRATION_HPP
#define FDM_RESISTANCE_SQUEEZE_CALIBRATION_HPP

#include "fdm/resistance/subgrid.hpp"

#include <cmath>
#include <string>
#include <vector>

namespace fdm {
namespace resistance {

class SqueezeCalibration {
public:
    struct Block {
        bool wall;
        double aOverDelta, ratio;
        std::vector<double> logXi, xiS;  // ln xi and xi * s_hat(xi), increasing xi; the last xiS is 0
        double xiMax() const { return logXi.empty() ? 0 : std::exp(logXi.back()); }
        double sHat(double xi) const;    // 0 from xiMax; below the first row xi * s_hat is held
    };

    SqueezeCalibration() {}
    // a copy shares no cached stencil (they point into their own object's blocks)
    SqueezeCalibration(const SqueezeCalibration& other) : blocks_(other.blocks_), path_(other.path_) {}
    SqueezeCalibration& operator=(const SqueezeCalibration& other)
    {
        blocks_ = other.blocks_;
        path_ = other.path_;
        stencils_.clear();
        return *this;
    }

    // Reads the table; std::runtime_error with the file and line on anything malformed.
    static SqueezeCalibration read(const std::string& path);
    // The table shipped in the repository: $FDM_ROOT/dem/resistance/data/squeeze_calibration.dat, else the
    // source tree this library was built from.
    static std::string defaultPath();

    // s_hat of a pair (radii in any order) or a sphere and a wall, mesh size delta; std::runtime_error
    // if a/Delta or the ratio is outside the table (`covers` says whether it is).
    double pairSHat(double a1, double a2, double delta, double xi) const;
    double wallSHat(double a, double delta, double eps) const;
    bool coversPair(double a1, double a2, double delta) const;
    bool coversWall(double a, double delta) const;
    double pairRange(double a1, double a2, double delta) const;  // largest xi with a correction
    double wallRange(double a, double delta) const;
    std::string coverage() const;  // "pairs a1/Delta 3..5, a2/a1 1..1.4; walls a/Delta 3..5"
    const std::string& path() const { return path_; }
    const std::vector<Block>& blocks() const { return blocks_; }

private:
    // The blocks around (aOverDelta, ratio) and their bilinear weights, found once per radius pair
    // (cached: a suspension has a few radius pairs; the cache makes the class not thread-safe, as
    // the cut-off model).
    struct Stencil {
        bool wall;
        double aOverDelta, ratio;
        bool covered;
        int n;
        const Block* block[4];
        double weight[4];
        double xiMax;
    };
    const Stencil& stencil(bool wall, double aOverDelta, double ratio) const;
    std::vector<Block> blocks_;
    std::string path_;
    mutable std::vector<Stencil> stencils_;
};

// The cut-off model with its squeeze functions (pair X21A, wall X^A) replaced by the calibration.
// The other functions stay the cut-off model's until their calibration exists (docs/resistance.md).
class CalibratedSubgridModel : public SubgridModel {
public:
    CalibratedSubgridModel(const SqueezeCalibration& calibration, double meshSize, double cutoffCells,
                           double wallCutoffCells);
    double pairRange(double a1, double a2) const;
    double wallRange(double a) const;
    PairSubgridBase pair(double a1, double a2, double xi) const;
    WallScalars wall(double a, double eps) const;
    const char* describe() const;

private:
    SqueezeCalibration calibration_;
    double meshSize_;
    CutoffSubgridModel pairCutoff_, wallCutoff_;
    std::string description_;
};

}  // namespace resistance
}  // namespace fdm

#endif
