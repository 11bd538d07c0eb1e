// Sphere-plane-wall theoretical resistance functions, eps = h/a - 1 (h: centre-to-wall distance).
//
// Kim-Karrila normalisation with the sphere radius a (as the "11" two-sphere scalars): A by 6 pi a,
// B and G by 4 pi a^2, C and H by 8 pi a^3, P by 6 pi a^2; all times the viscosity.  d is the unit
// normal pointing into the wall (paper Appendix A.2), so the same tensor forms as A_11, B_11, ... hold.
//
//   XA  normal translation       Brenner (1961) exact bipolar series; lubrication form of Cox & Brenner
//                                 (1967), 1/eps + (1/5) ln(1/eps) + 0.971264, below eps = 1e-3
//   YA  parallel translation     Chaoui & Feuillebois (2003): small-gap form, Table 11, for eps < 0.1;
//   YB  translation-rotation      Pade fits in a/h, Tables 9, 10, 12, for eps >= 0.1 (the two agree to
//   YC  rotation (parallel axis)  7 digits for 0.08 <= eps <= 1).  YB = -2 c_yx (sign: d into the wall).
//   XC  rotation (normal axis)   Jeffery (1915) exact series sinh^3(alpha) sum csch^3(n alpha)
//   XG  normal stresslet         leading lubrication terms 3/(2 eps) - (6/5) ln(1/eps): the lambda -> inf
//                                 limit of Jeffrey (1992) (19b); O(1) constant not included
//   XP  pressure moment          1/eps - (4/5) ln(1/eps): the lambda -> inf limit of the two-sphere X^P
//                                 (docs/resistance.md, "Pressure moment X^P"); O(1) constant not included
//   YG, YH                       from paper Eq. (D.4) applied to YA, YB, YC (exact for their singular
//                                 parts; these are what the frame-invariant sub-grid matrix uses)
#ifndef FDM_RESISTANCE_SPHERE_WALL_HPP
#define FDM_RESISTANCE_SPHERE_WALL_HPP

namespace fdm {
namespace resistance {

enum WallFunction { WallXA, WallYA, WallYB, WallXC, WallYC, WallXG, WallYG, WallYH, WallXP, NumWallFunctions };
const char* wallFunctionName(WallFunction f);

struct WallScalars {
    double f[NumWallFunctions];
};

double wallNormalTranslation(double eps);        // XA (Kim-Karrila, 6 pi a)
double wallParallelTranslation(double eps);      // YA = f_xx^t (6 pi a)
double wallCouplingMagnitude(double eps);        // c_yx^t = T/(8 pi a^2 U) >= 0
double wallParallelRotation(double eps);         // YC = c_yy^r (8 pi a^3)
double wallNormalRotation(double eps);           // XC (8 pi a^3)
double brennerNormalTranslationSeries(double eps);  // the exact series alone (slow below 1e-3)

// All functions at eps (floored at 1e-5), Kim-Karrila normalised.
WallScalars wallTheory(double eps);
// Kim-Karrila factor of a wall function for radius a.
double wallKimKarrilaFactor(WallFunction f, double a);
// Dimensional (divided by the viscosity) values for radius a.
WallScalars wallTheoryDimensional(double a, double eps);
// Paper Eq. (D.4): Y^G and Y^H from Y^A, Y^B, Y^C (dimensional values, radius a).
void applyWallClosureD4(WallScalars& dimensional, double a, double eps);

}  // namespace resistance
}  // namespace fdm

#endif
