// The exact solve of a separable box operator (fluid/boxSolvers/separableBoxSolver),
// without OpenFOAM: manufactured solutions on periodic and walled lattices, the singular
// Laplacian with OpenFOAM's reference cell, and the refusals.
#include "separableBoxSolver.H"

#include <gtest/gtest.h>

#include <algorithm>
#include <complex>
#include <memory>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

namespace
{

using fdm::separableBoxSolver;

// Coefficients varying across the walls (one value in a fully periodic box). A
// Laplacian-like operator: positive face coefficients, diag = -(their sum) + shift, so
// shift = 0 gives the singular Laplacian with zero-flux walls; sign -1 flips it to the
// negative definite form OpenFOAM's fvm::laplacian has.
separableBoxSolver::coefficients makeCoefficients
(
    const separableBoxSolver& solver,
    double shift,
    double sign,
    std::mt19937& rng
)
{
    std::uniform_real_distribution<double> u(0.5, 2.0);
    const long planes = solver.planes();
    const int w = solver.wallAxis();
    separableBoxSolver::coefficients c;
    c.diag.assign(planes, 0.0);
    for (int a = 0; a < 3; ++a)
    {
        const long size = (a == w) ? planes - 1 : planes;
        for (long p = 0; p < size; ++p)
        {
            c.offDiag[a].push_back(u(rng));
        }
    }
    for (long p = 0; p < planes; ++p)
    {
        double sum = 0;
        for (int a = 0; a < 3; ++a)
        {
            if (a == w)
            {
                if (p > 0) sum += c.offDiag[a][p-1];
                if (p < planes-1) sum += c.offDiag[a][p];
            }
            else
            {
                sum += 2*c.offDiag[a][p];
            }
        }
        c.diag[p] = -sum - shift*u(rng);
    }
    for (int a = 0; a < 3; ++a)
    {
        for (double& v : c.offDiag[a]) v *= -sign;
    }
    for (double& v : c.diag) v *= -sign;
    return c;
}

std::vector<double> randomField(std::size_t n, std::mt19937& rng)
{
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<double> x(n);
    for (double& v : x) v = u(rng);
    return x;
}

double maxDifference(const std::vector<double>& a, const std::vector<double>& b)
{
    double m = 0;
    for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(a[i] - b[i]));
    return m;
}

struct lattice
{
    std::array<long, 3> n;
    int wall;
};

// odd and even extents, every wall axis, and the fully periodic box
const lattice lattices[] =
{
    {{8, 6, 5}, -1}, {{7, 4, 6}, -1},
    {{8, 6, 5}, 0}, {{8, 6, 5}, 1}, {{8, 6, 5}, 2},
    {{5, 9, 4}, 1}, {{6, 1, 4}, 1}, {{3, 2, 7}, 2}
};

}


TEST(SeparableBoxSolver, RecoversAManufacturedSolutionToRoundOff)
{
    std::mt19937 rng(1);
    for (const lattice& l : lattices)
    {
        for (double sign : {1.0, -1.0})
        {
            separableBoxSolver solver(l.n, l.wall);
            solver.setCoefficients(makeCoefficients(solver, 0.3, sign, rng));
            EXPECT_FALSE(solver.singular());
            const std::vector<double> x = randomField(solver.size(), rng);
            std::vector<double> b(x.size()), y(x.size());
            solver.apply(x.data(), b.data());
            solver.solve(b.data(), y.data());
            EXPECT_LT(maxDifference(x, y), 1e-12)
                << "lattice " << l.n[0] << "x" << l.n[1] << "x" << l.n[2]
                << " wall axis " << l.wall << " sign " << sign;
        }
    }
}


TEST(SeparableBoxSolver, SolvesInPlace)
{
    std::mt19937 rng(2);
    separableBoxSolver solver({6, 5, 4}, 1);
    solver.setCoefficients(makeCoefficients(solver, 1.0, 1.0, rng));
    const std::vector<double> x = randomField(solver.size(), rng);
    std::vector<double> b(x.size());
    solver.apply(x.data(), b.data());
    solver.solve(b.data(), b.data());
    EXPECT_LT(maxDifference(x, b), 1e-12);
}


TEST(SeparableBoxSolver, SingularLaplacianWithAReferenceCellIsSolvedExactly)
{
    // fvMatrix::setReference adds delta to one cell's diagonal of a Laplacian whose rows
    // sum to zero (periodic or zero-flux walls): (M + delta e_r e_r^T) x = b
    std::mt19937 rng(3);
    for (const lattice& l : lattices)
    {
        for (double sign : {1.0, -1.0})
        {
            separableBoxSolver solver(l.n, l.wall);
            solver.setCoefficients(makeCoefficients(solver, 0.0, sign, rng));
            ASSERT_TRUE(solver.singular());
            const std::vector<double> x = randomField(solver.size(), rng);
            const std::size_t r = solver.index(l.n[0]-1, 0, l.n[2]/2);
            const double delta = -sign*1.7;
            std::vector<double> b(x.size()), y(x.size());
            solver.apply(x.data(), b.data());
            b[r] += delta*x[r];
            solver.solveWithReference(b.data(), y.data(), r, delta);
            EXPECT_LT(maxDifference(x, y), 1e-11)
                << "lattice " << l.n[0] << "x" << l.n[1] << "x" << l.n[2]
                << " wall axis " << l.wall;
        }
    }
}


TEST(SeparableBoxSolver, SingularLaplacianCompatibleSourceUpToAConstant)
{
    std::mt19937 rng(4);
    separableBoxSolver solver({8, 7, 6}, 1);
    solver.setCoefficients(makeCoefficients(solver, 0.0, -1.0, rng));
    ASSERT_TRUE(solver.singular());
    std::vector<double> x = randomField(solver.size(), rng);
    std::vector<double> b(x.size()), y(x.size());
    solver.apply(x.data(), b.data());
    solver.solve(b.data(), y.data());
    const double shift = x[0] - y[0];
    for (double& v : y) v += shift;
    EXPECT_LT(maxDifference(x, y), 1e-11);
}


TEST(SeparableBoxSolver, ReusesItsFactorsAndRefactorsWhenTheCoefficientsChange)
{
    std::mt19937 rng(5);
    separableBoxSolver solver({6, 6, 6}, 2);
    const auto first = makeCoefficients(solver, 0.5, 1.0, rng);
    const auto second = makeCoefficients(solver, 2.0, 1.0, rng);
    const std::vector<double> x = randomField(solver.size(), rng);
    std::vector<double> b(x.size()), y(x.size());
    for (const auto* c : {&first, &second, &first})
    {
        solver.setCoefficients(*c);
        solver.apply(x.data(), b.data());
        solver.solve(b.data(), y.data());
        EXPECT_LT(maxDifference(x, y), 1e-12);
    }
}


TEST(SeparableBoxSolver, RefusesWhatItCannotSolve)
{
    EXPECT_THROW(separableBoxSolver({4, 0, 4}, 1), std::invalid_argument);
    EXPECT_THROW(separableBoxSolver({4, 4, 4}, 3), std::invalid_argument);

    separableBoxSolver solver({4, 5, 6}, 1);
    separableBoxSolver::coefficients wrong;
    wrong.diag.assign(4, -6.0);                 // 5 planes across the walls
    wrong.offDiag[0].assign(5, 1.0);
    wrong.offDiag[1].assign(4, 1.0);
    wrong.offDiag[2].assign(5, 1.0);
    EXPECT_THROW(solver.setCoefficients(wrong), std::invalid_argument);

    // indefinite: a non-constant mode with a zero eigenvalue
    separableBoxSolver periodic({4, 4, 4}, -1);
    separableBoxSolver::coefficients indefinite;
    indefinite.diag = {0.0};
    indefinite.offDiag = {{{1.0}, {0.0}, {0.0}}};
    EXPECT_THROW(periodic.setCoefficients(indefinite), std::invalid_argument);

    separableBoxSolver regular({4, 4, 4}, -1);
    std::mt19937 rng(6);
    regular.setCoefficients(makeCoefficients(regular, 1.0, 1.0, rng));
    std::vector<double> b(regular.size(), 1.0), x(regular.size());
    EXPECT_THROW(regular.solveWithReference(b.data(), x.data(), 0, 1.0), std::invalid_argument);
}


// A box decomposed over processors: each transforms its slab of planes, the spectra are
// transposed to ranges of in-plane modes (done here by hand, as boxOperator does with
// Pstream), solved, transposed back. The parts give the whole solve's answer to round-off (bit
// for bit with FFTW_ESTIMATE here: the same transforms of the same planes, the same arithmetic
// per mode; a plan for fewer planes may in principle pick another algorithm).
TEST(SeparableBoxSolver, SolvedInPartsGivesTheWholeSolve)
{
    std::mt19937 rng(7);
    for (const lattice& l : lattices)
    {
        if (l.wall < 0) continue;
        separableBoxSolver whole(l.n, l.wall);
        const separableBoxSolver::coefficients c = makeCoefficients(whole, 0.3, -1.0, rng);
        whole.setCoefficients(c);
        const std::vector<double> x = randomField(whole.size(), rng);
        std::vector<double> b(x.size()), expected(x.size());
        whole.apply(x.data(), b.data());
        whole.solve(b.data(), expected.data());

        const long planes = whole.planes();
        // more processors than planes leaves some without a slab (and without modes)
        for (int nProcs : {1, 2, 3, int(planes) + 1})
        {
            auto planeStart = [&](int r) { return long(r)*planes/nProcs; };
            auto modeStart = [&](int r) { return std::size_t(r)*whole.modesPerPlane()/nProcs; };
            std::vector<std::unique_ptr<separableBoxSolver>> parts;
            for (int r = 0; r < nProcs; ++r)
            {
                parts.emplace_back(new separableBoxSolver(l.n, l.wall, false, planeStart(r), planeStart(r + 1)));
                parts.back()->setCoefficients(c);
            }
            const std::size_t perPlane = whole.cellsPerPlane(), modes = whole.modesPerPlane();
            // cell (i, j, k)'s value in the slab of the part that holds its plane
            auto inSlab = [&](long i, long j, long k) -> double&
            {
                const long ijk[3] = {i, j, k};
                const long p = ijk[l.wall];
                int r = 0;
                while (planeStart(r + 1) <= p) ++r;
                return parts[r]->planeValues()[(p - planeStart(r))*perPlane + whole.inPlaneIndex(i, j, k)];
            };
            // the right-hand side into the slabs
            for (long k = 0; k < l.n[2]; ++k)
                for (long j = 0; j < l.n[1]; ++j)
                    for (long i = 0; i < l.n[0]; ++i)
                        inSlab(i, j, k) = b[whole.index(i, j, k)];
            for (auto& part : parts) part->forwardPlanes();
            // transpose, solve each range of modes, transpose back
            for (int s = 0; s < nProcs; ++s)
            {
                const std::size_t m0 = modeStart(s), m1 = modeStart(s + 1), width = m1 - m0;
                std::vector<std::complex<double>> y(width*planes);
                for (int r = 0; r < nProcs; ++r)
                    for (long p = planeStart(r); p < planeStart(r + 1); ++p)
                        std::copy_n(parts[r]->planeSpectra() + (p - planeStart(r))*modes + m0, width,
                                    y.data() + width*p);
                parts[s]->solveModes(y.data(), m0, m1);
                for (int r = 0; r < nProcs; ++r)
                    for (long p = planeStart(r); p < planeStart(r + 1); ++p)
                        std::copy_n(y.data() + width*p, width,
                                    parts[r]->planeSpectra() + (p - planeStart(r))*modes + m0);
            }
            for (auto& part : parts) part->backwardPlanes();
            double largest = 0;
            for (long k = 0; k < l.n[2]; ++k)
                for (long j = 0; j < l.n[1]; ++j)
                    for (long i = 0; i < l.n[0]; ++i)
                        largest = std::max(largest, std::abs(inSlab(i, j, k) - expected[whole.index(i, j, k)]));
            EXPECT_LT(largest, 1e-13) << "lattice " << l.n[0] << "x" << l.n[1] << "x" << l.n[2] << " wall axis "
                                    << l.wall << " on " << nProcs << " processors";
        }
    }
}


TEST(SeparableBoxSolver, PartsAreRefusedWhereTheyCannotBe)
{
    // planes outside the box, a part of a fully periodic box, solve() on a part
    EXPECT_THROW(separableBoxSolver({4, 5, 6}, 1, false, 2, 6), std::invalid_argument);
    EXPECT_THROW(separableBoxSolver({4, 5, 6}, -1, false, 0, 0), std::invalid_argument);
    std::mt19937 rng(8);
    separableBoxSolver part({4, 5, 6}, 1, false, 1, 3);
    part.setCoefficients(makeCoefficients(part, 1.0, 1.0, rng));
    std::vector<double> b(part.size(), 1.0), x(part.size());
    EXPECT_THROW(part.solve(b.data(), x.data()), std::logic_error);
}
