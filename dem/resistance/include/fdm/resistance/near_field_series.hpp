// Near-contact asymptotic forms of the two-sphere resistance scalars for any size ratio.
//
// Sources: Jeffrey & Onishi, J. Fluid Mech. 139 (1984) 261 (A, B, C; "J&O"), Jeffrey, Phys. Fluids A 4
// (1992) 16 (G, H, M; "J92"), with the corrections of Townsend, Phys. Fluids 35 (2023) 127126 ("T23").
// Every scalar has the form   f(xi) = c_inv / xi + c_log ln(1/xi) + c_0 + c_xlog xi ln(1/xi),
// xi = 2r/(a1+a2) - 2 (symmetric reduced gap, paper Eq. A.1 text).  The singular coefficients are
// closed forms in lambda = a2/a1; the O(1) constants c_0 need sums over the far-field series
// coefficients f_k(lambda), which are built here from the J&O / J92 recurrences (computed once per
// recurrence family, lambda-independent) and summed for each lambda (truncated as in T23's generator).
//
// Normalisation ("Kim & Karrila with a1", as Townsend's tables): the 11 and 12 scalars are divided by
// 6 pi a1 (A), 4 pi a1^2 (B, G), 8 pi a1^3 (C, H), 20/3 pi a1^3 (M), 6 pi a1^2 (P) and 6 pi a1^3 (Q) (P, Q:
// this library's choice); all times the viscosity.  The 21 and 22 scalars are the 12 and 11 scalars at
// 1/lambda, normalised with a2 (paper Eq. A.4, with its signs for B, G, P; Q keeps its sign).
#ifndef FDM_RESISTANCE_NEAR_FIELD_SERIES_HPP
#define FDM_RESISTANCE_NEAR_FIELD_SERIES_HPP

#include <vector>

namespace fdm {
namespace resistance {

// Scalar families of paper Eq. (A.1).  XP and XQ are the pressure moments (trace of the force dipole s)
// from the translations and from the ambient strain: s_alpha = -eta sum_beta X^P_ab d.U_b + eta sum_beta
// X^Q_ab d.E.d (paper Eq. 19, Q_ab = X^Q_ab (dd - I/3)); 1/xi and ln(1/xi) terms by lubrication theory,
// O(1) constants from the twin-multipole pressure series; no xi ln(1/xi) term (docs/resistance.md).
// XQ is built with the M functions (withM) and is a theoretical function only: the sub-grid model drops
// the strain columns (paper Eq. 21), so it has no sub-grid value and no place in the blocks.
enum PairFunction { XA, YA, YB, XC, YC, XG, YG, YH, XM, YM, ZM, XP, XQ, NumPairFunctions };
const char* pairFunctionName(PairFunction f);

// c_inv/xi + c_log ln(1/xi) + c_0 + c_xlog xi ln(1/xi)
struct NearFieldForm {
    double inv = 0, log = 0, c0 = 0, xlog = 0;
    double operator()(double xi, double logInvXi) const { return inv / xi + (log + xlog * xi) * logInvXi + c0; }
    double operator()(double xi) const;
    NearFieldForm scaled(double s) const;
};

// The 11 and 12 near-field forms of every family at one lambda (normalisation above).
struct NearFieldConstants {
    double lambda = 1;
    bool hasMFunctions = false;          // X^M, Y^M, Z^M are built only on request (they are slow)
    NearFieldForm f11[NumPairFunctions];
    NearFieldForm f12[NumPairFunctions];
};

// Builds the constants.  withM: also X^M, Y^M, Z^M and X^Q (the Z^M recurrence to order 200 takes ~0.5 s
// the first time in a process; they are not needed for the sub-grid matrices).
NearFieldConstants computeNearFieldConstants(double lambda, bool withM = false);

// Individual pieces, exposed for the tests and the documentation.
double hurwitzZeta3(double a);  // sum_{k>=0} (k+a)^-3, a > 0

// Far-field series coefficient f_k(lambda) of J&O (3.15)/(9), J92, as tabulated in
// reference/two_sphere_general_lambda/farfield_fk.csv ("XA","YA","YB","YC","XG","YG","YH"); also XP,
// the pressure-moment series built here from the X^A table (X11P = sum_odd, X12P = -sum_even of
// f_k/(2(1+lambda))^k t^k, t = 2/s'; docs/resistance.md, "Pressure moment X^P"), and XQ, the same from
// the strain table of X^M (X11Q = sum_even, X12Q = +sum_odd; built with the M recurrences on first use).
double farFieldCoefficient(PairFunction family, int k, double lambda);

// ---------------------------------------------------------------------------------------------
// Full-range forms, valid at every gap (docs/resistance.md, "Full-range forms").
//
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

// The full-range forms of X^A, Y^A, Y^B, Y^C at one lambda (11 and 12, Kim-Karrila with a1).
// hasFullRangeForm(f): XA, YA, YB, XC, YC; X^C is evaluated by exactRotationAboutLineOfCentres.
const int fullRangeDefaultOrder = 100;
bool hasFullRangeForm(PairFunction f);
struct FullRangeConstants {
    double lambda = 1;
    int order = 0;
    MatchedForm f11[NumPairFunctions];   // filled for XA, YA, YB, YC
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
