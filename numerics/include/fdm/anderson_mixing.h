/*---------------------------------------------------------------------------*\
    fdm numerics: plain C++ shared by the fluid solver and the particle side

Class
    fdm::BasicAndersonMixing (fdm::AndersonMixing, fdm::AndersonMixingFloatHistory)

Description
    The arithmetic of Anderson acceleration (Anderson, J. ACM 12, 1965;
    Walker & Ni, SIAM J. Numer. Anal. 49, 2011) for a fixed-point iteration
    x -> G(x) on a vector distributed over MPI ranks, in plain C++11 so that
    it is unit-tested without OpenFOAM (numerics/tests). Its users: fdmFoam's
    inner iteration (fluid/fdmFoam/andersonAcceleration packs the fields into
    the vector) and the Coulomb rounds of Eq. (31) on the particle side
    (dem/particle_velocity_system.cpp).

    It keeps the last m differences dG_j = G_{j+1} - G_j and
    df_j = f_{j+1} - f_j of the residual f = G(x) - x, and replaces G(x_k) by

        x_{k+1} = G(x_k) - sum_j gamma_j dG_j,
        gamma   = argmin |f_k - sum_j gamma_j df_j|_2,

    solved by the normal equations with the columns scaled to unit norm and
    a Cholesky factorisation; while the smallest pivot is below 1e-10 (a
    column nearly a combination of the others) the oldest column is dropped.
    Every inner product is a local sum completed by the reduction the caller
    gives (a sum over ranks; none in serial): one reduction per iteration.
    The Gram matrix of the differences is kept from one iteration to the
    next (each new difference adds one row), so an iteration costs O(m n),
    not O(m^2 n): deep histories (m = 20-40, which the dense suspensions
    want) cost little more than short ones.

    The differences are stored as History (BasicAndersonMixing<History>):
    AndersonMixing keeps doubles; AndersonMixingFloatHistory keeps floats,
    which halves the history's memory and what an iteration reads of it
    (the fluid's mixing 13-15 % faster on the Table 8 scenes: packing the
    fields and updating G stay). Rounding a difference to float perturbs the next iterate
    by 6e-8 of the step it mixes, not of the iterate (x_k and G(x_k) stay
    double, the sums are double), so the fixed point and any tolerance above
    that are unchanged: the fluid's inner iteration uses it.

\*---------------------------------------------------------------------------*/

#ifndef fdm_AndersonMixing_H
#define fdm_AndersonMixing_H

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <deque>
#include <functional>
#include <vector>

namespace fdm
{

template<class History>
class BasicAndersonMixing
{
public:

    //- Sums a list of partial sums over the ranks, in place
    typedef std::function<void(std::vector<double>&)> Reduction;

    explicit BasicAndersonMixing(int depth, Reduction sumOverRanks = Reduction())
    :
        depth_(depth),
        sumOverRanks_(sumOverRanks),
        havePrevious_(false),
        dropped_(0)
    {}

    //- Forget the history (the map has changed)
    void reset()
    {
        // the history's vectors are kept for the next step's
        for (std::vector<History>& v : dG_) spare_.push_back(std::move(v));
        for (std::vector<History>& v : dF_) spare_.push_back(std::move(v));
        dG_.clear();
        dF_.clear();
        gram_.clear();
        havePrevious_ = false;
        dropped_ = 0;
    }

    //- x: the iterate x_k; g: G(x_k) on entry, x_{k+1} on return; n values
    //  on this rank. Returns false when there was no history to mix (g is
    //  left as G(x_k): the plain step).
    bool mix(const double* x, double* g, std::size_t n)
    {
        if (!havePrevious_)
        {
            previousG_.assign(g, g + n);
            previousF_.resize(n);
            for (std::size_t i = 0; i < n; ++i)
            {
                previousF_[i] = g[i] - x[i];
            }
            havePrevious_ = true;
            return false;
        }
        // one pass over the vectors: f = G(x) - x, the new differences
        // dG = G - G_prev and df = f - f_prev, and G and f kept as the
        // previous ones (separate loops read g three times)
        std::vector<History> dG = spareVector(n), dF = spareVector(n);
        {
            double* pG = previousG_.data();
            double* pF = previousF_.data();
            History* dGi = dG.data();
            History* dFi = dF.data();
            for (std::size_t i = 0; i < n; ++i)
            {
                const double gi = g[i];
                const double fi = gi - x[i];
                dGi[i] = History(gi - pG[i]);
                dFi[i] = History(fi - pF[i]);
                pG[i] = gi;
                pF[i] = fi;
            }
        }
        dG_.push_back(std::move(dG));
        dF_.push_back(std::move(dF));
        const std::vector<double>& f = previousF_;
        const std::vector<History>& dFNew = dF_.back();

        // the new row of the Gram matrix and the right-hand side, in blocks
        // of the vector so that dF and f are read from cache once per block
        // (each sum still adds its terms in the order of k)
        const int m = int(dF_.size());
        std::vector<double> sums(2*std::size_t(m), 0.0);
        for (std::size_t k0 = 0; k0 < n; k0 += block_)
        {
            const std::size_t k1 = std::min(n, k0 + block_);
            for (int j = 0; j < m; ++j)
            {
                const History* d = dF_[j].data();
                double row = sums[j], rhs = sums[m + j];
                for (std::size_t k = k0; k < k1; ++k)
                {
                    const double dk = d[k];
                    row += dk*double(dFNew[k]);
                    rhs += dk*f[k];
                }
                sums[j] = row;
                sums[m + j] = rhs;
            }
        }
        if (sumOverRanks_)
        {
            sumOverRanks_(sums);
        }
        gram_.push_back(std::vector<double>(sums.begin(), sums.begin() + m));
        for (int j = 0; j < m - 1; ++j)
        {
            gram_[j].push_back(sums[j]);
        }
        std::vector<double> rhs(sums.begin() + m, sums.end());
        if (m > depth_)
        {
            dropOldest(rhs);
        }

        const std::vector<double> gamma = coefficients(rhs);
        if (gamma.empty())
        {
            return false;
        }
        // g -= sum_j gamma_j dG_j, in blocks (each g[i] subtracts in the
        // order of j)
        for (std::size_t i0 = 0; i0 < n; i0 += block_)
        {
            const std::size_t i1 = std::min(n, i0 + block_);
            for (std::size_t j = 0; j < gamma.size(); ++j)
            {
                const History* d = dG_[j].data();
                const double c = gamma[j];
                for (std::size_t i = i0; i < i1; ++i)
                {
                    g[i] -= c*double(d[i]);
                }
            }
        }
        return true;
    }

    int size() const { return int(dF_.size()); }

    //- Differences dropped as ill-conditioned since the last reset
    int dropped() const { return dropped_; }

private:

    //- Forget the oldest difference (its row and column of the Gram matrix,
    //  its entry of the right-hand side)
    //- A vector of n from the recycled ones (allocating a vector of the
    //  whole state every iteration cost more than the arithmetic)
    std::vector<History> spareVector(std::size_t n)
    {
        std::vector<History> v;
        if (!spare_.empty())
        {
            v.swap(spare_.back());
            spare_.pop_back();
        }
        v.resize(n);
        return v;
    }

    void dropOldest(std::vector<double>& rhs)
    {
        spare_.push_back(std::move(dF_.front()));
        spare_.push_back(std::move(dG_.front()));
        dF_.pop_front();
        dG_.pop_front();
        gram_.pop_front();
        for (std::vector<double>& row : gram_)
        {
            row.erase(row.begin());
        }
        rhs.erase(rhs.begin());
    }

    //- gamma from the kept Gram matrix and rhs_j = df_j . f_k
    std::vector<double> coefficients(std::vector<double> rhs)
    {
        while (!dF_.empty())
        {
            const int m = int(dF_.size());

            // Columns scaled to unit norm, then Cholesky A = L L^T
            std::vector<double> scale(m), L(std::size_t(m)*m, 0.0);
            bool usable = true;
            for (int i = 0; i < m; ++i)
            {
                scale[i] = std::sqrt(std::max(gram_[i][i], 1e-300));
            }
            for (int i = 0; i < m && usable; ++i)
            {
                for (int j = 0; j <= i; ++j)
                {
                    double a = gram_[j][i]/(scale[i]*scale[j]);
                    for (int k = 0; k < j; ++k)
                    {
                        a -= L[i*m + k]*L[j*m + k];
                    }
                    if (i == j)
                    {
                        if (!(a > 1e-10))
                        {
                            usable = false;
                            break;
                        }
                        L[i*m + i] = std::sqrt(a);
                    }
                    else
                    {
                        L[i*m + j] = a/L[j*m + j];
                    }
                }
            }
            if (!usable)
            {
                dropOldest(rhs);
                ++dropped_;
                continue;
            }

            std::vector<double> y(m), gamma(m);
            for (int i = 0; i < m; ++i)
            {
                double s = rhs[i]/scale[i];
                for (int k = 0; k < i; ++k)
                {
                    s -= L[i*m + k]*y[k];
                }
                y[i] = s/L[i*m + i];
            }
            for (int i = m - 1; i >= 0; --i)
            {
                double s = y[i];
                for (int k = i + 1; k < m; ++k)
                {
                    s -= L[k*m + i]*gamma[k];
                }
                gamma[i] = s/L[i*m + i];
            }
            for (int i = 0; i < m; ++i)
            {
                gamma[i] /= scale[i];
            }
            return gamma;
        }
        return std::vector<double>();
    }

    const int depth_;
    const Reduction sumOverRanks_;
    std::deque<std::vector<History> > dG_;
    std::deque<std::vector<History> > dF_;
    //- gram_[i][j] = df_i . df_j (reduced over the ranks), i, j over dF_
    std::deque<std::vector<double> > gram_;
    std::vector<double> previousG_;
    std::vector<double> previousF_;
    //- Vectors of dropped differences, reused
    std::vector<std::vector<History> > spare_;
    //- Entries per block of the blocked loops (fits the L1/L2 caches)
    static const std::size_t block_ = 2048;
    bool havePrevious_;
    int dropped_;
};

//- The Coulomb rounds of Eq. (31): short vectors, tolerances near round-off
typedef BasicAndersonMixing<double> AndersonMixing;

//- The fluid's inner iteration: long vectors read at every iteration
typedef BasicAndersonMixing<float> AndersonMixingFloatHistory;

} // End namespace fdm

#endif
