// Far-field recurrences and near-field constants: see near_field_series.hpp for the sources.
#include "fdm/resistance/near_field_series.hpp"

#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>

namespace fdm {
namespace resistance {

const char* pairFunctionName(PairFunction f)
{
    static const char* names[NumPairFunctions] = {"XA", "YA", "YB", "XC", "YC", "XG",
                                                  "YG", "YH", "XM", "YM", "ZM", "XP", "XQ"};
    return names[f];
}

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

// ---------------------------------------------------------------------------------------------
// P, Q, V coefficient tables of the twin multipole expansions, indexed (n, p, q) with p + q <= N.
// Every non-zero entry has n <= p + 2 (the recurrences only reach back through p - n + 1 >= 0, and
// the starting values sit at p = q = 0, n <= 2), so only that triangle is stored.
class TripleTable {
public:
    explicit TripleTable(int order) : order_(order), offset_((order + 1) * (order + 1), 0)
    {
        std::size_t size = 0;
        for (int p = 0; p <= order; ++p)
            for (int q = 0; p + q <= order; ++q) {
                offset_[p * (order + 1) + q] = size;
                size += p + 3;
            }
        data_.assign(size, 0.0);
    }
    double operator()(int n, int p, int q) const
    {
        if (n < 0 || p < 0 || q < 0 || p + q > order_ || n > p + 2) return 0.0;
        return data_[offset_[p * (order_ + 1) + q] + n];
    }
    double& at(int n, int p, int q) { return data_[offset_[p * (order_ + 1) + q] + n]; }
    int order() const { return order_; }

private:
    int order_;
    std::vector<std::size_t> offset_;
    std::vector<double> data_;
};

struct RecurrenceTables {
    TripleTable P, Q, V;
    explicit RecurrenceTables(int order) : P(order), Q(order), V(order) {}
};

class Binomial {
public:
    explicit Binomial(int nmax) : nmax_(nmax), table_((nmax + 1) * (nmax + 1), 0.0)
    {
        for (int n = 0; n <= nmax; ++n) {
            table_[n * (nmax + 1)] = 1.0;
            for (int k = 1; k <= n; ++k)
                table_[n * (nmax + 1) + k] = table_[(n - 1) * (nmax + 1) + k - 1] +
                                             (k <= n - 1 ? table_[(n - 1) * (nmax + 1) + k] : 0.0);
        }
    }
    double operator()(int n, int k) const { return (k < 0 || k > n) ? 0.0 : table_[n * (nmax_ + 1) + k]; }

private:
    int nmax_;
    std::vector<double> table_;
};

// Axisymmetric problems (X^A, X^G from n = 1 start; X^M from n = 2): J&O (3.9)-(3.12), T23 (5)-(8).
std::unique_ptr<RecurrenceTables> buildAxisymmetric(int order, int startIndex)
{
    std::unique_ptr<RecurrenceTables> t(new RecurrenceTables(order));
    const Binomial C(2 * order + 4);
    TripleTable &P = t->P, &V = t->V;
    P.at(startIndex, 0, 0) = V.at(startIndex, 0, 0) = 1.0;
    for (int level = 1; level <= order; ++level)
        for (int p = 0; p <= level; ++p) {
            const int q = level - p;
            for (int n = 1; n <= p + 2; ++n) {
                const double nn = n;
                double sumP = 0, sumV = 0;
                for (int s = 1; s <= q; ++s) {
                    const double ss = s, binom = C(n + s, n);
                    const double viaP = nn * (2 * nn + 1) * (2 * nn * ss - nn - ss + 2) /
                                        (2 * (nn + 1) * (2 * ss - 1) * (nn + ss)) * P(s, q - s, p - n + 1);
                    const double viaPlower = nn * (2 * nn - 1) / (2 * (nn + 1)) * P(s, q - s, p - n - 1);
                    const double viaV = nn * (4 * nn * nn - 1) / (2 * (nn + 1) * (2 * ss + 1)) * V(s, q - s - 2, p - n + 1);
                    sumP += binom * (viaP - viaPlower - viaV);
                    sumV += binom * P(s, q - s, p - n - 1);
                }
                P.at(n, p, q) = sumP;
                V.at(n, p, q) = sumP - 2 * nn / ((nn + 1) * (2 * nn + 3)) * sumV;
            }
        }
    return t;
}

// Asymmetric problems (Y^A, Y^B, Y^G from a translation start; Y^C, Y^H from a rotation start,
// Q(1,0,0) = 1; Y^M from n = 2): J&O (4.6)-(4.11), (7.3)-(7.5), J92 (58).
enum AsymmetricStart { TranslationStart1, RotationStart1, TranslationStart2 };

std::unique_ptr<RecurrenceTables> buildAsymmetric(int order, AsymmetricStart start)
{
    std::unique_ptr<RecurrenceTables> t(new RecurrenceTables(order));
    const Binomial C(2 * order + 4);
    TripleTable &P = t->P, &Q = t->Q, &V = t->V;
    if (start == RotationStart1)
        Q.at(1, 0, 0) = 1.0;
    else {
        const int n0 = (start == TranslationStart1) ? 1 : 2;
        P.at(n0, 0, 0) = V.at(n0, 0, 0) = 1.0;
    }
    for (int level = 1; level <= order; ++level)
        for (int p = 0; p <= level; ++p) {
            const int q = level - p;
            for (int n = 1; n <= p + 2; ++n) {
                const double nn = n;
                double sumP = 0, sumQ = 0, sumV = 0;
                for (int s = 1; s <= q; ++s) {
                    const double ss = s, binom = C(n + s, n + 1);
                    const double coefP = (2 * nn + 1) / (2 * (nn + 1)) *
                                         (3 * (nn + ss) - (nn * ss + 1) * (2 * nn * ss - ss - nn + 2)) /
                                         (ss * (nn + ss) * (2 * ss - 1));
                    sumP += binom * (coefP * P(s, q - s, p - n + 1) +
                                     nn * (2 * nn - 1) / (2 * (nn + 1)) * P(s, q - s, p - n - 1) +
                                     nn * (4 * nn * nn - 1) / (2 * (nn + 1) * (2 * ss + 1)) * V(s, q - s - 2, p - n + 1) -
                                     2 * (4 * nn * nn - 1) / (3 * (nn + 1)) * Q(s, q - s - 1, p - n + 1));
                    sumQ += binom * (ss / (nn + 1) * Q(s, q - s - 1, p - n) -
                                     3 / (2 * nn * ss * (nn + 1)) * P(s, q - s, p - n));
                    sumV += binom * P(s, q - s, p - n - 1);
                }
                P.at(n, p, q) = sumP;
                Q.at(n, p, q) = sumQ;
                V.at(n, p, q) = sumP + 2 * nn / ((nn + 1) * (2 * nn + 3)) * sumV;
            }
        }
    return t;
}

// Z^M problem: J92 (73)-(76), starting at n = 2.
std::unique_ptr<RecurrenceTables> buildZ(int order)
{
    std::unique_ptr<RecurrenceTables> t(new RecurrenceTables(order));
    const Binomial C(2 * order + 4);
    TripleTable &P = t->P, &Q = t->Q, &V = t->V;
    P.at(2, 0, 0) = V.at(2, 0, 0) = 1.0;
    for (int level = 1; level <= order; ++level)
        for (int p = 0; p <= level; ++p) {
            const int q = level - p;
            for (int n = 1; n <= p + 2; ++n) {
                const double nn = n;
                double sumP = 0, sumQ = 0, sumV = 0;
                for (int s = 2; s <= q; ++s) {
                    const double ss = s, binom = C(n + s, n + 2);
                    const double coefP = (2 * nn + 1) / (nn + 1) *
                                         (nn * ss * (nn + ss - 2 * nn * ss - 2) - 4 * (2 * nn * ss - 4 * ss - 4 * nn + 2)) /
                                         (2 * ss * (nn + ss) * (2 * ss - 1));
                    sumP += binom * (-2 * (2 * nn + 1) * (2 * nn - 1) / (nn + 1) * Q(s, q - s - 1, p - n + 1) +
                                     nn * (2 * nn + 1) * (2 * nn - 1) / (2 * (nn + 1) * (2 * ss + 1)) * V(s, q - s - 2, p - n + 1) +
                                     coefP * P(s, q - s, p - n + 1) +
                                     nn * (2 * nn - 1) / (2 * (nn + 1)) * P(s, q - s, p - n - 1));
                    sumQ += binom * (ss / (nn + 1) * Q(s, q - s - 1, p - n) - 2 / (nn * ss * (nn + 1)) * P(s, q - s, p - n));
                    sumV += binom * P(s, q - s, p - n - 1);
                }
                P.at(n, p, q) = sumP;
                Q.at(n, p, q) = sumQ;
                V.at(n, p, q) = sumP + 2 * nn / ((nn + 1) * (2 * nn + 3)) * sumV;
            }
        }
    return t;
}

// ---------------------------------------------------------------------------------------------
// A far-field series f_k(lambda) = scale 2^k sum_q c[k][q] lambda^(q + shift(k)), kept as the triangle
// c[k][q] (lambda-independent) so that per-lambda sums cost O(order^2) and no recurrence.
struct SeriesTriangle {
    int order = 0;
    bool oddPowerShift = false;  // the extra lambda^(k mod 2) of the C, H and M series
    double scale = 1;
    std::vector<std::vector<double> > c;

    SeriesTriangle() {}
    SeriesTriangle(const TripleTable& table, int n, double scale_, bool shift) : order(table.order()), oddPowerShift(shift), scale(scale_)
    {
        c.resize(order + 1);
        for (int k = 0; k <= order; ++k) {
            c[k].resize(k + 1);
            for (int q = 0; q <= k; ++q) c[k][q] = table(n, k - q, q);
        }
    }

    // The pressure-moment series (docs/resistance.md, "Pressure moment X^P"): the trace of the force dipole of
    // sphere 1 is -a1 times the surface integral of the pressure, which by the mean-value property is
    // 4 pi a1^2 times the pressure of sphere 2's decaying harmonics at x1.  With J&O's axisymmetric table
    // (pressure harmonic n of a sphere ~ P_n a^n / r^(n+1) P_n(cos theta), normalised so that P_100 = 1 is
    // the isolated sphere), the X^P series in Kim-Karrila units (6 pi a1^2) is
    //   X11P = sum_odd a_m t^m,  X12P = -sum_even a_m t^m,  a_m = sum_{n+p+q+1=m} P_npq lambda^(p+n) / (1+lambda)^m,
    // i.e. c[m][j] = sum_{n+p=j, q=m-1-j} P(n, p, q) (t = 2/s').
    // The same sum over the strain table (start P_200 = 1, "Pressure moment X^Q") gives X^Q with scale 10/3
    // and the extra lambda of the odd powers (the strain at sphere 2 scales with a2, as for X^M).
    static SeriesTriangle pressureMoment(const TripleTable& table, double scale = 1.0, bool oddShift = false)
    {
        SeriesTriangle s;
        s.scale = scale;
        s.oddPowerShift = oddShift;
        s.order = table.order();
        s.c.resize(s.order + 1);
        for (int k = 0; k <= s.order; ++k) {
            s.c[k].assign(k + 1, 0.0);
            for (int j = 1; j < k; ++j)
                for (int n = 1; n <= j; ++n) s.c[k][j] += table(n, j - n, k - 1 - j);
        }
        return s;
    }

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
    SeriesStore(bool withM)
    {
        {
            std::unique_ptr<RecurrenceTables> t = buildAxisymmetric(100, 1);
            s[SeriesXA] = SeriesTriangle(t->P, 1, 1.0, false);      // J&O (3.15), T23 (9)
            s[SeriesXG] = SeriesTriangle(t->P, 2, 0.75, false);     // Ichiki et al. (94)
            s[SeriesXP] = SeriesTriangle::pressureMoment(t->P);     // every n: pressure at the other centre
        }
        {
            std::unique_ptr<RecurrenceTables> t = buildAsymmetric(100, TranslationStart1);
            s[SeriesYA] = SeriesTriangle(t->P, 1, 1.0, false);      // J&O (4.12)
            s[SeriesYB] = SeriesTriangle(t->Q, 1, 2.0, false);      // J&O (5.2), T23 (21)
            s[SeriesYG] = SeriesTriangle(t->P, 2, 0.75, false);     // Ichiki et al. (115)
        }
        {
            std::unique_ptr<RecurrenceTables> t = buildAsymmetric(100, RotationStart1);
            s[SeriesYC] = SeriesTriangle(t->Q, 1, 1.0, true);       // J&O (7.6), T23 (29)
            s[SeriesYH] = SeriesTriangle(t->P, 2, -0.375, true);    // Ichiki et al. (120)
        }
        if (withM) addM();
    }
    void addM()
    {
        if (!s[SeriesZM].c.empty()) return;
        {
            std::unique_ptr<RecurrenceTables> t = buildAxisymmetric(100, 2);
            s[SeriesXM] = SeriesTriangle(t->P, 2, 1.0, true);       // Ichiki et al. (105)
        }
        {
            // the same strain problem to order 200 for X^Q (~1 s): its constants need the L/m^2 tail, whose level
            // is estimated from the coefficients themselves (docs/resistance.md, truncation 100 vs 200 vs 300)
            std::unique_ptr<RecurrenceTables> t = buildAxisymmetric(strainPressureMomentOrder, 2);
            s[SeriesXQ] = SeriesTriangle::pressureMoment(t->P, 10.0 / 3.0, true);  // pressure at the other centre
        }
        {
            std::unique_ptr<RecurrenceTables> t = buildAsymmetric(130, TranslationStart2);
            s[SeriesYM] = SeriesTriangle(t->P, 2, 1.0, true);       // Ichiki et al. (125)
        }
        {
            std::unique_ptr<RecurrenceTables> t = buildZ(200);
            s[SeriesZM] = SeriesTriangle(t->P, 2, 1.0, true);       // Ichiki et al. (131)
        }
    }
};

const SeriesStore& seriesStore(bool withM)
{
    // Function-local statics are initialised once, thread-safely (C++11).
    static SeriesStore base(false);
    if (!withM) return base;
    static SeriesStore full(true);
    return full;
}

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

double farFieldCoefficient(PairFunction family, int k, double lambda)
{
    const SeriesStore& store = seriesStore(family == XQ);  // the X^Q series comes with the M recurrences
    SeriesId id;
    switch (family) {
    case XA: id = SeriesXA; break;
    case YA: id = SeriesYA; break;
    case YB: id = SeriesYB; break;
    case YC: id = SeriesYC; break;
    case XG: id = SeriesXG; break;
    case YG: id = SeriesYG; break;
    case YH: id = SeriesYH; break;
    case XP: id = SeriesXP; break;
    case XQ: id = SeriesXQ; break;
    default: throw std::invalid_argument("farFieldCoefficient: no far-field series kept for this family");
    }
    return store.s[id].normalisedTerm(k, lambda) * std::pow(2 * (1 + lambda), k);
}

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
        const SeriesTriangle& s = store.s[SeriesXA];
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
        const SeriesTriangle& sp = store.s[SeriesXP];
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
        const SeriesTriangle& s = store.s[SeriesYA];
        const double A11 = 1 - g3 - 4 * g3 / (double(M) * (M + 2)) + subtractedSum(s, lam, Even, M, 0, g2, g3);
        const double A12 = -2 / l1 * (2 * g2 * L - 2 * g3 - 4 * g3 / (double(M - 1) * (M + 1)) + subtractedSum(s, lam, Odd, M, 0, g2, g3));
        k.f11[YA] = form(0, g2, A11, g3);
        k.f12[YA] = form(0, -g2, 0.5 * l1 * A12, -g3);
    }
    // Y^B: J&O (5.5)-(5.7), T23 (22)-(25).
    {
        const double g2 = -lam * (4 + lam) / (5 * l1_2);
        const double g3 = -(32 - 33 * lam + 83 * l2 + 43 * l3) / (250 * l1_2);
        const SeriesTriangle& s = store.s[SeriesYB];
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
        const SeriesTriangle& s = store.s[SeriesYC];
        const double C11 = 1 - g3 + subtractedSum(s, lam, Even, M, 0, g2, g3);
        const double C12 = 8 / l1_3 * (2 * g4 * L - 2 * g5 + subtractedSum(s, lam, Odd, M, 0, g4, g5));
        k.f11[YC] = form(0, g2, C11, g3);
        k.f12[YC] = form(0, g4, l1_3 / 8 * C12, g5);
    }
    // X^G: J92 (19)-(21).
    {
        const double g1 = 3 * l2 / l1_3, g2 = 3 * (lam + 12 * l2 - 4 * l3) / (10 * l1_3);
        const double g3 = (5 + 181 * lam - 453 * l2 + 566 * l3 - 65 * l4) / (140 * l1_3);
        const SeriesTriangle& s = store.s[SeriesXG];
        const double G11 = g1 / 4 + 2 * g2 * L - 2 * g3 + subtractedSum(s, lam, Odd, M, g1, g2, g3);
        const double G12 = 4 / l1_2 * (g1 / 4 + g3 - subtractedSum(s, lam, Even, M, g1, g2, g3));
        k.f11[XG] = form(g1, g2, G11, g3);
        k.f12[XG] = form(-g1, -g2, 0.25 * l1_2 * G12, -g3);
    }
    // Y^G: J92 (27)-(29).
    {
        const double g2 = (4 * lam - l2 + 7 * l3) / (10 * l1_3);
        const double g3 = (32 - 179 * lam + 532 * l2 - 356 * l3 + 221 * l4) / (500 * l1_3);
        const SeriesTriangle& s = store.s[SeriesYG];
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
        const SeriesTriangle& s = store.s[SeriesYH];
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
        const SeriesTriangle& s = store.s[SeriesXM];
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
        const SeriesTriangle& s = store.s[SeriesYM];
        const double M11 = 1 - g3 + subtractedSum(s, lam, Even, 130, 0, g2, g3);
        const double M12 = 8 / l1_3 * (2 * g5 * L - 2 * g6 + subtractedSum(s, lam, Odd, 130, 0, g5, g6));
        k.f11[YM] = form(0, g2, M11, g3);
        k.f12[YM] = form(0, g5, l1_3 / 8 * M12, g6);
    }
    // Z^M: J92 (79)-(81), sums to order 150 (even) and 200 (odd).
    {
        const double g3 = -0.3 * (l2 + l4) / l1_3;
        const SeriesTriangle& s = store.s[SeriesZM];
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
        const SeriesTriangle& s = store.s[SeriesXQ];
        const int MQ = strainPressureMomentOrder;
        const double Q11 = -g1 / 4 + subtractedSumWithTail(s, lam, Even, MQ, g1, h1);
        const double Q12 = lam * g1 / 4 + 2 * h2 * L + subtractedSumWithTail(s, lam, Odd, MQ, lam * g1, h2);
        k.f11[XQ] = form(g1, h1, Q11, 0);
        k.f12[XQ] = form(lam * g1, h2, Q12, 0);
    }
    return k;
}

// ---------------------------------------------------------------------------------------------
// Full-range forms (near_field_series.hpp, docs/resistance.md).

namespace {

// The X^A, Y^A, Y^B, Y^C far-field series to a chosen order.  Up to order 100 the base store serves;
// above, the three recurrences are run once per order and process (cost ~ order^4, memory ~ order^3
// while building; the triangles kept afterwards are ~ order^2).
struct FullRangeSeries {
    SeriesTriangle xa, ya, yb, yc;
};

const FullRangeSeries& fullRangeSeries(int order)
{
    static std::mutex mutex;
    static std::map<int, std::unique_ptr<FullRangeSeries> > cache;
    std::lock_guard<std::mutex> lock(mutex);
    std::unique_ptr<FullRangeSeries>& entry = cache[order];
    if (entry) return *entry;
    entry.reset(new FullRangeSeries);
    if (order <= 100) {
        const SeriesStore& base = seriesStore(false);
        entry->xa = base.s[SeriesXA];
        entry->ya = base.s[SeriesYA];
        entry->yb = base.s[SeriesYB];
        entry->yc = base.s[SeriesYC];
        return *entry;
    }
    {
        std::unique_ptr<RecurrenceTables> t = buildAxisymmetric(order, 1);
        entry->xa = SeriesTriangle(t->P, 1, 1.0, false);     // J&O (3.15)
    }
    {
        std::unique_ptr<RecurrenceTables> t = buildAsymmetric(order, TranslationStart1);
        entry->ya = SeriesTriangle(t->P, 1, 1.0, false);     // J&O (4.12)
        entry->yb = SeriesTriangle(t->Q, 1, 2.0, false);     // J&O (5.2)
    }
    {
        std::unique_ptr<RecurrenceTables> t = buildAsymmetric(order, RotationStart1);
        entry->yc = SeriesTriangle(t->Q, 1, 1.0, true);      // J&O (7.6)
    }
    return *entry;
}

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

// S1, S2, S3 of near_field_series.hpp at xi, written with xi so that nothing cancels near contact.
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

bool hasFullRangeForm(PairFunction f) { return f == XA || f == YA || f == YB || f == XC || f == YC; }

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
