// Benchmark (not a test): cost of planning one position update with the log-gap correction
// (dem/position_update.h) for 1000 spheres with 6 close neighbours each (3000 gaps at 1e-3 a,
// a periodic simple cubic lattice), random velocities (argument: their amplitude, default 1e-3 a per unit time). Prints the
// median over repeats of the straight step and of the corrected one, and the sweeps used.
#include "position_update.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <random>

int main(int argc, char **argv)
{
  namespace motion = fdm::motion;
  const int side = 10, n = side * side * side, repeats = 51;
  const double a = 1.0, gap = 1e-3, spacing = 2 * a + gap, dt = 0.05;
  motion::Configuration c;
  c.n = n;
  c.radius.assign(n, a);
  c.x.resize(3 * n);
  c.u.resize(6 * n);
  c.uPrevious.resize(6 * n);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> noise(-1.0, 1.0);
  const double amplitude = argc > 1 ? std::atof(argv[1]) : 1e-3;  // relative velocity noise
  std::vector<int> pairs;
  auto index = [&](int i, int j, int k) { return ((i + side) % side) * side * side + ((j + side) % side) * side + (k + side) % side; };
  for (int i = 0; i < side; i++)
    for (int j = 0; j < side; j++)
      for (int k = 0; k < side; k++) {
        const int p = index(i, j, k);
        c.x[3 * p] = i * spacing;
        c.x[3 * p + 1] = j * spacing;
        c.x[3 * p + 2] = k * spacing;
        for (int d = 0; d < 6; d++) {
          c.u[6 * p + d] = amplitude * noise(random);
          c.uPrevious[6 * p + d] = c.u[6 * p + d] + 0.1 * amplitude * noise(random);
        }
        for (int q : {index(i + 1, j, k), index(i, j + 1, k), index(i, j, k + 1)}) {
          pairs.push_back(p);
          pairs.push_back(q);
        }
      }
  for (int d = 0; d < 3; d++) c.period[d] = side * spacing;
  c.xPrevious = c.x;  // where the previous velocities brought the particles from
  for (int p = 0; p < n; p++)
    for (int d = 0; d < 3; d++) c.xPrevious[3 * p + d] -= dt * c.uPrevious[6 * p + d];

  std::vector<double> rate;
  auto time = [&](const motion::Options &o, motion::Statistics &stats) {
    std::vector<double> seconds;
    for (int r = 0; r < repeats; r++) {
      const auto t0 = std::chrono::steady_clock::now();
      stats = motion::displacementRates(c, pairs, {}, dt, o, rate);
      seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    std::nth_element(seconds.begin(), seconds.begin() + repeats / 2, seconds.end());
    return seconds[repeats / 2];
  };
  motion::Options straight;
  straight.gapCorrection = false;
  motion::Statistics s0, s1;
  const double t0 = time(straight, s0), t1 = time(motion::Options(), s1);
  std::printf("{\"noise\": %g, \"particles\": %d, \"gaps\": %ld, \"straight_ms\": %.4f, \"log_gap_ms\": %.4f, \"sweeps\": %d, "
              "\"worst\": %.2e, \"limited\": %ld, \"fallback\": %d, \"repeats\": %d}\n",
              amplitude, n, s1.pairGaps, 1e3 * t0, 1e3 * t1, s1.sweeps, s1.worst, s1.limited, int(s1.fallback), repeats);
  return 0;
}
