// The exact solve of a separable box operator (fluid/boxSolvers/separableBoxSolver),
// without OpenFOAM: manufactured solutions on periodic and walled lattices, the singular
// Laplacian with OpenFOAM's reference cell, and the refusals.
#include "separableBoxSolver.H"

#include <gtest/gtest.h>

#include <algorithm>
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
