// Two-sphere theoretical resistance functions for radii (a1, a2), dimensional (divided by the viscosity).
//
// f[family][alpha][beta] follows paper Eq. (A.1): alpha = sphere feeling the force/torque/stresslet,
// beta = sphere whose motion causes it (0 = sphere 1, 1 = sphere 2); d = (x2 - x1)/|x2 - x1|.
// 11 and 12: the Kim-Karrila scalars at lambda = a2/a1 times 6 pi a1 (A), 4 pi a1^2 (B, G),
// 8 pi a1^3 (C, H), 20/3 pi a1^3 (M), 6 pi a1^2 (P), 6 pi a1^3 (Q).  21 and 22: paper Eq. (A.4), i.e. the 12
// and 11 scalars at 1/lambda, times the same factors built on a2, with a minus sign for B, G and P (d reverses).
// X^Q (and X^M, Y^M, Z^M) only when built withM; otherwise their values are zero.
#ifndef FDM_RESISTANCE_TWO_SPHERE_HPP
#define FDM_RESISTANCE_TWO_SPHERE_HPP

#include "fdm/resistance/full_range_forms.hpp"
#include "fdm/resistance/near_field_constants.hpp"

#include <map>
#include <utility>

namespace fdm {
namespace resistance {

// Smallest gap used anywhere (paper section 4.2): the functions are frozen below it.
const double minimumGap = 1e-5;

// Kim-Karrila normalising factor (without the viscosity) of a family for a sphere of radius a.
double kimKarrilaFactor(PairFunction f, double a);

struct PairForms {
    double a1 = 1, a2 = 1;
    bool hasMFunctions = false;
    NearFieldForm f[NumPairFunctions][2][2];
};

// Values of every function at one gap, dimensional / viscosity, [family][alpha][beta].
struct PairFunctionValues {
    double f[NumPairFunctions][2][2];
};

PairForms makePairForms(double a1, double a2, bool withM = false);
PairFunctionValues evaluate(const PairForms& forms, double xi);  // xi floored at minimumGap

// Full-range theory (docs/resistance.md, "Full-range forms"): X^A, Y^A, Y^B, Y^C from the matched forms
// of J&O (near-field singular terms plus the far-field series with their own expansion subtracted),
// X^C from its exact series (Jeffery 1915), valid at every gap; the other families (X^G, Y^G, Y^H, M, P, Q)
// are the near-field forms, as in evaluate().  The near-field forms themselves (evaluate, makePairForms,
// the sub-grid model) are unchanged.  Same layout and units as evaluate(): [family][alpha][beta],
// dimensional / viscosity; 21 and 22 from the 1/lambda constants by Eq. (A.4).
struct PairFullRangeForms {
    PairForms nearField;                // every family; the values of the families without a full-range form
    FullRangeConstants k, kSwapped;     // lambda = a2/a1 (11, 12) and 1/lambda (22, 21)
};
// order: far-field powers kept (fullRangeDefaultOrder = 100, T23's truncation; converged to < 5e-4 for
// 0.1 <= lambda <= 10, see the documentation before using more extreme size ratios).
PairFullRangeForms makeFullRangeForms(double a1, double a2, bool withM = false, int order = fullRangeDefaultOrder);
PairFunctionValues fullRange(const PairFullRangeForms& forms, double xi);  // xi floored at minimumGap
// Convenience: builds the full-range constants of (forms.a1, forms.a2) at every call (~0.1 ms, plus
// ~0.1 s once per process); the M values follow forms.hasMFunctions.  Prefer the cached
// TwoSphereTheory::fullValues in loops.
PairFunctionValues fullRange(const PairForms& forms, double xi);

// Caches the forms per distinct radius pair: the O(1) constants cost ~0.1 ms per new lambda (series
// sums) and nothing afterwards.  Not thread-safe: use one instance per thread.
class TwoSphereTheory {
public:
    explicit TwoSphereTheory(bool withM = false) : withM_(withM) {}
    const PairForms& forms(double a1, double a2);
    PairFunctionValues values(double a1, double a2, double xi) { return evaluate(forms(a1, a2), xi); }
    // Full-range values (fullRange above), with their own cache; values() is not affected.
    const PairFullRangeForms& fullRangeForms(double a1, double a2);
    PairFunctionValues fullValues(double a1, double a2, double xi) { return fullRange(fullRangeForms(a1, a2), xi); }
    std::size_t cachedPairs() const { return cache_.size(); }

private:
    bool withM_;
    std::map<std::pair<double, double>, PairForms> cache_;
    const PairForms* last_ = nullptr;
    std::map<std::pair<double, double>, PairFullRangeForms> fullCache_;
};

}  // namespace resistance
}  // namespace fdm

#endif
