#include "fdm/resistance/two_sphere.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace fdm {
namespace resistance {

double kimKarrilaFactor(PairFunction f, double a)
{
    const double pi = 3.14159265358979323846;
    switch (f) {
    case XA: case YA: return 6 * pi * a;
    case YB: case XG: case YG: return 4 * pi * a * a;
    case XC: case YC: case YH: return 8 * pi * a * a * a;
    case XM: case YM: case ZM: return 20.0 / 3.0 * pi * a * a * a;
    case XP: return 6 * pi * a * a;
    case XQ: return 6 * pi * a * a * a;  // this library's choice: C.1 reads X11Q + X12Q = (r/2a1)(X11P - X12P) + regular
    default: return 0;
    }
}

// Eq. (A.4): the functions odd under d -> -d change sign when the roles of the spheres swap (not X^Q:
// Q_ab = X^Q_ab (dd - I/3) is even in d).
static double swapSign(PairFunction f) { return (f == YB || f == XG || f == YG || f == XP) ? -1.0 : 1.0; }

PairForms makePairForms(double a1, double a2, bool withM)
{
    if (!(a1 > 0 && a2 > 0)) throw std::invalid_argument("makePairForms: radii must be positive");
    const double lambda = a2 / a1;
    const NearFieldConstants k = computeNearFieldConstants(lambda, withM);
    const NearFieldConstants kSwapped = (lambda == 1.0) ? k : computeNearFieldConstants(1.0 / lambda, withM);
    PairForms p;
    p.a1 = a1;
    p.a2 = a2;
    p.hasMFunctions = withM;
    for (int i = 0; i < NumPairFunctions; ++i) {
        const PairFunction f = PairFunction(i);
        const double s1 = kimKarrilaFactor(f, a1), s2 = swapSign(f) * kimKarrilaFactor(f, a2);
        p.f[f][0][0] = k.f11[f].scaled(s1);
        p.f[f][0][1] = k.f12[f].scaled(s1);
        p.f[f][1][0] = kSwapped.f12[f].scaled(s2);
        p.f[f][1][1] = kSwapped.f11[f].scaled(s2);
    }
    return p;
}

PairFunctionValues evaluate(const PairForms& forms, double xi)
{
    xi = std::max(xi, minimumGap);
    const double logInvXi = std::log(1.0 / xi);
    PairFunctionValues v;
    const int n = forms.hasMFunctions ? NumPairFunctions : XM;
    for (int f = 0; f < NumPairFunctions; ++f)
        for (int a = 0; a < 2; ++a)
            for (int b = 0; b < 2; ++b) v.f[f][a][b] = (f < n || f == XP) ? forms.f[f][a][b](xi, logInvXi) : 0.0;
    return v;
}

PairFullRangeForms makeFullRangeForms(double a1, double a2, bool withM, int order)
{
    PairFullRangeForms p;
    p.nearField = makePairForms(a1, a2, withM);  // checks the radii
    const double lambda = a2 / a1;
    p.k = computeFullRangeConstants(lambda, order);
    p.kSwapped = (lambda == 1.0) ? p.k : computeFullRangeConstants(1.0 / lambda, order);
    return p;
}

PairFunctionValues fullRange(const PairFullRangeForms& forms, double xi)
{
    xi = std::max(xi, minimumGap);
    PairFunctionValues v = evaluate(forms.nearField, xi);
    const double a1 = forms.nearField.a1, a2 = forms.nearField.a2;
    for (int i = 0; i < NumPairFunctions; ++i) {
        const PairFunction f = PairFunction(i);
        if (!hasFullRangeForm(f)) continue;
        // 11 and 12 at lambda with a1; 21 and 22 = 12 and 11 at 1/lambda with a2, Eq. (A.4)
        const double s1 = kimKarrilaFactor(f, a1), s2 = swapSign(f) * kimKarrilaFactor(f, a2);
        v.f[f][0][0] = s1 * fullRangeScalar(forms.k, f, false, xi);
        v.f[f][0][1] = s1 * fullRangeScalar(forms.k, f, true, xi);
        v.f[f][1][0] = s2 * fullRangeScalar(forms.kSwapped, f, true, xi);
        v.f[f][1][1] = s2 * fullRangeScalar(forms.kSwapped, f, false, xi);
    }
    return v;
}

PairFunctionValues fullRange(const PairForms& forms, double xi)
{
    PairFullRangeForms p;
    p.nearField = forms;
    const double lambda = forms.a2 / forms.a1;
    p.k = computeFullRangeConstants(lambda);
    p.kSwapped = (lambda == 1.0) ? p.k : computeFullRangeConstants(1.0 / lambda);
    return fullRange(p, xi);
}

const PairFullRangeForms& TwoSphereTheory::fullRangeForms(double a1, double a2)
{
    const std::pair<double, double> key(a1, a2);
    std::map<std::pair<double, double>, PairFullRangeForms>::iterator it = fullCache_.find(key);
    if (it == fullCache_.end()) it = fullCache_.insert(std::make_pair(key, makeFullRangeForms(a1, a2, withM_))).first;
    return it->second;
}

const PairForms& TwoSphereTheory::forms(double a1, double a2)
{
    if (last_ && last_->a1 == a1 && last_->a2 == a2) return *last_;
    const std::pair<double, double> key(a1, a2);
    std::map<std::pair<double, double>, PairForms>::iterator it = cache_.find(key);
    if (it == cache_.end()) it = cache_.insert(std::make_pair(key, makePairForms(a1, a2, withM_))).first;
    last_ = &it->second;
    return *last_;
}

}  // namespace resistance
}  // namespace fdm
