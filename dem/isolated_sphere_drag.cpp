// The isolated sphere's drag in Eq. (31) (isolated_sphere_drag.h).
#include "isolated_sphere_drag.h"

#include <algorithm>

namespace fdm {

namespace {
const double pi = 3.14159265358979323846;
}

coupler::Volumes isolatedSphereVolumes(const std::vector<GatheredParticle> &particles, long long step,
                                       double viscosity, double alphaLambda, double rhoFluid)
{
  const double eta = viscosity, alpha = alphaLambda, rho = rhoFluid;
  coupler::Volumes m;
  m.step = uint64_t(step);
  m.particles.resize(particles.size());
  for (size_t p = 0; p < particles.size(); p++) {
    const double a = particles[p].radius;
    m.particles[p].Vu = 6 * pi * eta * a * alpha / rho;
    m.particles[p].J[0] = m.particles[p].J[3] = m.particles[p].J[5] = 8 * pi * eta * a * a * a * alpha / rho;
  }
  return m;
}

void backgroundShearDrag(const std::vector<GatheredParticle> &particles, double yCentre, double viscosity,
                         double shearRate, coupler::Integrals &integrals, std::vector<double> *fluidStress)
{
  // Frame-invariant sub-grid lubrication and the springs act on the velocities as with the fluid: the
  // particle side of a sheared suspension without the fluid solver (docs/benchmarks.md, "Without the fluid").
  const double eta = viscosity, G = shearRate;
  for (size_t p = 0; p < particles.size(); p++) {
    const double a = particles[p].radius;
    integrals.particles[p].F[0] = 6 * pi * eta * a * G * (particles[p].x[1] - yCentre);
    integrals.particles[p].T[2] = -8 * pi * eta * a * a * a * 0.5 * G;
    if (fluidStress) {   // order xx xy xz yy yz zz, then the trace
      double *s = &(*fluidStress)[7 * p];
      std::fill(s, s + 7, 0.0);
      s[1] = (10.0 / 3.0) * pi * eta * a * a * a * G;
    }
  }
}

}  // namespace fdm
