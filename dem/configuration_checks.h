/* Checks of the particles' configuration that fix fdm/couple makes on rank 0, as functions of the
   particles and the box (no LIGGGHTS). Each returns an empty string when all is well, else the first
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

// In a box periodic in every direction a steady Stokes flow exists only if the loads on the free
// particles (the forces LIGGGHTS holds plus the buoyant weights of Eq. 31) sum to V0 gradP0 (Eq. 43);
// checked only under an imposed gradient (gradP0 != 0).
std::string periodicBalanceProblem(const std::vector<GatheredParticle> &particles, const ParticleBox &box,
                                   const double gradP0[3], double rhoFluid, const double gravity[3], long long step);

}  // namespace fdm

#endif
