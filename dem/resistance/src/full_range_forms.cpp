// Full-range forms: J&O's matched forms of X^A, Y^A, Y^B, Y^C and the exact X^C series, valid at every
// gap (sources in full_range_forms.hpp).
#include "fdm/resistance/full_range_forms.hpp"

#include "far_field_series_store.hpp"

#include <cmath>
#include <stdexcept>

namespace fdm {
namespace resistance {

using detail::FullRangeSeries;
using detail::SeriesTriangle;
using detail::fullRangeSeries;

namespace {

// Remainder coefficients a_m - g1 - 2 g2/m + 4 g3/(m(m+2)) of one parity (the g2, g3 terms only for
// m >= 1: S2 and S3 have no constant term).
MatchedForm matchedForm(const SeriesTriangle& series, double lambda, int order, bool odd, double sign, double g1,
                        double g2, double g3)
{
    MatchedForm f;
    f.odd = odd;
    f.sign = sign;
    f.g1 = g1;
    f.g2 = g2;
    f.g3 = g3;
    for (int m = odd ? 1 : 0; m <= order; m += 2) {
        double r = series.normalisedTerm(m, lambda) - g1;
        if (m > 0) r += -2 * g2 / m + 4 * g3 / (double(m) * (m + 2));
        f.remainder.push_back(r);
    }
    return f;
}

// sum_{n >= 0} (sinh(ref) / sinh(x0 + n delta))^3: direct terms, and for small delta an Euler-Maclaurin
// tail with the closed form int_Y^inf csch^3 = (csch Y coth Y + ln tanh(Y/2)) / 2 (as wallNormalRotation).
double cschCubedSum(double ref, double x0, double delta)
{
    const int K = 60;
    const double sinhRef = std::sinh(ref);
    double sum = 0;
    for (int n = 0; n < K; ++n) {
        const double y = x0 + n * delta;
        if (y > x0 + 40) return sum;  // the remaining terms are below e^-120 relative to the first
        const double c = sinhRef / std::sinh(y);
        sum += c * c * c;
    }
    // here K delta < 40: nothing overflows
    const double Y = x0 + K * delta;
    const double cschY = 1 / std::sinh(Y), cothY = 1 / std::tanh(Y);
    const double integral = 0.5 * (cschY * cothY + std::log(std::tanh(0.5 * Y))) / delta;
    const double fY = cschY * cschY * cschY;
    const double dfY = -3 * delta * fY * cothY;  // d/dn csch^3(x0 + n delta) at n = K
    return sum + sinhRef * sinhRef * sinhRef * (integral + 0.5 * fY - dfY / 12);
}

// S1, S2, S3 of full_range_forms.hpp at xi, written with xi so that nothing cancels near contact.
void singularFunctions(bool odd, double xi, double t, double s[3])
{
    const double x = t * t;
    const double oneMinusX = xi * (4 + xi) / ((2 + xi) * (2 + xi));  // 1 - t^2 = 1 - 4/s'^2
    if (!odd) {
        const double logOneMinusX = (x < 0.5) ? std::log1p(-x) : std::log(oneMinusX);
        s[0] = 1 / oneMinusX;
        s[1] = -logOneMinusX;
        s[2] = -1 - oneMinusX * logOneMinusX / x;
    } else {
        const double logRatio = (t < 0.5) ? 2 * std::atanh(t) : std::log((4 + xi) / xi);  // ln((1+t)/(1-t))
        s[0] = t / oneMinusX;
        s[1] = logRatio;
        s[2] = -2 / t + oneMinusX * logRatio / x;
    }
}

}  // namespace

double MatchedForm::operator()(double xi) const
{
    const double t = 2 / (2 + xi), x = t * t;
    const int order = 2 * int(remainder.size()) - (odd ? 1 : 2);
    if (order * std::log(1 / t) > 40) {
        // far out: t^order < e^-40, the plain far-field series a_m t^m has converged; summing it avoids the
        // cancellation between S1-S3 and the remainder (S3 ~ 2/t - 2/t there)
        double sum = 0;
        for (std::size_t j = remainder.size(); j-- > 0;) {
            const double m = 2.0 * j + (odd ? 1 : 0);
            double a = remainder[j] + g1;
            if (m > 0) a += 2 * g2 / m - 4 * g3 / (m * (m + 2));
            sum = sum * x + a;
        }
        if (odd) sum *= t;
        return sign * sum;
    }
    double sing[3];
    singularFunctions(odd, xi, t, sing);
    double sum = 0;  // Horner in t^2, then the odd power
    for (std::size_t j = remainder.size(); j-- > 0;) sum = sum * x + remainder[j];
    if (odd) sum *= t;
    return sign * (g1 * sing[0] + g2 * sing[1] + g3 * sing[2] + sum);
}

void exactRotationAboutLineOfCentres(double lambda, double xi, double& x11, double& x12)
{
    if (!(lambda > 0) || !(xi > 0)) throw std::invalid_argument("exactRotationAboutLineOfCentres: lambda and xi must be positive");
    // a1 = 1, a2 = lambda, h = r - a1 - a2; focal distance c^2 = h (2(a1+a2) + h) (r^2 - (a1-a2)^2) / (4 r^2)
    const double h = 0.5 * (1 + lambda) * xi, r = 1 + lambda + h;
    const double c = std::sqrt(h * (2 * (1 + lambda) + h) * (r - 1 + lambda) * (r + 1 - lambda)) / (2 * r);
    const double mu1 = std::asinh(c), mu2 = std::asinh(c / lambda), delta = mu1 + mu2;
    x11 = cschCubedSum(mu1, mu1, delta);
    x12 = -cschCubedSum(mu1, delta, delta);
}

bool hasFullRangeForm(PairFunction f)
{
    return f == XA || f == YA || f == YB || f == XC || f == YC || f == XG || f == YG || f == YH;
}

FullRangeConstants computeFullRangeConstants(double lam, int order)
{
    if (!(lam > 0)) throw std::invalid_argument("computeFullRangeConstants: lambda must be positive");
    if (order < 10) throw std::invalid_argument("computeFullRangeConstants: order must be at least 10");
    const FullRangeSeries& series = fullRangeSeries(order);
    const NearFieldConstants near = computeNearFieldConstants(lam, false);  // singular coefficients (T23)
    FullRangeConstants k;
    k.lambda = lam;
    k.order = order;
    // X^A: J&O (3.17)-(3.18).  X11A = sum_even a_m t^m, X12A = -sum_odd a_m t^m (J&O (3.13)-(3.14) in
    // Kim-Karrila units); g1, g2, g3 of J&O (3.16), T23 (10)-(12).
    {
        const NearFieldForm& n = near.f11[XA];
        k.f11[XA] = matchedForm(series.xa, lam, order, false, 1, n.inv, n.log, n.xlog);
        k.f12[XA] = matchedForm(series.xa, lam, order, true, -1, n.inv, n.log, n.xlog);
    }
    // Y^A: J&O (4.12)-(4.18).  Y11A = sum_even, Y12A = -sum_odd.
    {
        const NearFieldForm& n = near.f11[YA];
        k.f11[YA] = matchedForm(series.ya, lam, order, false, 1, 0, n.log, n.xlog);
        k.f12[YA] = matchedForm(series.ya, lam, order, true, -1, 0, n.log, n.xlog);
    }
    // Y^B: J&O (5.2)-(5.7), T23 (21)-(25).  Y11B = sum_odd, Y12B = -sum_even.
    {
        const NearFieldForm& n = near.f11[YB];
        k.f11[YB] = matchedForm(series.yb, lam, order, true, 1, 0, n.log, n.xlog);
        k.f12[YB] = matchedForm(series.yb, lam, order, false, -1, 0, n.log, n.xlog);
    }
    // Y^C: J&O (7.6)-(7.12), T23 (29)-(34).  Y11C = sum_even (g2, g3), Y12C = +sum_odd (g4, g5).
    {
        const NearFieldForm& n11 = near.f11[YC];
        const NearFieldForm& n12 = near.f12[YC];
        k.f11[YC] = matchedForm(series.yc, lam, order, false, 1, 0, n11.log, n11.xlog);
        k.f12[YC] = matchedForm(series.yc, lam, order, true, 1, 0, n12.log, n12.xlog);
    }
    // The stresslet functions, matched the same way to the near-field forms of near_field_constants.cpp
    // (their O(1) constants are these sums at t = 1; no m = 0 term: a sphere's own motion gives it no
    // stresslet). X^G: J92 (19)-(21), X11G = sum_odd, X12G = -sum_even (Kim-Karrila with a1).
    {
        const NearFieldForm& n = near.f11[XG];
        k.f11[XG] = matchedForm(series.xg, lam, order, true, 1, n.inv, n.log, n.xlog);
        k.f12[XG] = matchedForm(series.xg, lam, order, false, -1, n.inv, n.log, n.xlog);
    }
    // Y^G: J92 (27)-(29), Y11G = sum_odd, Y12G = -sum_even.
    {
        const NearFieldForm& n = near.f11[YG];
        k.f11[YG] = matchedForm(series.yg, lam, order, true, 1, 0, n.log, n.xlog);
        k.f12[YG] = matchedForm(series.yg, lam, order, false, -1, 0, n.log, n.xlog);
    }
    // Y^H: J92 (35)-(37), Y11H = sum_even (g2, g3), Y12H = +sum_odd (g5, g6), as Y^C.
    {
        const NearFieldForm& n11 = near.f11[YH];
        const NearFieldForm& n12 = near.f12[YH];
        k.f11[YH] = matchedForm(series.yh, lam, order, false, 1, 0, n11.log, n11.xlog);
        k.f12[YH] = matchedForm(series.yh, lam, order, true, 1, 0, n12.log, n12.xlog);
    }
    return k;
}

double fullRangeScalar(const FullRangeConstants& k, PairFunction f, bool twelve, double xi)
{
    if (!hasFullRangeForm(f)) throw std::invalid_argument("fullRangeScalar: no full-range form for this family");
    if (f == XC) {
        double x11, x12;
        exactRotationAboutLineOfCentres(k.lambda, xi, x11, x12);
        return twelve ? x12 : x11;
    }
    return twelve ? k.f12[f](xi) : k.f11[f](xi);
}

}  // namespace resistance
}  // namespace fdm
