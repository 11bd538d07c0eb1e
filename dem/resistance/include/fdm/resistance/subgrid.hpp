// Sub-grid resistance functions = theory - what the fluid solver resolves (paper section 2.2, Appendix B).
//
// Only the 10 independent functions of paper Appendix C.2 are computed for a pair; every other entry of
// the frame-invariant sub-grid matrix follows from the relations of Appendix C.2 (expandAppendixC2).
// For a wall: X^A, Y^A, Y^B, X^C, Y^C, X^G, X^P are computed; Y^G, Y^H follow from Eq. (D.4).
// All values are dimensional, divided by the viscosity.
#ifndef FDM_RESISTANCE_SUBGRID_HPP
#define FDM_RESISTANCE_SUBGRID_HPP

#include "fdm/resistance/sphere_wall.hpp"
#include "fdm/resistance/two_sphere.hpp"

namespace fdm {
namespace resistance {

// Appendix C.2's choice of independent functions.
enum SubgridBaseFunction { BaseX21A, BaseY21A, BaseY21B, BaseX21C, BaseY11C, BaseX11G, BaseY11G, BaseY21H, BaseX12P, BaseX21P, NumSubgridBase };
const char* subgridBaseName(SubgridBaseFunction f);

struct PairSubgridBase {
    double f[NumSubgridBase];
};

// Every sub-grid function of the pair from the 10 base ones (paper Appendix C.2); r = |x2 - x1|.
// YBtilde[alpha][beta] = -YB[beta][alpha] (Eq. A.3) is what multiplies the rotations in the force rows.
PairFunctionValues expandAppendixC2(const PairSubgridBase& base, double r);

// Dissipation safeguard, applied by every model after computing the base functions.  With the C.2
// relations the pair block is R = P^T K P, K acting on the 6 internal modes: squeeze (-X21A), twist
// (-X21C) and, for each transverse direction, the 2x2 block [[Y11A, Y11B], [Y11B, Y11C]] with
// Y11A = -Y21A, Y11B = -Y21B + r Y21A.  R is positive semi-definite iff these are.  Differences of
// theoretical functions need not be (near the cut-off they are differences of small numbers), so the
// safeguard clips -X21A, -Y21A, -X21C, Y11C at zero and |Y11B| at sqrt(Y11A Y11C) (through Y21B).
// Frame invariance is untouched (the C.2 structure is kept).  Returns true if anything was changed.
bool makeDissipative(PairSubgridBase& base, double r);

// The "resolved part" interface: a model says, for a pair or a particle and a wall, what the sub-grid
// correction of the independent functions is, and beyond which gap it vanishes.
class SubgridModel {
public:
    virtual ~SubgridModel() {}
    // Largest reduced gap xi (pair) with a non-zero correction; blocks beyond it are skipped.
    virtual double pairRange(double a1, double a2) const = 0;
    virtual double wallRange(double a) const = 0;
    // The 10 independent sub-grid functions, after makeDissipative; xi = 2r/(a1+a2) - 2.
    virtual PairSubgridBase pair(double a1, double a2, double xi) const = 0;
    // Wall sub-grid functions (Y^G, Y^H included, from Eq. D.4); eps = h/a - 1.
    virtual WallScalars wall(double a, double eps) const = 0;
    virtual const char* describe() const = 0;
};

// Every sub-grid function of a pair as the blocks use it: Appendix C.2's expansion averaged over the two
// labellings of the pair. C.2 takes Y^C_11 (not Y^C_22), Y^B_21, X^G_11, Y^G_11, ... as independent and
// derives the rest through the rigid-body relations, so with any model that is not exact the derived
// functions differ from their mirror images (cut-off model, equal spheres, xi 0.1, a/Delta 3: Y^C_11
// 5.41 against Y^C_22 3.72) and a pair's block depended on which sphere LIGGGHTS calls i. The functions
// of the relabelled pair (radii a2, a1, d -> -d: model.pair(a2, a1, xi)) are put back in this pair's
// labels with the parity of each tensor form of Eq. (A.1) under d -> -d (A, C, H even; B, G, P odd) and
// averaged with this labelling's. The C.2 relations are linear and the same for both labellings, so the
// average keeps them (frame invariance, Eq. 24), and a mean of positive semi-definite blocks is one.
// r = |x2 - x1|.
PairFunctionValues subgridPairFunctions(const SubgridModel& model, double a1, double a2, double xi, double r);

// pair_style fdm/subgrid's default cut-off gaps, in mesh cells (docs/dem.md; chosen from the squeeze
// flows): the cut-off model, and the functions the calibrated model takes from it
const double defaultPairCutoffCells = 0.65, defaultWallCutoffCells = 0.75;

// Placeholder for the calibration of Appendix B: the solver is assumed to resolve the theory down to a
// cut-off gap of k mesh cells, xi_c = k Delta / a_mean (a_mean = (a1 + a2)/2), eps_c = k Delta / a,
// and nothing below:
//   f_SG(xi) = f_th(max(xi, 1e-5)) - f_th(xi_c)  for xi < xi_c,   0 beyond.
// Caches the near-field forms per radius pair (mutable cache: one instance per thread).
class CutoffSubgridModel : public SubgridModel {
public:
    explicit CutoffSubgridModel(double meshSize, double cutoffCells = 1.0);
    double pairRange(double a1, double a2) const;
    double wallRange(double a) const;
    PairSubgridBase pair(double a1, double a2, double xi) const;
    WallScalars wall(double a, double eps) const;
    const char* describe() const;
    double meshSize() const { return meshSize_; }
    double cutoffCells() const { return cutoffCells_; }

private:
    struct PairEntry {
        double a1, a2, xiCut;
        NearFieldForm base[NumSubgridBase];
        double frozen[NumSubgridBase];  // theory at the cut-off
    };
    const PairEntry& entry(double a1, double a2) const;
    double meshSize_, cutoffCells_;
    mutable TwoSphereTheory theory_;
    mutable std::map<std::pair<double, double>, PairEntry> cache_;
    mutable const PairEntry* last_ = nullptr;
    mutable double lastWallRadius_ = -1;
    mutable WallScalars lastWallFrozen_;
};

// The theoretical near-field forms of the 10 independent functions, taken from the full set.
void selectSubgridBaseForms(const PairForms& forms, NearFieldForm out[NumSubgridBase]);

}  // namespace resistance
}  // namespace fdm

#endif
