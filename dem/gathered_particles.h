/* What rank 0 holds of the particles and the box at each step of fix fdm/couple: every particle,
   gathered from the ranks and stored by tag (index tag - 1), and the box they are in. The units of the
   particle side (configuration checks, Eq. (31)'s adapter, the Step message) take these, not LIGGGHTS. */

#ifndef FDM_GATHERED_PARTICLES_H
#define FDM_GATHERED_PARTICLES_H

#include <string>
#include <vector>

namespace fdm {

struct GatheredParticle {
  double x[3], radius, v[3], omega[3], f[3], torque[3], mass, density;
  double contactStress[6];  // S^c of Eq. (52), when stresslets are asked for
};

struct ParticleBox {
  double lo[3], hi[3];
  double length[3];         // hi - lo, as LIGGGHTS holds it (domain->prd)
  bool periodic[3];
};

// The particles of the ranks' records concatenated on rank 0 ([tag, x, radius, v, omega, f, torque, mass,
// density, and with withStress the contact stresslet] per particle, `width` values each), by tag 1..n into
// particles. Returns the first problem (an ID out of range or twice; a particle missing: LIGGGHTS lost it,
// atomsLeft are left), or an empty string.
std::string particlesByTag(const std::vector<double> &records, int width, bool withStress, int n,
                           long long atomsLeft, std::vector<GatheredParticle> &particles);

}  // namespace fdm

#endif
