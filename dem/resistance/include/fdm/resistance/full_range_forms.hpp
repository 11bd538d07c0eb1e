// Full-range forms of the two-sphere resistance scalars, valid at every gap (docs/resistance.md,
// "Full-range forms"): J&O's matched forms (Jeffrey & Onishi, J. Fluid Mech. 139 (1984) 261) of X^A, Y^A, Y^B,
// Y^C, and the same construction for the stresslet functions X^G, Y^G, Y^H (Jeffrey, Phys. Fluids A 4 (1992)
// 16), with the singular coefficients and constants corrected by Townsend, Phys. Fluids 35 (2023) 127126
// ("T23"), and the exact X^C series of Jeffery (1915).  Normalisation: Kim-Karrila with a1 (pair_functions.hpp).
#ifndef FDM_RESISTANCE_FULL_RANGE_FORMS_HPP
#define FDM_RESISTANCE_FULL_RANGE_FORMS_HPP

#include "fdm/resistance/near_field_constants.hpp"

#include <vector>

namespace fdm {
namespace resistance {

// J&O's matched forms, J&O (3.17)-(3.18) for X^A and their analogues for Y^A (4.x), Y^B (5.x), Y^C (7.x),
// with the singular coefficients and constants as corrected by T23: with t = 2/s' = 2/(2 + xi),
//
//   f(xi) = sign [ g1 S1(t) + g2 S2(t) + g3 S3(t) + sum_m (a_m - g1 - 2 g2/m + 4 g3/(m(m+2))) t^m ],
//
// the sum running over the even (m = 0, 2, ...) or odd (m = 1, 3, ...) powers of the far-field series
// a_m = f_m(lambda)/(2(1+lambda))^m (J&O (3.13)-(3.14): X11A = sum_even a_m t^m, X12A = -sum_odd a_m t^m in
// Kim-Karrila units; the g2, g3 subtractions start at m = 2 for the even sums).  S1, S2, S3 are the closed
// forms whose Taylor coefficients in t are exactly the subtracted ones:
//   even: S1 = 1/(1-t^2),   S2 = -ln(1-t^2),          S3 = -1 - (1-t^2) ln(1-t^2)/t^2
//   odd:  S1 = t/(1-t^2),   S2 = ln((1+t)/(1-t)),     S3 = -2/t + (1-t^2) ln((1+t)/(1-t))/t^2
// Near contact S1 = 1/xi + 3/4 (odd: + 1/4), S2 = ln(1/xi) (odd: + 2 ln 2), S3 = -1 (odd: -2) + xi ln(1/xi),
// all + O(xi): at xi -> 0 the form reduces to the NearFieldForm (whose c0 is the same sum at t = 1), and
// at large xi to the far-field series.  The identity is exact for the untruncated sums; the remainder
// coefficients decay like m^-3 (with an oscillating amplitude, genuine: the same in quadruple precision),
// so truncating at `order` costs ~ order^-2 near contact and less with the factor t^m further out
// (convergence measured in docs/resistance.md).  The g3 subtraction 4/(m(m+2)) is the one of T23's
// constants (J&O's original uses m(m-2) with a special m = 2 term); S3 is its closed form.
struct MatchedForm {
    bool odd = false;                 // parity of the powers of t
    double sign = 1;
    double g1 = 0, g2 = 0, g3 = 0;    // coefficients of S1, S2, S3 (the NearFieldForm's inv, log, xlog times sign)
    std::vector<double> remainder;    // a_m - (S1, S2, S3 coefficients), for m = parity, parity + 2, ... <= order
    double operator()(double xi) const;  // xi > 0, not floored
};

// X^C (rotation about the line of centres) has an exact solution (Jeffery, Proc. London Math. Soc. 14
// (1915) 327; the image system of rotlets behind the closed forms J&O (6.9)-(6.10)): with the bispherical coordinates of the spheres mu1 = asinh(c/a1),
// mu2 = asinh(c/a2), c the focal distance, delta = mu1 + mu2,
//   X11C = sinh^3(mu1) sum_{n>=0} csch^3(mu1 + n delta),   X12C = -sinh^3(mu1) sum_{n>=1} csch^3(n delta)
// (Kim-Karrila, a1).  Near contact mu1/delta -> lambda/(1+lambda) and these reduce to the zeta constants of
// the NearFieldForm.  Used in place of a matched form (it needs no truncation).
void exactRotationAboutLineOfCentres(double lambda, double xi, double& x11, double& x12);

// The full-range forms of X^A, Y^A, Y^B, Y^C, X^G, Y^G, Y^H at one lambda (11 and 12, Kim-Karrila with a1).
// hasFullRangeForm(f): XA, YA, YB, XC, YC, XG, YG, YH; X^C is evaluated by exactRotationAboutLineOfCentres.
const int fullRangeDefaultOrder = 100;
bool hasFullRangeForm(PairFunction f);
struct FullRangeConstants {
    double lambda = 1;
    int order = 0;
    MatchedForm f11[NumPairFunctions];   // filled for XA, YA, YB, YC, XG, YG, YH
    MatchedForm f12[NumPairFunctions];
};
// order: highest power of t kept.  Up to 100 the series of the near-field constants serve (no extra
// cost); above, the X^A, Y^A/Y^B and Y^C recurrences are run to that order once per process (~0.9 s at
// 150, ~3.3 s at 200).  Throws for lambda <= 0 or order < 10.
FullRangeConstants computeFullRangeConstants(double lambda, int order = fullRangeDefaultOrder);
// The 11 (twelve = false) or 12 scalar of a family with a full-range form at xi (floored at minimumGap
// by the callers in two_sphere.hpp; here any xi > 0).
double fullRangeScalar(const FullRangeConstants& k, PairFunction f, bool twelve, double xi);

}  // namespace resistance
}  // namespace fdm

#endif
