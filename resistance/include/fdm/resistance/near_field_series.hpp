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
// 6 pi a1 (A), 4 pi a1^2 (B, G), 8 pi a1^3 (C, H), 20/3 pi a1^3 (M), 6 pi a1^2 (P, this library's
// choice); all times the viscosity.  The 21 and 22 scalars are the 12 and 11 scalars at 1/lambda,
// normalised with a2 (paper Eq. A.4, with its signs for B, G, P).
#ifndef FDM_RESISTANCE_NEAR_FIELD_SERIES_HPP
#define FDM_RESISTANCE_NEAR_FIELD_SERIES_HPP

#include <vector>

namespace fdm {
namespace resistance {

// Scalar families of paper Eq. (A.1).  XP is the pressure moment (trace of the force dipole).
enum PairFunction { XA, YA, YB, XC, YC, XG, YG, YH, XM, YM, ZM, XP, NumPairFunctions };
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

// Builds the constants.  withM: also X^M, Y^M, Z^M (the Z^M recurrence to order 200 takes ~0.5 s the
// first time in a process; it is not needed for the sub-grid matrices).
NearFieldConstants computeNearFieldConstants(double lambda, bool withM = false);

// Individual pieces, exposed for the tests and the documentation.
double hurwitzZeta3(double a);  // sum_{k>=0} (k+a)^-3, a > 0

// Far-field series coefficient f_k(lambda) of J&O (3.15)/(9), J92, as tabulated in
// reference/two_sphere_general_lambda/farfield_fk.csv ("XA","YA","YB","YC","XG","YG","YH").
double farFieldCoefficient(PairFunction family, int k, double lambda);

}  // namespace resistance
}  // namespace fdm

#endif
