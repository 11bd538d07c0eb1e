// Internal to the library (src/, not a public header): the far-field series of the twin-multipole
// expansions, kept as lambda-independent coefficient triangles.  Built from the recurrences in
// far_field_series.cpp, summed for each lambda by near_field_constants.cpp (the O(1) constants) and
// full_range_forms.cpp (the matched forms).
#ifndef FDM_RESISTANCE_SRC_FAR_FIELD_SERIES_STORE_HPP
#define FDM_RESISTANCE_SRC_FAR_FIELD_SERIES_STORE_HPP

#include <cmath>
#include <vector>

namespace fdm {
namespace resistance {
namespace detail {

class TripleTable;  // P, Q or V coefficients of one recurrence (far_field_series.cpp)

// A far-field series f_k(lambda) = scale 2^k sum_q c[k][q] lambda^(q + shift(k)), kept as the triangle
// c[k][q] (lambda-independent) so that per-lambda sums cost O(order^2) and no recurrence.
struct SeriesTriangle {
    int order = 0;
    bool oddPowerShift = false;  // the extra lambda^(k mod 2) of the C, H and M series
    double scale = 1;
    std::vector<std::vector<double> > c;

    SeriesTriangle() {}
    // c[k][q] = table(n, k - q, q): the series of harmonic n of a recurrence table.
    SeriesTriangle(const TripleTable& table, int n, double scale_, bool shift);

    // The pressure-moment series (docs/resistance.md, "Pressure moment X^P"): the trace of the force dipole of
    // sphere 1 is -a1 times the surface integral of the pressure, which by the mean-value property is
    // 4 pi a1^2 times the pressure of sphere 2's decaying harmonics at x1.  With J&O's axisymmetric table
    // (pressure harmonic n of a sphere ~ P_n a^n / r^(n+1) P_n(cos theta), normalised so that P_100 = 1 is
    // the isolated sphere), the X^P series in Kim-Karrila units (6 pi a1^2) is
    //   X11P = sum_odd a_m t^m,  X12P = -sum_even a_m t^m,  a_m = sum_{n+p+q+1=m} P_npq lambda^(p+n) / (1+lambda)^m,
    // i.e. c[m][j] = sum_{n+p=j, q=m-1-j} P(n, p, q) (t = 2/s').
    // The same sum over the strain table (start P_200 = 1, "Pressure moment X^Q") gives X^Q with scale 10/3
    // and the extra lambda of the odd powers (the strain at sphere 2 scales with a2, as for X^M).
    static SeriesTriangle pressureMoment(const TripleTable& table, double scale = 1.0, bool oddShift = false);

    // f_k / (2 (1 + lambda))^k, computed without forming lambda^k (no overflow for large lambda, k).
    double normalisedTerm(int k, double lambda) const
    {
        const double w = lambda / (1 + lambda), u = 1 / (1 + lambda);
        double sum = 0, wq = 1;
        const double uk = std::pow(u, k);
        const double ratio = w / u;  // = lambda
        // w^q u^(k-q) = u^k lambda^q; use it while it is representable, else the safe product
        if (uk > 1e-280) {
            double term = uk;
            for (int q = 0; q <= k; ++q) {
                sum += c[k][q] * term;
                term *= ratio;
            }
        } else {
            for (int q = 0; q <= k; ++q) {
                sum += c[k][q] * wq * std::pow(u, k - q);
                wq *= w;
            }
        }
        if (oddPowerShift && (k % 2)) sum *= lambda;
        return scale * sum;
    }
};

// Truncation of the X^Q pressure series (the M recurrences of the strain problem, rebuilt to this order).
const int strainPressureMomentOrder = 200;

enum SeriesId { SeriesXA, SeriesXG, SeriesYA, SeriesYB, SeriesYG, SeriesYC, SeriesYH, SeriesXM, SeriesYM, SeriesZM, SeriesXP, SeriesXQ, NumSeries };

// Orders: 100 as in T23's generator for A, B, C, G, H and X^M; 130 for Y^M and 200 for Z^M, whose sums
// converge more slowly (T23 uses 130, and 150 / 200 for the even / odd Z^M sums).
struct SeriesStore {
    SeriesTriangle s[NumSeries];
    explicit SeriesStore(bool withM);

private:
    void addM();  // X^M, Y^M, Z^M and the X^Q pressure series
};

// Built once per process, thread-safely; withM: also the M and X^Q series (~2.5 s).
const SeriesStore& seriesStore(bool withM);

// The X^A, Y^A, Y^B, Y^C far-field series to a chosen order.  Up to order 100 the base store serves;
// above, the three recurrences are run once per order and process (cost ~ order^4, memory ~ order^3
// while building; the triangles kept afterwards are ~ order^2).
struct FullRangeSeries {
    SeriesTriangle xa, ya, yb, yc;
    SeriesTriangle xg, yg, yh;  // the stresslet series, from the same three recurrences
};
const FullRangeSeries& fullRangeSeries(int order);

}  // namespace detail
}  // namespace resistance
}  // namespace fdm

#endif
