/* Checks of the particles' configuration that fix fdm/couple makes on rank 0, as functions of the
   particles and the box, and of the input's set-up (no LIGGGHTS). Each returns an empty string when all is well, else the first
   problem, naming the particle and its numbers: a particle through a wall, or two overlapping, would
   give a wrong flow silently, and an unbalanced periodic box a flow that grows without bound. */

#ifndef FDM_CONFIGURATION_CHECKS_H
#define FDM_CONFIGURATION_CHECKS_H

#include "gathered_particles.h"

#include <string>
#include <vector>

namespace fdm {

// Positive radius, density and mass; centre in the box; clear of its own periodic image; clear of the
// walls (non-periodic faces). fromInput: a configuration the input gave, which must also be free of
// overlaps and touch no wall; otherwise (a continuing or resumed run) a sphere may be pressed into a
// wall by its contact spring as deep as both codes accept (coupler::contactOverlapTolerance radii).
std::string configurationProblem(const std::vector<GatheredParticle> &particles, const ParticleBox &box,
                                 bool fromInput);

// The overlapping pair of lowest indices (minimum image across periodic faces) and how many overlap.
// Binned, O(N log N).
std::string firstOverlap(const std::vector<GatheredParticle> &particles, const ParticleBox &box);

// During a run: two spheres overlapping by more than the fluid accepts of a sphere pressed into a wall
// (coupler::contactOverlapTolerance of the smaller radius; depth: the overlap in those units, gap < 0)
// are beyond what the contact springs allow for any load they were chosen for: the run is no longer a
// suspension of rigid spheres (measured: 0.08-0.21 a1 in dense scenes at large steps, docs/benchmarks.md
// "Stability map"), so it stops rather than record it.
std::string deepOverlapProblem(long tagI, long tagJ, double gap, double depth, long long step);

// The deepest overlap of two spheres a rank's pair style saw in a step (depth in units of the smaller
// radius, gap, tags), gathered by step_collectives.h's deepestOverlap.
struct Overlap {
  double depth = -1e300, gap = 0;
  long tagI = 0, tagJ = 0;
};

// In a box periodic in every direction a steady Stokes flow exists only if the loads on the free
// particles (the forces LIGGGHTS holds plus the buoyant weights of Eq. 31) sum to V0 gradP0 (Eq. 43);
// checked only under an imposed gradient (gradP0 != 0).
std::string periodicBalanceProblem(const std::vector<GatheredParticle> &particles, const ParticleBox &box,
                                   const double gradP0[3], double rhoFluid, const double gravity[3], long long step);

// The LIGGGHTS set-up fix fdm/couple needs (checked in its init()): newton off, units si (the fluid solver
// works in SI), a positive time step.
std::string couplingSetupProblem(bool newtonPair, const std::string &unitStyle, double dt);

// Another fix of the input beside fix fdm/couple (style, ID, whether it integrates the motion): a second
// fdm/couple, an integrator (fdm/couple moves the particles itself) and fix gravity (the full weight
// without buoyancy) are refused.
std::string otherFixProblem(const std::string &style, const std::string &id, bool integratesMotion);

}  // namespace fdm

#endif
