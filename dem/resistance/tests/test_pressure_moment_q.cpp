// Pressure moment X^Q (trace of the force dipole from the ambient strain) of two spheres:
//   s_alpha = eta sum_beta X^Q_alpha,beta d.E.d   (paper Eq. 19 with Q_ab = X^Q_ab (dd - I/3); Kim-Karrila, 6 pi a1^3)
//   X11Q = g1/xi + h1 ln(1/xi) + c0_11,   X12Q = lambda g1/xi + h2 ln(1/xi) + c0_12,
//   h1 = lambda (1 + 2 lambda - 9 lambda^2) / (5 (1+lambda)^3),  h2 = -2 lambda^2 (2 lambda^2 - lambda + 2) / (5 (1+lambda)^3)
// (derivation in docs/resistance.md, "Pressure moment X^Q").  No published X^Q numbers were available here
// (Jeffrey, Morris & Brady 1993 is not among the project's reference data).  The checks: (a) the singular
// terms from the published X^G coefficients (Townsend's generator) and the lubrication tails of X^P; (b) the independent
// twin-multipole series of the pressure (J92's strain problem) reproduces them; (c) the far field against
// the single-sphere strain and Stokes solutions; (d) Appendix C.1: the theory's third term of Eq. (20),
// (X11Q + X12Q) - (r/2a1)(X11P - X12P), has no singular term, seen in the series alone; (e) Eq. (A.4);
// (f) truncation of the O(1) constants and regression values.
#include "fdm/resistance/far_field_series.hpp"
#include "fdm/resistance/near_field_constants.hpp"
#include "fdm/resistance/two_sphere.hpp"
#include "reference_data.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

using namespace fdm::resistance;

namespace {

double cube(double x) { return x * x * x; }
double g1Of(double lambda) { return 2 * lambda * lambda / cube(1 + lambda); }
double h1Of(double lambda) { return lambda * (1 + 2 * lambda - 9 * lambda * lambda) / (5 * cube(1 + lambda)); }
double h2Of(double lambda) { return -2 * lambda * lambda * (2 * lambda * lambda - lambda + 2) / (5 * cube(1 + lambda)); }
double g2POf(double lambda) { return lambda * (1 - 4 * lambda) / (5 * (1 + lambda) * (1 + lambda)); }

// b_m of the X^Q series: X11Q = sum_even b_m t^m, X12Q = sum_odd b_m t^m (t = 2/s'), and a_m of X^P
// (X11P = sum_odd a_m t^m, X12P = -sum_even a_m t^m).
double qTerm(int m, double lambda) { return farFieldCoefficient(XQ, m, lambda) / std::pow(2 * (1 + lambda), m); }
double pTerm(int m, double lambda) { return farFieldCoefficient(XP, m, lambda) / std::pow(2 * (1 + lambda), m); }

// sum_{j >= 0} (first + 2 j)^-2 (trigamma asymptotics; first >= 50)
double inverseSquareTail(int first)
{
    const double x = 0.5 * first, x2 = x * x;
    return 0.25 * (1 / x + 1 / (2 * x2) + 1 / (6 * x2 * x) - 1 / (30 * x2 * x2 * x));
}

const NearFieldConstants& constantsWithM(double lambda)
{
    static std::vector<std::pair<double, NearFieldConstants> > cache;
    for (std::size_t i = 0; i < cache.size(); ++i)
        if (cache[i].first == lambda) return cache[i].second;
    cache.push_back(std::make_pair(lambda, computeNearFieldConstants(lambda, true)));
    return cache.back().second;
}

const double lambdas[] = {0.1, 0.5, 1 / 1.4, 1, 1.4, 2, 10};

}  // namespace

// (a) The singular coefficients.  1/xi: the surface of the strained sphere recedes at a_alpha d.E.d near the
// gap, the squeeze of X^P.  ln(1/xi): s1 = a1 F1.d + the two lubrication tails of X^P, with F1.d the X^G force,
// i.e. h1 = (2/3) G2xg(lambda) + w^3 - 2 w^2 and h2 = (2/3) lambda^2 G2xg(1/lambda) + lambda (w^3 - 2 w^2),
// w = lambda/(1+lambda): against the published G2xg (lambda = 1, 1.4, 1/1.4; 12-digit csv, bound 1e-10).
// And Appendix C.1 for the theory: the sums are (1+lambda) times the X^P coefficients (round-off).
TEST(PressureMomentQ, SingularCoefficientsFromPublishedXG)
{
    const reference::Csv singular = reference::readCsv("two_sphere_general_lambda/nearfield_singular_coeffs_g.csv", true);
    ASSERT_EQ(singular.rows.size(), 3u);
    for (std::size_t r = 0; r < singular.rows.size(); ++r) {
        const double lambda = singular.rows[r][singular.column("lambda")];
        double g2xgInverse = std::nan("");
        for (std::size_t j = 0; j < singular.rows.size(); ++j)
            if (std::fabs(singular.rows[j][singular.column("lambda")] * lambda - 1) < 1e-9) g2xgInverse = singular.rows[j][singular.column("G2xg")];
        ASSERT_FALSE(std::isnan(g2xgInverse)) << lambda;
        const double w = lambda / (1 + lambda), tails = w * w * w - 2 * w * w;
        const NearFieldConstants& k = constantsWithM(lambda);
        EXPECT_NEAR(k.f11[XQ].inv, (2.0 / 3.0) * singular.rows[r][singular.column("G1xg")], 1e-10) << lambda;
        EXPECT_NEAR(k.f11[XQ].log, (2.0 / 3.0) * singular.rows[r][singular.column("G2xg")] + tails, 1e-10) << lambda;
        EXPECT_NEAR(k.f12[XQ].log, (2.0 / 3.0) * lambda * lambda * g2xgInverse + lambda * tails, 1e-10) << lambda;
    }
    for (double lambda : lambdas) {
        const NearFieldConstants& k = constantsWithM(lambda);
        EXPECT_NEAR(k.f11[XQ].inv, g1Of(lambda), 1e-14);
        EXPECT_NEAR(k.f12[XQ].inv, lambda * g1Of(lambda), 1e-14);
        EXPECT_NEAR(k.f11[XQ].log, h1Of(lambda), 1e-14) << lambda;
        EXPECT_NEAR(k.f12[XQ].log, h2Of(lambda), 1e-14) << lambda;
        EXPECT_NEAR(k.f11[XQ].inv + k.f12[XQ].inv, (1 + lambda) * k.f11[XP].inv, 1e-14);
        EXPECT_NEAR(k.f11[XQ].log + k.f12[XQ].log, (1 + lambda) * k.f11[XP].log, 1e-14) << lambda;
        EXPECT_EQ(k.f11[XQ].xlog, 0.0);
        EXPECT_EQ(k.f12[XQ].xlog, 0.0);
    }
    // equal spheres: h1 = h2 = g2P = -3/20
    EXPECT_NEAR(h1Of(1), -0.15, 1e-15);
    EXPECT_NEAR(h2Of(1), -0.15, 1e-15);
    // without the M functions X^Q is not built
    EXPECT_EQ(computeNearFieldConstants(1.0, false).f11[XQ].inv, 0.0);
}

// (b) Independent check of the lubrication result: the twin-multipole series of the strain problem has
// b_m -> g + 2 h/m - 4 g3/m^2 + (oscillating, ~m^-3), g = g1 (even m, X11Q) and lambda g1 (odd m, X12Q).  A wrong h
// by d makes m^2 (b_m - g - 2 h/m) grow like 2 d m: the fitted slope over 50 <= m <= 200 (one parity) bounds d.
// Bound 2e-3 for lambda <= 2 (measured 1.3e-3) and 1e-2 for lambda = 10 (measured 4.8e-3, 0.4 % of |h1| = 1.32;
// the slow oscillation of m^2 (b_m - ...) leaves that much in the fit); the naive guess h1 = g2P would be off by
// lambda^2 (1-lambda)/(1+lambda)^3, 0.057 at lambda = 1.4.
TEST(PressureMomentQ, SeriesMatchesNearField)
{
    double worst = 0;
    for (double lambda : lambdas) {
        const double g[2] = {g1Of(lambda), lambda * g1Of(lambda)}, h[2] = {h1Of(lambda), h2Of(lambda)};
        for (int parity = 0; parity < 2; ++parity) {
            EXPECT_NEAR(qTerm(200 - parity, lambda), g[parity], 0.2 * g[parity] + 0.05) << lambda;
            double sx = 0, sy = 0, sxx = 0, sxy = 0;
            int n = 0;
            for (int m = 50 + parity; m <= 200; m += 2, ++n) {
                const double y = double(m) * m * (qTerm(m, lambda) - g[parity] - 2 * h[parity] / m);
                sx += m; sy += y; sxx += double(m) * m; sxy += m * y;
            }
            const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
            worst = std::max(worst, std::fabs(slope / 2));
            EXPECT_LT(std::fabs(slope / 2), lambda <= 2 ? 2e-3 : 1e-2) << "lambda " << lambda << (parity ? " X12Q" : " X11Q");
        }
    }
    std::printf("[worst] X^Q series: |h(series) - h(lubrication)| <= %.1e\n", worst);
}

// (c) Far field from single-sphere solutions (no multipole table involved).  X12Q: sphere 2 in the strain has
// the disturbance pressure p = -5 eta a2^3 (x.E.x)/|x|^5, at x1: -5 eta a2^3 d.E.d / r^3, and
// s1 = -4 pi a1^3 p(x1) gives X12Q = (10/3) a2^3/r^3 = (10/3) lambda^3 t^3/(1+lambda)^3.  X11Q: sphere 1's
// disturbance velocity -(5/2) a1^3 x (x.E.x)/|x|^5 reaches x2 as -(5/2) a1^3 d.E.d d/r^2; sphere 2 (moving with
// the ambient flow) then exerts the Stokes force 6 pi eta a2 (5/2) a1^3 d.E.d/r^2 d on the fluid, whose pressure
// at x1 is -(15/4) eta a1^3 a2 d.E.d/r^4: X11Q = (5/2) a1^3 a2/r^4 = (5/2) lambda t^4/(1+lambda)^4.  No t^0 ... t^2.
// Round-off.
TEST(PressureMomentQ, FarFieldFromSingleSphereSolutions)
{
    for (double lambda : lambdas) {
        const double l1 = 1 + lambda;
        for (int m = 0; m <= 2; ++m) EXPECT_NEAR(qTerm(m, lambda), 0, 1e-15) << m;
        EXPECT_NEAR(qTerm(3, lambda), 10.0 / 3.0 * cube(lambda / l1), 1e-13) << lambda;
        EXPECT_NEAR(qTerm(4, lambda), 2.5 * lambda / (l1 * l1 * l1 * l1), 1e-13) << lambda;
    }
    // and the library's values far apart follow the same leading terms (the near-field form is not meant
    // for large gaps: this only checks that both are in the same units) -- here through the series directly
    const double lambda = 1.4, l1 = 1 + lambda, sDash = 40, t = 2 / sDash;
    double x11 = 0, x12 = 0;
    for (int m = 0; m <= 30; ++m) (m % 2 ? x12 : x11) += qTerm(m, lambda) * std::pow(t, m);
    EXPECT_NEAR(x12 / (10.0 / 3.0 * cube(lambda * t / l1)), 1, 5 * t * t);
    EXPECT_NEAR(x11 / (2.5 * lambda * std::pow(t / l1, 4)), 1, 5 * t * t);
}

// (d) Appendix C.1 in the theory.  T = (X11Q + X12Q) - (r/2a1)(X11P - X12P), r/2a1 = (1+lambda)/(2t), is the trace
// of the force dipole of sphere 1 for the pair at rest in a pure strain (third term of Eq. 20), in units of
// 6 pi eta a1^3 d.E.d.  Its series T = sum_m c_m t^m, c_m = b_m - (1+lambda)/2 a_(m+1), built from the two
// multipole series only: c_m alternates with amplitude (1-lambda) g1/2 (regular at t = 1), and its smooth part
// beta_m = (c_(m-1) + 2 c_m + c_(m+1))/4 must vanish faster than 1/m (no 1/xi: beta -> 0; no log: m beta -> 0).
// Measured: mean of m beta_m over 50 <= m <= 98 below 5e-3 (a log term of the size of (1+lambda) g2P would give
// 0.05 ... 1.3).  Then the contact value of T from the series (Abel sum, L/m tail) equals the one of the
// near-field constants, c11Q + c12Q - (1+lambda)/2 (c11P - c12P) - (1+lambda) g1/2, to 3e-3 (lambda <= 2) and 1e-2
// (lambda = 10); and the near-field forms give a T that stays bounded down to xi = 1e-5.
TEST(PressureMomentQ, AppendixC1CombinationIsRegular)
{
    double worstLog = 0, worstContact = 0;
    for (double lambda : lambdas) {
        const double l1 = 1 + lambda;
        const int N = 98;  // the X^P series is kept to order 100
        std::vector<double> c(N + 2);
        for (int m = 0; m <= N + 1; ++m) c[m] = qTerm(m, lambda) - 0.5 * l1 * pTerm(m + 1, lambda);
        double meanMBeta = 0, level = 0, sum = 0;
        int n = 0;
        for (int m = 0; m <= N; ++m) {
            sum += c[m];
            if (m >= 50) {
                const double beta = (c[m - 1] + 2 * c[m] + c[m + 1]) / 4;
                meanMBeta += m * beta;
                level += double(m) * m * beta;
                ++n;
            }
        }
        meanMBeta /= n;
        level /= n;
        worstLog = std::max(worstLog, std::fabs(meanMBeta));
        EXPECT_LT(std::fabs(meanMBeta), 5e-3) << "lambda " << lambda;
        const double seriesContact = sum + 0.5 * c[N + 1] + level / (N + 1);
        const NearFieldConstants& k = constantsWithM(lambda);
        const double g1 = g1Of(lambda);
        const double formContact = k.f11[XQ].c0 + k.f12[XQ].c0 - 0.5 * l1 * (k.f11[XP].c0 - k.f12[XP].c0) - 0.5 * l1 * g1;
        const double bound = lambda <= 2 ? 3e-3 : 1e-2;
        worstContact = std::max(worstContact, std::fabs(seriesContact - formContact) / bound);
        EXPECT_NEAR(seriesContact, formContact, bound) << "lambda " << lambda;
        std::printf("[C.1] lambda %.4g: mean m beta_m %.1e, T(contact) series %.5f, near-field constants %.5f\n", lambda,
                    meanMBeta, seriesContact, formContact);
        // the dimensional forms of a pair (a1 = 1, a2 = lambda): T stays within O(xi ln(1/xi)) of its contact value
        // down to xi = 1e-5 (a left-over 1/xi or ln(1/xi) term would exceed the bound by orders of magnitude)
        const PairForms p = makePairForms(1, lambda, true);
        for (double xi = 1e-2; xi >= 0.99e-5; xi /= 10) {
            const PairFunctionValues v = evaluate(p, xi);
            const double r = 0.5 * l1 * (2 + xi);
            const double T = v.f[XQ][0][0] + v.f[XQ][0][1] - 0.5 * r * (v.f[XP][0][0] - v.f[XP][0][1]);
            EXPECT_NEAR(T / (6 * M_PI), formContact, l1 * xi * (std::fabs(g2POf(lambda)) * std::log(1 / xi) + 1))
                << "lambda " << lambda << " xi " << xi;
        }
    }
    std::printf("[worst] C.1: |mean m beta_m| <= %.1e; contact values differ by <= %.2f of their bound\n", worstLog, worstContact);
}

// (e) Paper Eq. (A.4) with the plus sign of an even tensor: X^Q_ab(lambda) = X^Q_(3-a)(3-b)(1/lambda), on the
// dimensional forms of swapped radii (every coefficient); 21 and 22 scale with a2^3.
TEST(PressureMomentQ, SizeRatioInversion)
{
    const double radii[][2] = {{1, 1.4}, {1, 10}, {2.5, 0.25}, {1, 1}};
    for (const auto& rr : radii) {
        const double a1 = rr[0], a2 = rr[1];
        const PairForms p = makePairForms(a1, a2, true), q = makePairForms(a2, a1, true);
        for (int a = 0; a < 2; ++a)
            for (int b = 0; b < 2; ++b) {
                const NearFieldForm &f = p.f[XQ][a][b], &g = q.f[XQ][1 - a][1 - b];
                const double s = 1e-12 * (std::fabs(f.inv) + std::fabs(f.c0) + 1);
                EXPECT_NEAR(f.inv, g.inv, s);
                EXPECT_NEAR(f.log, g.log, s);
                EXPECT_NEAR(f.c0, g.c0, s);
            }
        // X22Q (dimensional) = 6 pi a2^3 X11Q(1/lambda): its 1/xi term is 6 pi a2^3 g1(1/lambda)
        EXPECT_NEAR(p.f[XQ][1][1].inv, 6 * M_PI * cube(a2) * g1Of(a1 / a2), 1e-12 * p.f[XQ][1][1].inv);
        EXPECT_NEAR(p.f[XQ][1][0].inv, 6 * M_PI * cube(a2) * (a1 / a2) * g1Of(a1 / a2), 1e-12 * p.f[XQ][1][0].inv);
        // the pair functions keep X^Q to themselves: built without M they are zero
        const PairFunctionValues v = evaluate(makePairForms(a1, a2, false), 0.01);
        for (int a = 0; a < 2; ++a)
            for (int b = 0; b < 2; ++b) EXPECT_EQ(v.f[XQ][a][b], 0.0);
    }
}

// (f) The O(1) constants (series truncated at 200, L/m^2 tail, near_field_constants.cpp), recomputed here from the
// public series at truncation 100 with the same procedure.  Measured 100 vs 200: 1.6e-3 (lambda <= 2), 6.7e-3
// (lambda = 10); 200 vs 300 (offline): 3e-4 and 1.9e-3.  Bounds 2.5e-3 and 1e-2.  Regression values at lambda = 1
// and 1.4 (docs/resistance.md table): bound 5e-4, the truncation uncertainty of the tabulated values.
TEST(PressureMomentQ, ConstantsStableUnderTruncation)
{
    const double L = std::log(2.0);
    double worst = 0;
    for (double lambda : lambdas) {
        const double g[2] = {g1Of(lambda), lambda * g1Of(lambda)}, h[2] = {h1Of(lambda), h2Of(lambda)};
        const int M = 100;
        double c[2];
        for (int parity = 0; parity < 2; ++parity) {
            double level = 0, sum = 0;
            int n = 0;
            const int last = parity ? M - 1 : M;
            for (int m = parity ? 1 : 2; m <= last; m += 2) {
                const double r = qTerm(m, lambda) - g[parity] - 2 * h[parity] / m;
                sum += r;
                if (2 * m >= M) { level += double(m) * m * r; ++n; }
            }
            c[parity] = sum + level / n * inverseSquareTail(last + 2);
        }
        const double c11 = -g[0] / 4 + c[0], c12 = g[1] / 4 + 2 * h[1] * L + c[1];
        const NearFieldConstants& k = constantsWithM(lambda);
        const double bound = lambda <= 2 ? 2.5e-3 : 1e-2;
        EXPECT_NEAR(k.f11[XQ].c0, c11, bound) << lambda;
        EXPECT_NEAR(k.f12[XQ].c0, c12, bound) << lambda;
        worst = std::max(worst, std::max(std::fabs(k.f11[XQ].c0 - c11), std::fabs(k.f12[XQ].c0 - c12)) / bound);
    }
    std::printf("[worst] X^Q constants, truncation 100 vs 200: %.2f of the bound\n", worst);
    EXPECT_NEAR(constantsWithM(1.0).f11[XQ].c0, -0.10641, 5e-4);
    EXPECT_NEAR(constantsWithM(1.0).f12[XQ].c0, 0.17712, 5e-4);
    EXPECT_NEAR(constantsWithM(1.4).f11[XQ].c0, -0.02264, 5e-4);
    EXPECT_NEAR(constantsWithM(1.4).f12[XQ].c0, 0.30653, 5e-4);
}
