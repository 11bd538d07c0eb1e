// Near-contact asymptotic forms of the two-sphere resistance scalars for any size ratio.
//
// Sources: Jeffrey & Onishi, J. Fluid Mech. 139 (1984) 261 (A, B, C; "J&O"), Jeffrey, Phys. Fluids A 4
// (1992) 16 (G, H, M; "J92"), with the corrections of Townsend, Phys. Fluids 35 (2023) 127126 ("T23").
// Every scalar has the form   f(xi) = c_inv / xi + c_log ln(1/xi) + c_0 + c_xlog xi ln(1/xi),
// xi = 2r/(a1+a2) - 2 (symmetric reduced gap, paper Eq. A.1 text).  The singular coefficients are
// closed forms in lambda = a2/a1; the O(1) constants c_0 need sums over the far-field series
// coefficients f_k(lambda), which come from the J&O / J92 recurrences (far_field_series.hpp) and are
// summed for each lambda (truncated as in T23's generator) as in J&O (3.20)-(3.23) and their analogues
// (near_field_constants.cpp cites each family's equations).  Normalisation: pair_functions.hpp.
#ifndef FDM_RESISTANCE_NEAR_FIELD_CONSTANTS_HPP
#define FDM_RESISTANCE_NEAR_FIELD_CONSTANTS_HPP

#include "fdm/resistance/pair_functions.hpp"

namespace fdm {
namespace resistance {

// c_inv/xi + c_log ln(1/xi) + c_0 + c_xlog xi ln(1/xi)
struct NearFieldForm {
    double inv = 0, log = 0, c0 = 0, xlog = 0;
    double operator()(double xi, double logInvXi) const { return inv / xi + (log + xlog * xi) * logInvXi + c0; }
    double operator()(double xi) const;
    NearFieldForm scaled(double s) const;
};

// The 11 and 12 near-field forms of every family at one lambda (normalisation: pair_functions.hpp).
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

}  // namespace resistance
}  // namespace fdm

#endif
