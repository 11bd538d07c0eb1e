// Near-contact forms of the two-sphere resistance scalars: singular coefficients in closed form, O(1)
// constants as subtracted sums over the far-field series (sources in near_field_constants.hpp).
#include "fdm/resistance/near_field_constants.hpp"

#include "far_field_series_store.hpp"

#include <cmath>
#include <stdexcept>

namespace fdm {
namespace resistance {

using detail::SeriesStore;
using detail::SeriesTriangle;
using detail::seriesStore;

double NearFieldForm::operator()(double xi) const { return (*this)(xi, std::log(1.0 / xi)); }

NearFieldForm NearFieldForm::scaled(double s) const
{
    NearFieldForm r;
    r.inv = s * inv;
    r.log = s * log;
    r.c0 = s * c0;
    r.xlog = s * xlog;
    return r;
}

double hurwitzZeta3(double a)
{
    // Direct sum of the first terms, Euler-Maclaurin for the tail (next term 0.15 x^-10 at x = K + a).
    const int K = 20;
    double sum = 0;
    for (int k = 0; k < K; ++k) sum += 1.0 / ((k + a) * (k + a) * (k + a));
    const double x = K + a, x2 = x * x;
    const double x4 = x2 * x2;
    return sum + 1.0 / (2 * x2) + 1.0 / (2 * x2 * x) + 1.0 / (4 * x4) - 1.0 / (12 * x4 * x2) + 1.0 / (12 * x4 * x4);
}

namespace {

// sum over m of parity (odd: 1, 3, ..., order-1; even: 2, 4, ..., order) of
//   f_m/(2(1+lambda))^m - g1 - 2 g2/m + 4 g3/(m(m+2))
// (the subtractions remove the terms that make the plain sums diverge: J&O (3.20)-(3.23)).
enum Parity { Odd, Even };
double subtractedSum(const SeriesTriangle& series, double lambda, Parity parity, int order, double g1, double g2, double g3)
{
    double sum = 0;
    const int first = (parity == Odd) ? 1 : 2;
    const int last = (parity == Odd) ? order - 1 : order;
    for (int m = first; m <= last; m += 2)
        sum += series.normalisedTerm(m, lambda) - g1 - 2 * g2 / m + 4 * g3 / (double(m) * (m + 2));
    return sum;
}

// sum_{j >= 0} (first + 2 j)^-2 = psi'(first/2) / 4, asymptotic series of the trigamma function (first >= 50:
// the next term is below 1e-14 relative).
double inverseSquareTail(int first)
{
    const double x = 0.5 * first, x2 = x * x;
    return 0.25 * (1 / x + 1 / (2 * x2) + 1 / (6 * x2 * x) - 1 / (30 * x2 * x2 * x));
}

// The part of a near-contact constant that comes from a pressure-moment series of one parity whose
// coefficients tend to g1 + 2 g2/m - 4 g3/m^2 + (oscillating, ~m^-3) with g3 not known in closed form:
// sum_{m <= M} (a_m - g1 - 2 g2/m) plus the tail sum_{m > M} L/m^2, L the mean of m^2 (a_m - g1 - 2 g2/m) over the
// powers M/2 <= m <= M of that parity (L = -4 g3 up to the oscillation).  Used for X^Q (docs/resistance.md).
double subtractedSumWithTail(const SeriesTriangle& series, double lambda, Parity parity, int M, double g1, double g2)
{
    const int first = (parity == Odd) ? 1 : 2, last = (parity == Odd) ? M - 1 : M;
    double level = 0;
    int count = 0;
    for (int m = first; m <= last; m += 2)
        if (2 * m >= M) {
            level += double(m) * m * (series.normalisedTerm(m, lambda) - g1 - 2 * g2 / m);
            ++count;
        }
    level /= count;
    return subtractedSum(series, lambda, parity, M, g1, g2, 0) + level * inverseSquareTail(last + 2);
}

NearFieldForm form(double inv, double log, double c0, double xlog)
{
    NearFieldForm f;
    f.inv = inv;
    f.log = log;
    f.c0 = c0;
    f.xlog = xlog;
    return f;
}

}  // namespace

NearFieldConstants computeNearFieldConstants(double lam, bool withM)
{
    if (!(lam > 0)) throw std::invalid_argument("computeNearFieldConstants: lambda must be positive");
    const SeriesStore& store = seriesStore(withM);
    const double L = std::log(2.0);
    const double l1 = 1 + lam, l2 = lam * lam, l3 = l2 * lam, l4 = l3 * lam;
    const double l1_2 = l1 * l1, l1_3 = l1_2 * l1;
    const int M = 100;  // truncation of the A, B, C, G, H sums (T23's generator)
    NearFieldConstants k;
    k.lambda = lam;
    k.hasMFunctions = withM;

    // X^A: J&O (3.17)-(3.23); singular coefficients J&O (3.16), T23 (10)-(12).
    {
        const double g1 = 2 * l2 / l1_3, g2 = lam * (1 + 7 * lam + l2) / (5 * l1_3);
        const double g3 = (1 + 18 * lam - 29 * l2 + 18 * l3 + l4) / (42 * l1_3);
        const SeriesTriangle& s = store.s[detail::SeriesXA];
        // the g3 * 4/(M(M+2)) term: T23's match of J&O's original summation, truncated at M
        const double A11 = 1 - g1 / 4 - g3 - 4 * g3 / (double(M) * (M + 2)) + subtractedSum(s, lam, Even, M, g1, g2, g3);
        const double A12 = -2 / l1 * (g1 / 4 + 2 * g2 * L - 2 * g3 + subtractedSum(s, lam, Odd, M, g1, g2, g3));
        k.f11[XA] = form(g1, g2, A11, g3);
        k.f12[XA] = form(-g1, -g2, 0.5 * l1 * A12, -g3);
        // Pressure moment X^P (trace of the force dipole), Kim-Karrila with 6 pi a1^2; derivation and checks in
        // docs/resistance.md, "Pressure moment X^P":
        //  * 1/xi: s1 = -a1 (integral of p over sphere 1), and at leading order that integral is the squeeze
        //    force: g1 of X^A.
        //  * ln(1/xi): g2P = g2 + w^3 - 2 w^2 with w = lambda/(1+lambda) = a_r/a1 (a_r = a1 a2/(a1+a2)), i.e.
        //    g2P = lambda (1 - 4 lambda) / (5 (1+lambda)^2): X^A's g2 (J&O (3.16)) plus the two lubrication
        //    integrals that separate the pressure integral from the force, the pressure on the tilted surface
        //    (1 - n.d ~ rho^2/(2 a1^2): + w^3) and the viscous traction along d (-3 eta V rho^2/(a1 h^2): -2 w^2).
        //    Checked against the series a_m -> g1 + 2 g2P/m below (test PressureMomentSeriesMatchesNearField).
        //  * O(1): the J&O subtraction of the series of SeriesTriangle::pressureMoment, truncated at M, with
        //    the tail sum_{m>M} (a_m - g1 - 2 g2P/m) ~ L/m^2 estimated from the mean L of m^2 (a_m - g1 - 2 g2P/m)
        //    over M/2 <= m <= M (that mean is -4 g3P, g3P the unknown coefficient of xi ln(1/xi), not kept).
        //    Near contact: odd S1 = 1/xi + 1/4, S2 = ln(1/xi) + 2 ln 2; even S1 = 1/xi + 3/4, S2 = ln(1/xi).
        const double w = lam / l1;
        const double g2P = g2 + w * w * w - 2 * w * w;
        const SeriesTriangle& sp = store.s[detail::SeriesXP];
        double level = 0;
        int count = 0;
        for (int m = M / 2; m <= M; ++m, ++count) level += double(m) * m * (sp.normalisedTerm(m, lam) - g1 - 2 * g2P / m);
        level /= count;
        const double tailOdd = level * inverseSquareTail(M + 1), tailEven = level * inverseSquareTail(M + 2);
        const double P11 = g1 / 4 + 2 * g2P * L + subtractedSum(sp, lam, Odd, M, g1, g2P, 0) + tailOdd;
        const double P12 = -(-g1 / 4 + subtractedSum(sp, lam, Even, M, g1, g2P, 0) + tailEven);
        k.f11[XP] = form(g1, g2P, P11, 0);
        k.f12[XP] = form(-g1, -g2P, P12, 0);
    }
    // Y^A: J&O (4.15)-(4.18).
    {
        const double g2 = 4 * lam * (2 + lam + 2 * l2) / (15 * l1_3);
        const double g3 = 2 * (16 - 45 * lam + 58 * l2 - 45 * l3 + 16 * l4) / (375 * l1_3);
        const SeriesTriangle& s = store.s[detail::SeriesYA];
        const double A11 = 1 - g3 - 4 * g3 / (double(M) * (M + 2)) + subtractedSum(s, lam, Even, M, 0, g2, g3);
        const double A12 = -2 / l1 * (2 * g2 * L - 2 * g3 - 4 * g3 / (double(M - 1) * (M + 1)) + subtractedSum(s, lam, Odd, M, 0, g2, g3));
        k.f11[YA] = form(0, g2, A11, g3);
        k.f12[YA] = form(0, -g2, 0.5 * l1 * A12, -g3);
    }
    // Y^B: J&O (5.5)-(5.7), T23 (22)-(25).
    {
        const double g2 = -lam * (4 + lam) / (5 * l1_2);
        const double g3 = -(32 - 33 * lam + 83 * l2 + 43 * l3) / (250 * l1_2);
        const SeriesTriangle& s = store.s[detail::SeriesYB];
        const double B11 = 2 * g2 * L - 2 * g3 + subtractedSum(s, lam, Odd, M, 0, g2, g3);
        const double B12 = -4 / l1_2 * (-g3 + subtractedSum(s, lam, Even, M, 0, g2, g3));
        k.f11[YB] = form(0, g2, B11, g3);
        k.f12[YB] = form(0, -g2, 0.25 * l1_2 * B12, -g3);
    }
    // X^C: J&O (6.9)-(6.10) in closed form, T23 (26)-(27).
    {
        const double zetaSum11 = l3 / l1_3 * hurwitzZeta3(lam / l1);
        const double zeta3 = 1.2020569031595942854;
        k.f11[XC] = form(0, 0, zetaSum11, -l2 / (4 * l1));
        k.f12[XC] = form(0, 0, -l3 / l1_3 * zeta3, l2 / (4 * l1));
    }
    // Y^C: J&O (7.9)-(7.12), T23 (29)-(34).
    {
        const double g2 = 2 * lam / (5 * l1), g3 = (8 + 6 * lam + 33 * l2) / (125 * l1);
        const double g4 = l2 / (10 * l1), g5 = lam * (43 - 24 * lam + 43 * l2) / (500 * l1);
        const SeriesTriangle& s = store.s[detail::SeriesYC];
        const double C11 = 1 - g3 + subtractedSum(s, lam, Even, M, 0, g2, g3);
        const double C12 = 8 / l1_3 * (2 * g4 * L - 2 * g5 + subtractedSum(s, lam, Odd, M, 0, g4, g5));
        k.f11[YC] = form(0, g2, C11, g3);
        k.f12[YC] = form(0, g4, l1_3 / 8 * C12, g5);
    }
    // X^G: J92 (19)-(21).
    {
        const double g1 = 3 * l2 / l1_3, g2 = 3 * (lam + 12 * l2 - 4 * l3) / (10 * l1_3);
        const double g3 = (5 + 181 * lam - 453 * l2 + 566 * l3 - 65 * l4) / (140 * l1_3);
        const SeriesTriangle& s = store.s[detail::SeriesXG];
        const double G11 = g1 / 4 + 2 * g2 * L - 2 * g3 + subtractedSum(s, lam, Odd, M, g1, g2, g3);
        const double G12 = 4 / l1_2 * (g1 / 4 + g3 - subtractedSum(s, lam, Even, M, g1, g2, g3));
        k.f11[XG] = form(g1, g2, G11, g3);
        k.f12[XG] = form(-g1, -g2, 0.25 * l1_2 * G12, -g3);
    }
    // Y^G: J92 (27)-(29).
    {
        const double g2 = (4 * lam - l2 + 7 * l3) / (10 * l1_3);
        const double g3 = (32 - 179 * lam + 532 * l2 - 356 * l3 + 221 * l4) / (500 * l1_3);
        const SeriesTriangle& s = store.s[detail::SeriesYG];
        const double G11 = 2 * g2 * L - 2 * g3 + subtractedSum(s, lam, Odd, M, 0, g2, g3);
        const double G12 = 4 / l1_2 * (g3 - subtractedSum(s, lam, Even, M, 0, g2, g3));
        k.f11[YG] = form(0, g2, G11, g3);
        k.f12[YG] = form(0, -g2, 0.25 * l1_2 * G12, -g3);
    }
    // Y^H: J92 (35)-(37).
    {
        const double g2 = (2 * lam - l2) / (10 * l1_2), g3 = (16 - 61 * lam + 180 * l2 + 2 * l3) / (500 * l1_2);
        const double g5 = (l2 + 7 * l3) / (20 * l1_2);
        const double g6 = (43 * lam + 147 * l2 - 185 * l3 + 221 * l4) / (1000 * l1_2);
        const SeriesTriangle& s = store.s[detail::SeriesYH];
        const double H11 = -g3 + subtractedSum(s, lam, Even, M, 0, g2, g3);
        const double H12 = 8 / l1_3 * (2 * g5 * L - 2 * g6 + subtractedSum(s, lam, Odd, M, 0, g5, g6));
        k.f11[YH] = form(0, g2, H11, g3);
        k.f12[YH] = form(0, g5, l1_3 / 8 * H12, g6);
    }
    if (!withM) return k;
    const double l5 = l4 * lam;
    // X^M: J92 (48)-(50).
    {
        const double g1 = 1.2 * l2 / l1_3, g2 = 3 * (lam + 17 * l2 - 9 * l3) / (25 * l1_3);
        const double g3 = (5 + 272 * lam - 831 * l2 + 1322 * l3 - 415 * l4) / (350 * l1_3);
        const double g4 = 1.2 * l3 / l1_3, g5 = 3 * (-4 * l2 + 17 * l3 - 4 * l4) / (25 * l1_3);
        const double g6 = (-65 * lam + 832 * l2 - 1041 * l3 + 832 * l4 - 65 * l5) / (350 * l1_3);
        const SeriesTriangle& s = store.s[detail::SeriesXM];
        const double M11 = 1 - g1 / 4 - g3 + subtractedSum(s, lam, Even, M, g1, g2, g3);
        const double M12 = 8 / l1_3 * (g4 / 4 + 2 * g5 * L - 2 * g6 + subtractedSum(s, lam, Odd, M, g4, g5, g6));
        k.f11[XM] = form(g1, g2, M11, g3);
        k.f12[XM] = form(g4, g5, l1_3 / 8 * M12, g6);
    }
    // Y^M: J92 (64)-(66), sums to order 130.
    {
        const double g2 = 6 * (lam - l2 + 4 * l3) / (25 * l1_3);
        const double g3 = (24 - 201 * lam + 882 * l2 - 1182 * l3 + 591 * l4) / (625 * l1_3);
        const double g5 = 3 * (7 * l2 - 10 * l3 + 7 * l4) / (50 * l1_3);
        const double g6 = 3 * lam * (221 - 728 * lam + 1902 * l2 - 728 * l3 + 221 * l4) / (2500 * l1_3);
        const SeriesTriangle& s = store.s[detail::SeriesYM];
        const double M11 = 1 - g3 + subtractedSum(s, lam, Even, 130, 0, g2, g3);
        const double M12 = 8 / l1_3 * (2 * g5 * L - 2 * g6 + subtractedSum(s, lam, Odd, 130, 0, g5, g6));
        k.f11[YM] = form(0, g2, M11, g3);
        k.f12[YM] = form(0, g5, l1_3 / 8 * M12, g6);
    }
    // Z^M: J92 (79)-(81), sums to order 150 (even) and 200 (odd).
    {
        const double g3 = -0.3 * (l2 + l4) / l1_3;
        const SeriesTriangle& s = store.s[detail::SeriesZM];
        const double M11 = 1 - g3 + subtractedSum(s, lam, Even, 150, 0, 0, g3);
        const double M12 = 8 / l1_3 * (2 * g3 - subtractedSum(s, lam, Odd, 200, 0, 0, g3));
        k.f11[ZM] = form(0, 0, M11, g3);
        k.f12[ZM] = form(0, 0, l1_3 / 8 * M12, -g3);
    }
    // Pressure moment X^Q (trace of the force dipole from the ambient strain), Kim-Karrila with 6 pi a1^3:
    // s1 = eta (X11Q + X12Q) d.E.d; X11Q: strain at sphere 1 (J92's X^M problem), X12Q: strain at sphere 2.
    // Derivation and checks in docs/resistance.md, "Pressure moment X^Q":
    //  * 1/xi: near the gap the surface of the strained sphere alpha recedes with speed a_alpha d.E.d: the
    //    squeeze of X^P, g1 (11) and lambda g1 (12).
    //  * ln(1/xi), as for X^P: s1 = -a1 (integral of p over sphere 1) = a1 F1.d + the two lubrication tails
    //    (tilted surface, viscous traction), where F1.d is the X^G force (X11G, and X21G by Eq. A.3):
    //    h1 = (2/3) g2 of X11G + w^3 - 2 w^2 = lambda (1 + 2 lambda - 9 lambda^2) / (5 (1+lambda)^3),
    //    h2 = (2/3) lambda^2 g2 of X11G(1/lambda) + lambda (w^3 - 2 w^2) = -2 lambda^2 (2 lambda^2 - lambda + 2) / (5 (1+lambda)^3);
    //    h1 + h2 = (1 + lambda) g2P, as Appendix C.1 requires of the singular terms.  Checked against the
    //    series (b_m -> g + 2 h/m, test PressureMomentQ.SeriesMatchesNearField).
    //  * O(1): the subtracted series X11Q = sum_even b_m t^m, X12Q = sum_odd b_m t^m (SeriesTriangle::pressureMoment
    //    of the strain table) truncated at 200 with the L/m^2 tail; no xi ln(1/xi) term kept.
    //    Near contact: even S1 = 1/xi + 3/4 (no m = 0 term here: -1), odd S1 = 1/xi + 1/4, S2 = ln(1/xi) + 2 ln 2.
    {
        const double g1 = 2 * l2 / l1_3;
        const double h1 = lam * (1 + 2 * lam - 9 * l2) / (5 * l1_3);
        const double h2 = -2 * l2 * (2 * l2 - lam + 2) / (5 * l1_3);
        const SeriesTriangle& s = store.s[detail::SeriesXQ];
        const int MQ = detail::strainPressureMomentOrder;
        const double Q11 = -g1 / 4 + subtractedSumWithTail(s, lam, Even, MQ, g1, h1);
        const double Q12 = lam * g1 / 4 + 2 * h2 * L + subtractedSumWithTail(s, lam, Odd, MQ, lam * g1, h2);
        k.f11[XQ] = form(g1, h1, Q11, 0);
        k.f12[XQ] = form(lam * g1, h2, Q12, 0);
    }
    return k;
}

}  // namespace resistance
}  // namespace fdm
