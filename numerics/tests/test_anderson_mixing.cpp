// fdm::AndersonMixing (numerics/include/fdm/anderson_mixing.h) on fixed-point
// iterations whose answers are known: it must reach the same fixed point as the plain
// iteration, much sooner on a slowly contracting linear map (where it is GMRES in disguise),
// give the same iterates whatever the split of the vector over "ranks", and survive
// linearly dependent differences.
#include "fdm/anderson_mixing.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

namespace {

// A damped Jacobi (Richardson) sweep for -u'' = 1 on (0, 1), u(0) = u(1) = 0, n interior
// points: G(u) = u + omega h^2/2 (f + (u_{i-1} - 2 u_i + u_{i+1})/h^2). It contracts by
// 1 - omega (1 - cos(pi h)) ~ 1 - omega pi^2 h^2 / 2 per sweep: the slow diffusion of the
// plain inner iteration in miniature.
struct Poisson {
  int n;
  double h, omega;
  explicit Poisson(int n_) : n(n_), h(1.0 / (n_ + 1)), omega(1.0) {}
  std::vector<double> G(const std::vector<double> &u) const {
    std::vector<double> g(n);
    for (int i = 0; i < n; i++) {
      const double left = i > 0 ? u[i - 1] : 0.0, right = i < n - 1 ? u[i + 1] : 0.0;
      g[i] = u[i] + omega * 0.5 * h * h * (1.0 + (left - 2 * u[i] + right) / (h * h));
    }
    return g;
  }
  double exact(int i) const { const double x = (i + 1) * h; return 0.5 * x * (1 - x); }
  double error(const std::vector<double> &u) const {
    double e = 0;
    for (int i = 0; i < n; i++) e = std::max(e, std::fabs(u[i] - exact(i)));
    return e;
  }
};

// Iterations to bring the error below tol (plain if depth == 0), at most maxIterations
template <class Mixing = fdm::AndersonMixing>
int iterationsToConverge(const Poisson &problem, int depth, double tol, int maxIterations,
                         std::vector<double> *solution = nullptr) {
  std::vector<double> u(problem.n, 0.0);
  Mixing mixing(depth);
  for (int k = 1; k <= maxIterations; k++) {
    std::vector<double> g = problem.G(u);
    if (depth > 0) mixing.mix(u.data(), g.data(), g.size());
    u = g;
    if (problem.error(u) < tol) {
      if (solution) *solution = u;
      return k;
    }
  }
  if (solution) *solution = u;
  return maxIterations + 1;
}

}  // namespace

TEST(AndersonMixing, ReachesThePlainFixedPointInFarFewerIterations) {
  const Poisson problem(60);
  std::vector<double> accelerated;
  const int plain = iterationsToConverge(problem, 0, 1e-8, 100000);
  const int anderson = iterationsToConverge(problem, 8, 1e-8, 100000, &accelerated);
  // plain: ~ (2/pi^2)(n+1)^2 ln(1/tol) = 12 000 sweeps; depth 8 (measured 1656): a window of
  // eight differences is a truncated GMRES, which on this stiff symmetric map gains a factor ~7
  EXPECT_GT(plain, 5000);
  EXPECT_LT(anderson, plain / 5) << "plain " << plain << ", Anderson " << anderson;
  EXPECT_LT(problem.error(accelerated), 1e-8);
}

TEST(AndersonMixing, WithTheWholeHistoryItIsGmres) {
  // Walker & Ni (2011): with every difference kept, Anderson acceleration of a linear fixed-point
  // map is GMRES, which ends in at most n steps on an n-dimensional problem (measured: 21 for
  // n = 40 with 1e-8, against 645 with depth 8 and ~5 000 plain sweeps)
  const Poisson problem(40);
  const int full = iterationsToConverge(problem, problem.n, 1e-8, 10000);
  EXPECT_LE(full, problem.n + 2);
}

TEST(AndersonMixing, FloatHistoryReachesBelowFloatPrecisionOfTheIterate) {
  // The differences kept as floats perturb each iterate by 6e-8 of the step mixed, not of the
  // iterate: the error still falls far below float precision of u (max u = 1/8, float spacing
  // there 7e-9). Iterations, double and float history, measured: 1258 and 1261 to 1e-6, 1656
  // and 1679 to 1e-8, 1896 and 2128 to 1e-11 (the fluid's inner iterations stop near 1e-2)
  const Poisson problem(60);
  std::vector<double> solution;
  const int doubles = iterationsToConverge(problem, 8, 1e-11, 100000);
  const int floats = iterationsToConverge<fdm::AndersonMixingFloatHistory>(problem, 8, 1e-11, 100000, &solution);
  EXPECT_LT(problem.error(solution), 1e-11);
  EXPECT_LT(floats, doubles * 5 / 4) << "double history " << doubles << ", float " << floats;
}

TEST(AndersonMixing, FirstStepIsThePlainStep) {
  const Poisson problem(10);
  std::vector<double> u(problem.n, 0.0), g = problem.G(u), plain = g;
  fdm::AndersonMixing mixing(5);
  EXPECT_FALSE(mixing.mix(u.data(), g.data(), g.size()));
  EXPECT_EQ(g, plain);
  EXPECT_EQ(mixing.size(), 0);
}

// Two "ranks" on two threads: each sums its partial sums with the other's, as Pstream does.
class TwoRankSum {
 public:
  void operator()(int rank, std::vector<double> &sums) {
    std::unique_lock<std::mutex> lock(mutex_);
    const long generation = generation_;
    partial_[rank] = sums;
    if (++arrived_ == 2) {
      total_ = partial_[0];
      for (size_t i = 0; i < total_.size(); i++) total_[i] += partial_[1][i];
      arrived_ = 0;
      ++generation_;
      done_.notify_all();
    } else {
      done_.wait(lock, [&] { return generation_ != generation; });
    }
    sums = total_;
  }
 private:
  std::mutex mutex_;
  std::condition_variable done_;
  std::vector<double> partial_[2], total_;
  int arrived_ = 0;
  long generation_ = 0;
};

TEST(AndersonMixing, SameIteratesWhateverTheSplitOverRanks) {
  const Poisson problem(40);
  // Few iterations: the sums are added in another order than in serial, and the least-squares
  // problem amplifies that round-off (1e-11 after 10 iterations here, growing after), as the
  // fluid's decomposed runs do (tests/test_periodic_array.py).
  const int iterations = 8, half = problem.n / 3;   // an uneven split
  // serial reference
  std::vector<double> reference(problem.n, 0.0);
  fdm::AndersonMixing serial(6);
  std::vector<std::vector<double> > referenceIterates;
  for (int k = 0; k < iterations; k++) {
    std::vector<double> g = problem.G(reference);
    serial.mix(reference.data(), g.data(), g.size());
    reference = g;
    referenceIterates.push_back(reference);
  }
  // distributed: each rank applies G to the whole vector (the map is not what is tested) but
  // mixes only its own part, with its own mixer, the inner products summed over both ranks
  TwoRankSum sum;
  std::vector<double> shared(problem.n, 0.0);
  std::vector<std::vector<double> > ownParts(2);
  std::mutex sharedMutex;
  std::vector<double> maxDifference(2, 0.0);
  auto rank = [&](int r) {
    const int lo = r == 0 ? 0 : half, hi = r == 0 ? half : problem.n;
    fdm::AndersonMixing mixing(6, [&sum, r](std::vector<double> &s) { sum(r, s); });
    std::vector<double> x(problem.n, 0.0);
    for (int k = 0; k < iterations; k++) {
      std::vector<double> g = problem.G(x);
      std::vector<double> mine(g.begin() + lo, g.begin() + hi);
      mixing.mix(x.data() + lo, mine.data(), mine.size());
      for (int i = lo; i < hi; i++)
        maxDifference[r] = std::max(maxDifference[r], std::fabs(mine[i - lo] - referenceIterates[k][i]));
      // the other rank's part of the new iterate: in an MPI code it arrives by a halo exchange;
      // here it is the reference's, which the other thread reproduces (checked above)
      x = referenceIterates[k];
      for (int i = lo; i < hi; i++) x[i] = mine[i - lo];
    }
  };
  std::thread first(rank, 0), second(rank, 1);
  first.join();
  second.join();
  EXPECT_LT(maxDifference[0], 1e-10);
  EXPECT_LT(maxDifference[1], 1e-10);
}

TEST(AndersonMixing, DropsLinearlyDependentDifferences) {
  // A map that changes only one component: every difference is parallel to the first, so the
  // least-squares problem is singular from the second difference on. No NaN, columns dropped,
  // and the iteration still converges to the fixed point x = (1, 0, 0).
  auto G = [](const std::vector<double> &x) {
    std::vector<double> g(x);
    g[0] = 0.5 * x[0] + 0.5;
    return g;
  };
  std::vector<double> x = {0.0, 0.0, 0.0};
  fdm::AndersonMixing mixing(4);
  for (int k = 0; k < 10; k++) {
    std::vector<double> g = G(x);
    mixing.mix(x.data(), g.data(), g.size());
    x = g;
    for (double v : x) ASSERT_TRUE(std::isfinite(v));
  }
  EXPECT_NEAR(x[0], 1.0, 1e-12);
  EXPECT_EQ(x[1], 0.0);
  EXPECT_GE(mixing.dropped(), 1);
  EXPECT_LE(mixing.size(), 1);
}

TEST(AndersonMixing, ResetForgetsTheHistory) {
  const Poisson problem(10);
  std::vector<double> u(problem.n, 0.0);
  fdm::AndersonMixing mixing(5);
  for (int k = 0; k < 4; k++) {
    std::vector<double> g = problem.G(u);
    mixing.mix(u.data(), g.data(), g.size());
    u = g;
  }
  EXPECT_GT(mixing.size(), 0);
  mixing.reset();
  EXPECT_EQ(mixing.size(), 0);
  std::vector<double> g = problem.G(u), plain = g;
  EXPECT_FALSE(mixing.mix(u.data(), g.data(), g.size()));
  EXPECT_EQ(g, plain);
}

TEST(AndersonMixing, KeptGramMatrixGivesTheIteratesOfTheTextbookFormula) {
  // the Gram matrix kept from one iteration to the next (O(m n) per iteration) against Anderson's
  // formula recomputed from scratch: gamma = argmin |f_k - dF gamma| by the normal equations of the
  // whole window, x_{k+1} = G(x_k) - dG gamma; the window slides (m = 5 of 40 iterations)
  const Poisson problem(30);
  const int depth = 5;
  fdm::AndersonMixing mixing(depth);
  std::vector<double> u(problem.n, 0.0), v(problem.n, 0.0), previousG, previousF;
  std::vector<std::vector<double>> dG, dF;
  for (int k = 0; k < 40; k++) {
    std::vector<double> g = problem.G(u);
    mixing.mix(u.data(), g.data(), g.size());
    u = g;
    // the textbook formula on its own copy of the iterates
    std::vector<double> G = problem.G(v), f(problem.n);
    for (int i = 0; i < problem.n; i++) f[i] = G[i] - v[i];
    if (!previousG.empty()) {
      std::vector<double> a(problem.n), b(problem.n);
      for (int i = 0; i < problem.n; i++) {
        a[i] = G[i] - previousG[i];
        b[i] = f[i] - previousF[i];
      }
      dG.push_back(a);
      dF.push_back(b);
      if (int(dF.size()) > depth) {
        dG.erase(dG.begin());
        dF.erase(dF.begin());
      }
    }
    previousG = G;
    previousF = f;
    const int m = int(dF.size());
    std::vector<double> next = G;
    if (m > 0) {
      // normal equations A gamma = r by Gaussian elimination with partial pivoting
      std::vector<std::vector<double>> A(m, std::vector<double>(m + 1, 0.0));
      for (int r = 0; r < m; r++) {
        for (int c = 0; c < m; c++)
          for (int i = 0; i < problem.n; i++) A[r][c] += dF[r][i] * dF[c][i];
        for (int i = 0; i < problem.n; i++) A[r][m] += dF[r][i] * f[i];
      }
      for (int c = 0; c < m; c++) {
        int p = c;
        for (int r = c + 1; r < m; r++)
          if (std::fabs(A[r][c]) > std::fabs(A[p][c])) p = r;
        std::swap(A[c], A[p]);
        for (int r = c + 1; r < m; r++) {
          const double q = A[r][c] / A[c][c];
          for (int j = c; j <= m; j++) A[r][j] -= q * A[c][j];
        }
      }
      std::vector<double> gamma(m);
      for (int r = m - 1; r >= 0; r--) {
        double s = A[r][m];
        for (int j = r + 1; j < m; j++) s -= A[r][j] * gamma[j];
        gamma[r] = s / A[r][r];
      }
      for (int j = 0; j < m; j++)
        for (int i = 0; i < problem.n; i++) next[i] -= gamma[j] * dG[j][i];
    }
    v = next;
    double scale = 0, difference = 0;
    for (int i = 0; i < problem.n; i++) {
      scale = std::max(scale, std::fabs(v[i]));
      difference = std::max(difference, std::fabs(u[i] - v[i]));
    }
    ASSERT_LE(difference, 1e-9 * scale) << "iteration " << k;
    if (problem.error(v) < 1e-12) break;   // converged: the differences lose their meaning
  }
  EXPECT_EQ(mixing.size(), depth);
}
