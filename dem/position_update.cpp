// Position update with the log-gap correction (see position_update.h).
#include "position_update.h"

#include <algorithm>
#include <cmath>

namespace fdm {
namespace motion {

namespace {

struct Gap {
  int i, j;       // j < 0: a wall, index -1 - j
  double target;  // surface gap wanted at step n+1
  double scale;   // what |gap - target| is compared with: the target, or h_r for a held contact gap
  double lower;   // the bound of the fallback: min(target, h_n), which the positions x_n meet
};

void minimumImage(double d[3], const double period[3])
{
  for (int k = 0; k < 3; k++)
    if (period[k] > 0) d[k] -= period[k] * std::round(d[k] / period[k]);
}

// x_j - x_i (minimum image) into d; returns its length.
double separation(const Configuration &c, const std::vector<double> &x, int i, int j, double d[3])
{
  for (int k = 0; k < 3; k++) d[k] = x[3 * j + k] - x[3 * i + k];
  minimumImage(d, c.period);
  return std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

// +1 for a wall below the fluid (side 0), -1 above: the direction from the wall into the fluid.
double intoFluid(const Wall &w) { return w.side == 0 ? 1.0 : -1.0; }

double wallGapOf(const Configuration &c, const std::vector<double> &x, int i, const Wall &w)
{
  return intoFluid(w) * (x[3 * i + w.axis] - w.position) - c.radius[i];
}

// Surface gap of pair (i, j) and its rate of change d.(U_j - U_i) for positions x, velocities u.
void pairGap(const Configuration &c, const std::vector<double> &x, const std::vector<double> &u, int i, int j,
             double &h, double &hdot)
{
  double d[3];
  const double r = separation(c, x, i, j, d);
  h = r - c.radius[i] - c.radius[j];
  hdot = 0;
  if (r > 0)
    for (int k = 0; k < 3; k++) hdot += d[k] / r * (u[6 * j + k] - u[6 * i + k]);
}

void wallGap(const Configuration &c, const std::vector<double> &x, const std::vector<double> &u, int i,
             const Wall &w, double &h, double &hdot)
{
  h = wallGapOf(c, x, i, w);
  hdot = intoFluid(w) * u[6 * i + w.axis];
}

// h_{n+1} = h_n exp(dt [3/2 (hdot/h)_n - 1/2 (hdot/h)_{n-1}]), Euler in log h without a usable
// previous gap. Returns false if the gap is closed (h_n <= 0: contact overlap, left to the
// straight step).
bool logTarget(double h, double hdot, bool havePrevious, double hPrevious, double hdotPrevious, double dt,
               const Options &o, double &target, long &limited)
{
  if (!(h > 0) || h < o.contactGap) return false;
  double rate = hdot / h;
  if (o.adamsBashforth && havePrevious && hPrevious > 0) rate = 1.5 * rate - 0.5 * hdotPrevious / hPrevious;
  double step = dt * rate;
  if (std::fabs(step) > o.maxLogStep) {
    step = std::copysign(o.maxLogStep, step);
    limited++;
  }
  target = h * std::exp(step);
  return true;
}

}  // namespace

Statistics displacementRates(const Configuration &c, const std::vector<int> &closePairs,
                             const std::vector<Wall> &walls, double dt, const Options &o, std::vector<double> &rate)
{
  Statistics stats;
  const int n = c.n;
  const bool previous = c.uPrevious.size() == size_t(6) * n && c.xPrevious.size() == size_t(3) * n;
  const bool multistep = o.adamsBashforth && previous;
  rate.assign(size_t(6) * n, 0.0);
  for (size_t k = 0; k < rate.size(); k++) rate[k] = multistep ? 1.5 * c.u[k] - 0.5 * c.uPrevious[k] : c.u[k];
  if (!o.gapCorrection || !(dt > 0)) return stats;

  // the straight step
  std::vector<double> y(size_t(3) * n);
  for (int i = 0; i < n; i++)
    for (int k = 0; k < 3; k++) y[3 * i + k] = c.x[3 * i + k] + dt * rate[6 * i + k];

  // Targets: log h for the gaps of lubrication; a gap held by a contact spring (h < h_r) or closed
  // keeps the gap the straight step gives it (what the implicit springs of Eq. 31 assumed,
  // docs/contact.md C2), so that the corrections of its particles' other gaps do not push it
  // deeper into contact (in dense clusters they did: overlaps of 0.03-0.07 a1, docs/benchmarks.md)
  std::vector<Gap> gaps;
  const double smallest = 1e-9 * (n ? *std::min_element(c.radius.begin(), c.radius.end()) : 1.0);
  const auto held = [&](int i, int j, double straightGap, double gapNow) {
    gaps.push_back(Gap{i, j, straightGap, std::max(std::max(o.contactGap, std::fabs(straightGap)), smallest),
                       std::min(straightGap, gapNow)});
    stats.heldGaps++;
  };
  for (size_t p = 0; p + 1 < closePairs.size(); p += 2) {
    const int i = closePairs[p], j = closePairs[p + 1];
    double h, hdot, hp = 0, hdotp = 0, target;
    pairGap(c, c.x, c.u, i, j, h, hdot);
    if (previous) pairGap(c, c.xPrevious, c.uPrevious, i, j, hp, hdotp);
    if (logTarget(h, hdot, previous, hp, hdotp, dt, o, target, stats.limited)) {
      gaps.push_back(Gap{i, j, target, target, std::min(target, h)});
      stats.pairGaps++;
    } else if (o.holdContactGaps) {
      double d[3];
      held(i, j, separation(c, y, i, j, d) - c.radius[i] - c.radius[j], h);
    }
  }
  for (int i = 0; i < n; i++)
    for (size_t w = 0; w < walls.size(); w++) {
      double h, hdot, hp = 0, hdotp = 0, target;
      wallGap(c, c.x, c.u, i, walls[w], h, hdot);
      if (!(h < c.radius[i])) continue;
      if (previous) wallGap(c, c.xPrevious, c.uPrevious, i, walls[w], hp, hdotp);
      if (logTarget(h, hdot, previous, hp, hdotp, dt, o, target, stats.limited)) {
        gaps.push_back(Gap{i, -1 - int(w), target, target, std::min(target, h)});
        stats.wallGaps++;
      } else if (o.holdContactGaps) {
        held(i, -1 - int(w), wallGapOf(c, y, i, walls[w]), h);
      }
    }
  // held gaps alone are met by the straight step
  if (stats.pairGaps + stats.wallGaps == 0) return stats;

  // the straight step moved along the lines of centres until every gap has its target
  std::vector<char> touched(n, 0);
  for (const Gap &g : gaps) {
    touched[g.i] = 1;
    if (g.j >= 0) touched[g.j] = 1;
  }
  // One Gauss-Seidel sweep: each gap moved to its target (bounds = false), or, on the fallback,
  // only pushed apart where it is below its bound (bounds = true); returns the largest relative miss
  // slack: on bounds, a gap within slack * scale of its bound is left alone
  const auto sweep = [&](bool bounds, double slack) {
    double worst = 0;
    for (const Gap &g : gaps) {
      double miss;  // > 0: push apart
      double d[3] = {0, 0, 0}, r = 0;
      if (g.j >= 0) {
        r = separation(c, y, g.i, g.j, d);
        miss = (bounds ? g.lower : g.target) - (r - c.radius[g.i] - c.radius[g.j]);
      } else {
        miss = (bounds ? g.lower : g.target) - wallGapOf(c, y, g.i, walls[size_t(-1 - g.j)]);
      }
      if (bounds && miss <= slack * g.scale) continue;
      if (g.j >= 0) {
        // the smaller sphere (less drag) takes the larger share
        const double ai = c.radius[g.i], aj = c.radius[g.j];
        const double wi = aj / (ai + aj), wj = ai / (ai + aj);
        for (int k = 0; k < 3; k++) {
          y[3 * g.i + k] -= wi * miss * d[k] / r;
          y[3 * g.j + k] += wj * miss * d[k] / r;
        }
      } else {
        const Wall &w = walls[size_t(-1 - g.j)];
        y[3 * g.i + w.axis] += intoFluid(w) * miss;
      }
      worst = std::max(worst, std::fabs(miss) / g.scale);
    }
    return worst;
  };
  // Bound sweeps until no gap is below its bound by more than the tolerance (gaps within slack of
  // theirs left alone); returns the first sweep's largest violation
  const auto holdToBounds = [&](double slack) {
    double first = 0;
    for (stats.boundSweeps = 1; stats.boundSweeps <= o.maxBoundSweeps; stats.boundSweeps++) {
      stats.worstBound = sweep(true, slack);
      if (stats.boundSweeps == 1) first = stats.worstBound;
      if (stats.worstBound <= o.tolerance) break;
    }
    stats.boundSweeps = std::min(stats.boundSweeps, o.maxBoundSweeps);
    return first;
  };
  double previousWorst = HUGE_VAL;
  for (stats.sweeps = 1; stats.sweeps <= o.maxSweeps; stats.sweeps++) {
    const double worst = sweep(false, 0.0);
    stats.worst = worst;
    if (worst <= o.tolerance) break;
    // inconsistent targets (see Options::tolerance): stop once the sweeps no longer gain
    if (stats.sweeps >= 3 && worst > 0.8 * previousWorst) break;
    previousWorst = worst;
  }
  stats.sweeps = std::min(stats.sweeps, o.maxSweeps);
  if (stats.worst > o.fallback) {
    // The targets contradict each other (relative motions of gaps far from lubrication's hdot ~ h
    // at a large dt, or many coupled gaps of a dense cluster): no compromise between them is
    // good. The fallback starts again from the straight step and only keeps every gap from
    // closing below its bound, min(target, h_n) (a held contact gap: min(straight gap, h_n)),
    // pushing apart along the lines of centres: the closing lubrication gaps cannot overshoot
    // their log targets into contact, which the straight step alone let them do (the whole step
    // was straight before 2026-11-25: in the phi 0.37 Table 8 scene at dt 0.04 at nearly every
    // step, and a pair driven together at 3.7 a1 gamma_dot overlapped by 0.07 a1). The positions
    // x_n meet every bound, so the sweeps have a solution.
    stats.fallback = true;
    for (int i = 0; i < n; i++)
      for (int k = 0; k < 3; k++) y[3 * i + k] = c.x[3 * i + k] + dt * rate[6 * i + k];
    holdToBounds(0.0);
  } else if (stats.worst > o.tolerance) {
    // A compromise between targets that contradict each other mildly (a ring of close pairs
    // through the periodic box) spreads their misses over every gap of the ring, a held contact
    // gap too: closed a little further than the springs assumed at every step, it ratcheted into
    // an overlap the springs could not stop (the channel of cases/poiseuille at step 220: two
    // spheres 0.05 a1 deep, 0.0017 a1 per step beyond their straight step, docs/dem.md). The
    // compromise keeps its positions where it meets the bounds of the fallback and is pushed apart
    // along the lines of centres where it does not.
    stats.compromiseMiss = holdToBounds(o.tolerance);
  }
  for (int i = 0; i < n; i++)
    if (touched[i])
      for (int k = 0; k < 3; k++) rate[6 * i + k] = (y[3 * i + k] - c.x[3 * i + k]) / dt;
  return stats;
}

}  // namespace motion
}  // namespace fdm
