// The position update between two steps and its history (move_plan.h).
#include "move_plan.h"

#include <cmath>
#include <cstdio>

namespace fdm {

motion::Statistics MovePlan::plan(const std::vector<GatheredParticle> &particles, const ParticleBox &box,
                                  const std::vector<double> &u, const std::vector<int> &closePairs,
                                  const std::vector<motion::Wall> &walls, double dt, double contactGap)
{
  const int n = int(particles.size());
  motion::Configuration c;
  c.n = n;
  c.x.resize(size_t(3) * n);
  c.radius.resize(n);
  for (int p = 0; p < n; p++) {
    for (int k = 0; k < 3; k++) c.x[size_t(3) * p + k] = particles[p].x[k];
    c.radius[p] = particles[p].radius;
  }
  c.u = u;
  if (planned && haveVelocities && positions.size() == c.x.size()) {
    c.xPrevious = positions;
    c.uPrevious = current;
  }
  for (int d = 0; d < 3; d++) c.period[d] = box.periodic[d] ? box.length[d] : 0.0;
  motion::Options options = options_;
  options.contactGap = contactGap;
  const motion::Statistics stats = motion::displacementRates(c, closePairs, walls, dt, options, rates);
  positions = c.x;
  planned = true;
  return stats;
}

bool MovePlan::continuesFrom(const std::vector<GatheredParticle> &particles,
                             const std::function<void(double *)> &minimumImage) const
{
  for (size_t p = 0; p < particles.size(); p++) {
    const double *x = particles[p].x;
    double d[3];
    for (int k = 0; k < 3; k++) d[k] = x[k] - positions[3 * p + k];
    minimumImage(d);
    if (std::fabs(d[0]) + std::fabs(d[1]) + std::fabs(d[2]) >
        1e-12 * (1.0 + std::fabs(x[0]) + std::fabs(x[1]) + std::fabs(x[2])))
      return false;
  }
  return true;
}

void MovePlan::forget()
{
  planned = false;
  haveVelocities = false;
  previous.clear();
  positions.clear();
}

bool MovePlan::multistep(int particles) const
{
  return options_.adamsBashforth && planned && haveVelocities && positions.size() == size_t(3) * particles;
}

void MovePlan::springHistory(bool multistep, bool chordTerms, int n, double dt,
                             ParticleVelocitySystem::Springs &springs) const
{
  const bool chord = chordTerms && haveVelocities && current.size() == size_t(6) * n;
  if (multistep) springs.gamma = 1.0 / 3.0;
  if (chord) springs.dt = dt;
  if (multistep || chord) springs.previous = current;
}

void MovePlan::solved(const std::vector<double> &u)
{
  // the velocities of the step now ending are the "previous" ones of the next position update
  if (haveVelocities) previous = current;
  current = u;
  haveVelocities = true;
}

std::string MovePlan::fallbackWarning(long long step, const motion::Statistics &stats)
{
  char text[400];
  std::snprintf(text, sizeof text, "fdm/couple: step %lld: the log-gap targets of %ld pairs and %ld wall gaps "
                "contradict each other (a gap still %.2g of its target off after %d sweeps): such steps move the "
                "particles straight, keeping every gap from closing below min(target, present gap) (docs/dem.md, "
                "'Position update'; counted in the timing line)",
                step, stats.pairGaps, stats.wallGaps, stats.worst, stats.sweeps);
  return text;
}

}  // namespace fdm
