// Checks of the particles' configuration (configuration_checks.h).
#include "configuration_checks.h"

#include "fdm/coupler.h"
#include "message_text.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace fdm {

using text::number;
using text::particleId;
using text::point;

std::string configurationProblem(const std::vector<GatheredParticle> &particles, const ParticleBox &box,
                                 bool fromInput)
{
  const char *axis = "xyz";
  const double tolerance = coupler::contactOverlapTolerance;
  for (size_t i = 0; i < particles.size(); i++) {
    const GatheredParticle &p = particles[i];
    const std::string who = "particle " + particleId(int(i)) + " at " + point(p.x) + " with radius " + number(p.radius);
    if (!(p.radius > 0) || !(p.density > 0) || !(p.mass > 0))
      return who + " has a non-positive radius, density (" + number(p.density) + ") or mass (" + number(p.mass) + ")";
    for (int d = 0; d < 3; d++) {
      const double lo = box.lo[d], hi = box.hi[d];
      if (!std::isfinite(p.x[d]) || p.x[d] < lo || p.x[d] > hi)
        return who + ": its centre lies outside the box in " + axis[d] + " (" + number(lo) + " .. " + number(hi) + ")";
      if (box.periodic[d]) {
        if (2 * p.radius > box.length[d])
          return who + " is larger than the periodic box in " + axis[d] + " (extent " + number(box.length[d]) +
                 "): it would overlap its own image";
        continue;
      }
      const bool low = p.x[d] - p.radius - lo < hi - p.x[d] - p.radius;
      const double gap = low ? p.x[d] - p.radius - lo : hi - p.x[d] - p.radius;
      const double allowed = fromInput ? 0.0 : tolerance * p.radius;
      if (gap < -allowed)
        return who + " crosses the wall " + axis[d] + " = " + number(low ? lo : hi) + " (non-periodic boundary; box " +
               number(lo) + " .. " + number(hi) + "): gap " + number(gap) +
               (fromInput ? std::string()
                          : " (" + number(-gap / p.radius) + " radii, more than the " + number(tolerance) +
                                " radii accepted for a contact pressed into a wall)");
    }
  }
  return fromInput ? firstOverlap(particles, box) : std::string();
}

std::string firstOverlap(const std::vector<GatheredParticle> &p, const ParticleBox &box)
{
  // Bins at least 2 r_max wide, so overlapping pairs are in the same or adjacent bins; sorting by bin
  // and looking the 27 neighbours up is O(N log N).
  const long n = long(p.size());
  if (n < 2) return "";
  double rmax = 0;
  for (const GatheredParticle &q : p) rmax = std::max(rmax, q.radius);
  int bins[3];
  for (int d = 0; d < 3; d++) bins[d] = std::max(1, int(std::min(1e6, std::floor(box.length[d] / (2 * rmax)))));
  while (double(bins[0]) * bins[1] * bins[2] > 8.0 * n + 64)
    for (int d = 0; d < 3; d++) bins[d] = std::max(1, bins[d] / 2);
  auto binOf = [&](const double *x, int d) {
    double s = (x[d] - box.lo[d]) / box.length[d];
    if (box.periodic[d]) s -= std::floor(s);
    return std::min(bins[d] - 1, std::max(0, int(s * bins[d])));
  };
  auto key = [&](int bx, int by, int bz) { return (long long)(bx * (long long) bins[1] + by) * bins[2] + bz; };
  std::vector<std::pair<long long, long> > sorted(n);
  for (long i = 0; i < n; i++) sorted[i] = std::make_pair(key(binOf(p[i].x, 0), binOf(p[i].x, 1), binOf(p[i].x, 2)), i);
  std::sort(sorted.begin(), sorted.end());

  long firstI = -1, firstJ = -1, pairs = 0;
  double firstGap = 0;
  std::vector<long long> neighbours;
  for (long i = 0; i < n; i++) {
    const int b[3] = {binOf(p[i].x, 0), binOf(p[i].x, 1), binOf(p[i].x, 2)};
    neighbours.clear();
    for (int dx = -1; dx <= 1; dx++)
      for (int dy = -1; dy <= 1; dy++)
        for (int dz = -1; dz <= 1; dz++) {
          int c[3] = {b[0] + dx, b[1] + dy, b[2] + dz};
          bool inside = true;
          for (int d = 0; d < 3; d++) {
            if (box.periodic[d]) c[d] = (c[d] + bins[d]) % bins[d];
            else if (c[d] < 0 || c[d] >= bins[d]) inside = false;
          }
          if (inside) neighbours.push_back(key(c[0], c[1], c[2]));
        }
    std::sort(neighbours.begin(), neighbours.end());
    neighbours.erase(std::unique(neighbours.begin(), neighbours.end()), neighbours.end());
    for (long long k : neighbours) {
      auto range = std::equal_range(sorted.begin(), sorted.end(), std::make_pair(k, -1L),
          [](const std::pair<long long, long> &a, const std::pair<long long, long> &c) { return a.first < c.first; });
      for (auto it = range.first; it != range.second; ++it) {
        const long j = it->second;
        if (j <= i) continue;
        double r2 = 0;
        for (int d = 0; d < 3; d++) {
          double dx = p[j].x[d] - p[i].x[d];
          if (box.periodic[d]) dx -= box.length[d] * std::round(dx / box.length[d]);  // minimum image
          r2 += dx * dx;
        }
        const double gap = std::sqrt(r2) - p[i].radius - p[j].radius;
        if (gap < 0) {
          pairs++;
          if (firstI < 0 || i < firstI || (i == firstI && j < firstJ)) { firstI = i; firstJ = j; firstGap = gap; }
        }
      }
    }
  }
  if (pairs == 0) return "";
  return "particles " + particleId(int(firstI)) + " and " + particleId(int(firstJ)) + " overlap: centres " +
         point(p[firstI].x) + " and " + point(p[firstJ].x) + ", radii " + number(p[firstI].radius) + " and " +
         number(p[firstJ].radius) + ", surface gap " + number(firstGap) +
         (pairs > 1 ? " (" + std::to_string(pairs) + " overlapping pairs in all)" : std::string());
}

std::string deepOverlapProblem(long tagI, long tagJ, double gap, double depth, long long step)
{
  const double allowed = coupler::contactOverlapTolerance;
  if (!(depth > allowed)) return "";
  char text[500];
  std::snprintf(text, sizeof text,
                "particles %ld and %ld overlap by %g m (%g of the smaller radius) at step %lld, more than the %g the "
                "fluid accepts: the contact springs did not hold them (a time step too large for this packing, or "
                "springs too soft for its loads: docs/benchmarks.md, 'Stability map', docs/contact.md, 'A recipe')",
                tagI, tagJ, -gap, depth, step, allowed);
  return text;
}

std::string periodicBalanceProblem(const std::vector<GatheredParticle> &particles, const ParticleBox &box,
                                   const double gradP0[3], double rhoFluid, const double gravity[3], long long step)
{
  // Otherwise the mean flow grows without bound (2e12 m/s within the first step of a force-free sphere
  // under gradP0 = 0.01 Pa/m). Only under an imposed gradient: the unit tests' stand-in fluids drive free
  // particles in periodic boxes by forces alone (a real fluid's mean flow would then grow too; docs/errors.md).
  const double pi = 3.14159265358979323846;
  if (gradP0[0] == 0 && gradP0[1] == 0 && gradP0[2] == 0) return "";
  const double volume = box.length[0] * box.length[1] * box.length[2];
  double sum[3] = {0, 0, 0}, scale = 0;
  for (const GatheredParticle &q : particles) {
    const double buoyantMass = q.mass - rhoFluid * 4.0 / 3.0 * pi * q.radius * q.radius * q.radius;
    for (int d = 0; d < 3; d++) {
      const double load = q.f[d] + buoyantMass * gravity[d];
      sum[d] += load;
      scale += std::fabs(load);
    }
  }
  double imposed[3], mismatch = 0;
  for (int d = 0; d < 3; d++) {
    imposed[d] = volume * gradP0[d];
    scale += std::fabs(imposed[d]);
    mismatch = std::max(mismatch, std::fabs(sum[d] - imposed[d]));
  }
  if (mismatch <= 1e-6 * scale || scale == 0) return "";
  char text[800];
  std::snprintf(text, sizeof text,
                "in a box periodic in every direction the loads on the free particles (forces beside contacts, "
                "buoyant weights) sum to (%g %g %g) N but the fluid's imposed pressure gradient gradP0 = (%g %g %g) "
                "Pa/m needs V0 gradP0 = (%g %g %g) N (Eq. 43; V0 = %g m3) at step %lld: no steady Stokes flow exists. "
                "Set gradP0 in the fluid's constant/fdmProperties, give the particles that external force (fix "
                "addforce; move no fixes their places, not their velocities), or bound the flow with walls",
                sum[0], sum[1], sum[2], gradP0[0], gradP0[1], gradP0[2], imposed[0], imposed[1], imposed[2], volume,
                step);
  return text;
}

std::string couplingSetupProblem(bool newtonPair, const std::string &unitStyle, double dt)
{
  if (newtonPair) return "fix fdm/couple requires newton off";
  if (unitStyle != "si")
    return "fix fdm/couple requires units si (the fluid solver works in SI), not units " + unitStyle;
  if (!(dt > 0)) return "fix fdm/couple requires a positive timestep";
  return std::string();
}

std::string otherFixProblem(const std::string &style, const std::string &id, bool integratesMotion)
{
  if (style == "fdm/couple") return "fix fdm/couple is defined twice: one coupled fluid, one fix";
  if (integratesMotion)
    return "fix fdm/couple moves the particles itself (it replaces nve/sphere): remove fix " + id + " (" + style + ")";
  if (style == "gravity")
    return "fix " + id + " (gravity) adds the full weight m g without buoyancy: use the gravity keyword of fix "
           "fdm/couple, which adds (rho_p - rho_f)/rho_p m g (Eq. 32)";
  return std::string();
}

}  // namespace fdm
