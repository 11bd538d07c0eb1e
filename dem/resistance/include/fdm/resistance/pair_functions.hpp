// The two-sphere scalar families of paper Eq. (A.1) and the normalisation of their scalars.
//
// Normalisation ("Kim & Karrila with a1", as Townsend's tables): the 11 and 12 scalars are divided by
// 6 pi a1 (A), 4 pi a1^2 (B, G), 8 pi a1^3 (C, H), 20/3 pi a1^3 (M), 6 pi a1^2 (P) and 6 pi a1^3 (Q) (P, Q:
// this library's choice); all times the viscosity.  The 21 and 22 scalars are the 12 and 11 scalars at
// 1/lambda, normalised with a2 (paper Eq. A.4, with its signs for B, G, P; Q keeps its sign).
#ifndef FDM_RESISTANCE_PAIR_FUNCTIONS_HPP
#define FDM_RESISTANCE_PAIR_FUNCTIONS_HPP

namespace fdm {
namespace resistance {

// Scalar families of paper Eq. (A.1).  XP and XQ are the pressure moments (trace of the force dipole s)
// from the translations and from the ambient strain: s_alpha = -eta sum_beta X^P_ab d.U_b + eta sum_beta
// X^Q_ab d.E.d (paper Eq. 19, Q_ab = X^Q_ab (dd - I/3)); 1/xi and ln(1/xi) terms by lubrication theory,
// O(1) constants from the twin-multipole pressure series; no xi ln(1/xi) term (docs/resistance.md).
// XQ is built with the M functions (withM) and is a theoretical function only: the sub-grid model drops
// the strain columns (paper Eq. 21), so it has no sub-grid value and no place in the blocks.
enum PairFunction { XA, YA, YB, XC, YC, XG, YG, YH, XM, YM, ZM, XP, XQ, NumPairFunctions };

inline const char* pairFunctionName(PairFunction f)
{
    static const char* const names[NumPairFunctions] = {"XA", "YA", "YB", "XC", "YC", "XG",
                                                        "YG", "YH", "XM", "YM", "ZM", "XP", "XQ"};
    return names[f];
}

}  // namespace resistance
}  // namespace fdm

#endif
