// fdm::channel::solveProfile (fluid/fdmFoam/meanFlowCorrection/channelProfile.H): the
// plane-averaged steady Stokes equation of a channel on the finite-volume stencil fdmFoam uses.
// Checked against profiles with closed forms: Couette flow (linear, exact on the stencil at any
// n), plane Poiseuille flow (second-order convergence to the parabola, and the exact
// discrete flow rate), and the stencil itself (the residual of every row, including the walls),
// with and without the damping viscosity of meanFlowCorrection.H.
#include "channelProfile.H"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace {

// The row j of the finite-volume operator applied to u: (nu/delta^2)(-u_{j-1} + 2u_j - u_{j+1})
// with the walls half a cell from the first and last centres.
double row(const std::vector<double> &u, int j, double nu, double delta, double low, double high) {
  const int n = static_cast<int>(u.size());
  const double k = nu / (delta * delta);
  const double fluxBelow = j == 0 ? 2 * (u[0] - low) : u[j] - u[j - 1];
  const double fluxAbove = j == n - 1 ? 2 * (high - u[n - 1]) : u[j + 1] - u[j];
  return k * (fluxBelow - fluxAbove);
}

}  // namespace

TEST(ChannelProfile, CouetteFlowIsExactAtCellCentres) {
  // -nu u'' = 0 between walls at -U and +U: u = -U + 2U y/H at every centre y_j = (j + 1/2) delta
  for (int n : {1, 2, 7, 40}) {
    const double H = 3.0, delta = H / n, U = 1.7;
    const auto u = fdm::channel::solveProfile(std::vector<double>(n, 0.0), 0.3, delta, -U, U);
    for (int j = 0; j < n; j++) {
      EXPECT_NEAR(u[j], -U + 2 * U * (j + 0.5) * delta / H, 1e-13) << "n " << n << " j " << j;
    }
  }
}

TEST(ChannelProfile, EveryRowOfTheStencilHolds) {
  // random source and wall velocities: the solution satisfies each discrete row to round-off
  const int n = 25;
  const double nu = 0.7, delta = 0.13, low = 0.4, high = -1.1;
  std::vector<double> s(n);
  for (int j = 0; j < n; j++) s[j] = std::sin(1.3 * j) + 0.2 * j;
  const auto u = fdm::channel::solveProfile(s, nu, delta, low, high);
  for (int j = 0; j < n; j++) {
    EXPECT_NEAR(row(u, j, nu, delta, low, high), s[j], 1e-10 * (1 + std::fabs(s[j]))) << "row " << j;
  }
}

TEST(ChannelProfile, PoiseuilleFlowConvergesAtSecondOrder) {
  // -nu u'' = G, u(0) = u(H) = 0: u = G y (H - y) / (2 nu). The half-cell wall rows are first
  // order locally, the profile second order globally; the discrete flow rate is exact up to
  // the same order.
  const double H = 2.0, nu = 0.5, G = 3.0;
  double previous = 0;
  for (int n : {8, 16, 32, 64}) {
    const double delta = H / n;
    const auto u = fdm::channel::solveProfile(std::vector<double>(n, G), nu, delta, 0.0, 0.0);
    double error = 0;
    for (int j = 0; j < n; j++) {
      const double y = (j + 0.5) * delta;
      error = std::max(error, std::fabs(u[j] - G * y * (H - y) / (2 * nu)));
    }
    if (previous > 0) {
      EXPECT_NEAR(previous / error, 4.0, 0.3) << "n " << n;
    }
    previous = error;
  }
  EXPECT_LT(previous, 1e-3 * G * H * H / (8 * nu));
}

TEST(ChannelProfile, DampingLeavesTheSteadyProfileUnchanged) {
  // When the profile it relaxes towards is already the steady one, the damping viscosity nuP
  // cancels: the answer is the undamped profile, whatever nuP (here uneven, zero at a wall)
  const int n = 30;
  const double nu = 0.4, delta = 0.2, low = -1.0, high = 2.5;
  std::vector<double> s(n), nuP(n + 1);
  for (int j = 0; j < n; j++) s[j] = std::cos(0.7 * j) - 0.1 * j;
  for (int f = 0; f <= n; f++) nuP[f] = f == 0 ? 0.0 : 3.0 + 2.0 * std::sin(0.9 * f);
  const auto steady = fdm::channel::solveProfile(s, nu, delta, low, high);
  const auto damped = fdm::channel::solveProfile(s, nu, delta, low, high, nuP, steady);
  for (int j = 0; j < n; j++) EXPECT_NEAR(damped[j], steady[j], 1e-12 * (1 + std::fabs(steady[j]))) << j;
}

TEST(ChannelProfile, EveryRowOfTheDampedStencilHolds) {
  // -d/dy((nu + nuP) du/dy) = s - d/dy(nuP dv/dy) row by row, v a profile far from the answer,
  // with the face coefficients doubled at the walls (half a cell from the first and last centres)
  const int n = 17;
  const double nu = 0.7, delta = 0.13, low = 0.4, high = -1.1;
  std::vector<double> s(n), nuP(n + 1), v(n);
  for (int j = 0; j < n; j++) {
    s[j] = std::sin(1.3 * j) + 0.2 * j;
    v[j] = 5.0 * std::cos(0.4 * j);
  }
  for (int f = 0; f <= n; f++) nuP[f] = 1.0 + 0.5 * f;
  const auto u = fdm::channel::solveProfile(s, nu, delta, low, high, nuP, v);
  // the flux of w through face f (upwards) with viscosity mu_f, walls at their velocities
  auto flux = [&](const std::vector<double> &w, int f, double mu) {
    const double below = f == 0 ? low : w[f - 1], above = f == n ? high : w[f];
    return mu * (above - below) / (f == 0 || f == n ? delta / 2 : delta);
  };
  for (int j = 0; j < n; j++) {
    const double lhs = -(flux(u, j + 1, nu + nuP[j + 1]) - flux(u, j, nu + nuP[j])) / delta;
    const double rhs = s[j] - (flux(v, j + 1, nuP[j + 1]) - flux(v, j, nuP[j])) / delta;
    EXPECT_NEAR(lhs, rhs, 1e-9 * (1 + std::fabs(rhs))) << "row " << j;
  }
}

TEST(ChannelProfile, BadInputIsRefused) {
  EXPECT_THROW(fdm::channel::solveProfile({}, 1.0, 1.0, 0, 0), std::invalid_argument);
  EXPECT_THROW(fdm::channel::solveProfile({1.0}, 0.0, 1.0, 0, 0), std::invalid_argument);
  EXPECT_THROW(fdm::channel::solveProfile({1.0}, 1.0, -1.0, 0, 0), std::invalid_argument);
  // the damping viscosity needs a value per face (n + 1) and the profile one per cell
  EXPECT_THROW(fdm::channel::solveProfile({1.0, 2.0}, 1.0, 1.0, 0, 0, {1.0, 1.0}, {0.0, 0.0}),
               std::invalid_argument);
  EXPECT_THROW(fdm::channel::solveProfile({1.0, 2.0}, 1.0, 1.0, 0, 0, {1.0, 1.0, 1.0}, {0.0}),
               std::invalid_argument);
}
