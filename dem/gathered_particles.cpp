// The particles gathered on rank 0 (gathered_particles.h).
#include "gathered_particles.h"

#include "message_text.h"

#include <cmath>

namespace fdm {

std::string particlesByTag(const std::vector<double> &records, int width, bool withStress, int n,
                           long long atomsLeft, std::vector<GatheredParticle> &particles)
{
  particles.assign(size_t(n), GatheredParticle());
  std::vector<char> seen(size_t(n), 0);
  for (size_t k = 0; k < records.size(); k += width) {
    const long tag = std::lround(records[k]);
    if (tag < 1 || tag > n || seen[tag - 1])
      return "particle ID " + std::to_string(tag) + " is out of 1.." + std::to_string(n) + " or twice in the system";
    seen[tag - 1] = 1;
    GatheredParticle &p = particles[tag - 1];
    const double *b = &records[k + 1];
    for (int d = 0; d < 3; d++) p.x[d] = *b++;
    p.radius = *b++;
    for (int d = 0; d < 3; d++) p.v[d] = *b++;
    for (int d = 0; d < 3; d++) p.omega[d] = *b++;
    for (int d = 0; d < 3; d++) p.f[d] = *b++;
    for (int d = 0; d < 3; d++) p.torque[d] = *b++;
    p.mass = *b++;
    p.density = *b++;
    for (int c = 0; c < 6; c++) p.contactStress[c] = withStress ? *b++ : 0.0;
  }
  for (int t = 0; t < n; t++)
    if (!seen[t])
      return "particle " + text::particleId(t) + " is missing: LIGGGHTS lost it (was it put or moved outside a "
             "non-periodic face of the box? " + std::to_string(atomsLeft) + " atoms left of " + std::to_string(n) + ")";
  return "";
}

}  // namespace fdm
