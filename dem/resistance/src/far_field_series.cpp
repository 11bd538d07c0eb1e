// Far-field series of the two-sphere resistance scalars: the twin-multipole recurrences (sources in
// far_field_series.hpp), run once per process and reduced to coefficient triangles (far_field_series_store.hpp).
#include "fdm/resistance/far_field_series.hpp"

#include "far_field_series_store.hpp"

#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>

namespace fdm {
namespace resistance {
namespace detail {

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

namespace {

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

}  // namespace

SeriesTriangle::SeriesTriangle(const TripleTable& table, int n, double scale_, bool shift)
    : order(table.order()), oddPowerShift(shift), scale(scale_)
{
    c.resize(order + 1);
    for (int k = 0; k <= order; ++k) {
        c[k].resize(k + 1);
        for (int q = 0; q <= k; ++q) c[k][q] = table(n, k - q, q);
    }
}

SeriesTriangle SeriesTriangle::pressureMoment(const TripleTable& table, double scale, bool oddShift)
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

namespace {
// The first-order series, X^A, X^G (and X^P) from the axisymmetric translation problem, Y^A, Y^B, Y^G from
// the transverse translation, Y^C, Y^H from the rotation, at `order`: the one builder of the base store
// (order 100) and of the full-range forms' longer series.
void buildFirstOrderSeries(int order, bool withPressure, SeriesTriangle s[NumSeries])
{
    {
        std::unique_ptr<RecurrenceTables> t = buildAxisymmetric(order, 1);
        s[SeriesXA] = SeriesTriangle(t->P, 1, 1.0, false);      // J&O (3.15), T23 (9)
        s[SeriesXG] = SeriesTriangle(t->P, 2, 0.75, false);     // Ichiki et al. (94)
        if (withPressure) s[SeriesXP] = SeriesTriangle::pressureMoment(t->P);  // every n: pressure at the other centre
    }
    {
        std::unique_ptr<RecurrenceTables> t = buildAsymmetric(order, TranslationStart1);
        s[SeriesYA] = SeriesTriangle(t->P, 1, 1.0, false);      // J&O (4.12)
        s[SeriesYB] = SeriesTriangle(t->Q, 1, 2.0, false);      // J&O (5.2), T23 (21)
        s[SeriesYG] = SeriesTriangle(t->P, 2, 0.75, false);     // Ichiki et al. (115)
    }
    {
        std::unique_ptr<RecurrenceTables> t = buildAsymmetric(order, RotationStart1);
        s[SeriesYC] = SeriesTriangle(t->Q, 1, 1.0, true);       // J&O (7.6), T23 (29)
        s[SeriesYH] = SeriesTriangle(t->P, 2, -0.375, true);    // Ichiki et al. (120)
    }
}
}  // namespace

SeriesStore::SeriesStore(bool withM)
{
    buildFirstOrderSeries(100, true, s);
    if (withM) addM();
}

void SeriesStore::addM()
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

const SeriesStore& seriesStore(bool withM)
{
    // Function-local statics are initialised once, thread-safely (C++11).
    static SeriesStore base(false);
    if (!withM) return base;
    static SeriesStore full(true);
    return full;
}

const FullRangeSeries& fullRangeSeries(int order)
{
    static std::mutex mutex;
    static std::map<int, std::unique_ptr<FullRangeSeries> > cache;
    std::lock_guard<std::mutex> lock(mutex);
    std::unique_ptr<FullRangeSeries>& entry = cache[order];
    if (entry) return *entry;
    entry.reset(new FullRangeSeries);
    SeriesTriangle longer[NumSeries];
    const SeriesTriangle* series = seriesStore(false).s;
    if (order > 100) {
        buildFirstOrderSeries(order, false, longer);
        series = longer;
    }
    entry->xa = series[SeriesXA];
    entry->ya = series[SeriesYA];
    entry->yb = series[SeriesYB];
    entry->yc = series[SeriesYC];
    entry->xg = series[SeriesXG];
    entry->yg = series[SeriesYG];
    entry->yh = series[SeriesYH];
    return *entry;
}

}  // namespace detail

double farFieldCoefficient(PairFunction family, int k, double lambda)
{
    const detail::SeriesStore& store = detail::seriesStore(family == XQ);  // the X^Q series comes with the M recurrences
    detail::SeriesId id;
    switch (family) {
    case XA: id = detail::SeriesXA; break;
    case YA: id = detail::SeriesYA; break;
    case YB: id = detail::SeriesYB; break;
    case YC: id = detail::SeriesYC; break;
    case XG: id = detail::SeriesXG; break;
    case YG: id = detail::SeriesYG; break;
    case YH: id = detail::SeriesYH; break;
    case XP: id = detail::SeriesXP; break;
    case XQ: id = detail::SeriesXQ; break;
    default: throw std::invalid_argument("farFieldCoefficient: no far-field series kept for this family");
    }
    return store.s[id].normalisedTerm(k, lambda) * std::pow(2 * (1 + lambda), k);
}

}  // namespace resistance
}  // namespace fdm
