/* Eq. (31) within a coupled time step, on rank 0: the adapter between the particles fix fdm/couple
   gathers (and the fluid's messages) and the linear system of particle_velocity_system.h, and the
   per-particle results the fix outputs (by tag):

     solution     6: (U, Omega) of the last solve, the warm start of the next
     hydro        6: F^FDM, T^FDM, the fluid's force of the last StepDone (or its stand-in below)
     fluidStress  7: S^FDM (6), s^FDM of the last StepDone (Eq. 12)
     subgrid      6: F^SG, T^SG (Eq. 21 and D.6)
     springs      6: the implicit part of the contact forces (Eq. C2 of docs/contact.md)
     stress      20: S^h (6), s^h = S^FDM + S^SG, s^FDM + s^SG (Eq. 13), S^c (6, Eq. 52), S^SG (6), s^SG

   A step with the fluid: assemble(), setVolumes() with the fluid's Volumes, solve() every inner
   iteration, storeStepDone() and finishStep(). Without a fluid solve the fluid's part is an isolated
   sphere's drag (isolated_sphere_drag.h): noFluidStep() (transport none) and heldStep() (the steps
   between fluid steps, held_drag.h). Problems are thrown as std::runtime_error naming the particle
   and, for the fluid's values, the step and inner iteration. No LIGGGHTS. */

#ifndef FDM_COUPLED_VELOCITY_SOLVE_H
#define FDM_COUPLED_VELOCITY_SOLVE_H

#include "coupling_timing.h"
#include "fdm/coupler.h"
#include "fluid_exchange.h"
#include "gathered_particles.h"
#include "held_drag.h"
#include "particle_velocity_system.h"

#include <memory>
#include <vector>

namespace fdm {

class CoupledVelocitySolve {
 public:
  struct Results {
    std::vector<double> solution, hydro, fluidStress, subgrid, springs, stress;
    // fix fdm/couple's per-atom columns: F^FDM, T^FDM, F^SG, T^SG (12), and with stresslets the 20 of stress
    static int perAtomColumns(bool stresslets) { return stresslets ? 32 : 12; }
    // Those columns of the particle of index tag - 1 (of n) into row; zeros for a particle the results do
    // not hold (an index out of 0..n-1, or results not sized for n yet)
    void perAtomRow(long index, int n, bool stresslets, double *row) const;
  };

  // settings: of Eq. (31) but the fluid's values; counts: where the solves are counted, and their
  // seconds by part (assembly, factorisation, solves, results: CouplingTiming::parts)
  CoupledVelocitySolve(const ParticleVelocitySystem::Settings &settings, CouplingTiming &counts);
  // What the fluid said at the handshake (or transport none's keywords).
  void setFluid(double alphaLambda, double rhoFluid, double viscosity, double meshSize)
  {
    alphaLambda_ = alphaLambda;
    rhoFluid_ = rhoFluid;
    viscosity_ = viscosity;
    meshSize_ = meshSize;
  }
  // n particles: the results sized (zero) for them, unless they already are
  void resize(int n);

  // Once per step: the loads on the particles (contacts, external: F^c + F^ext of Eq. 32), the
  // sub-grid blocks and the implicit springs gathered from every rank.
  void assemble(const std::vector<GatheredParticle> &particles, std::vector<double> pairBlocks,
                std::vector<double> wallBlocks, ParticleVelocitySystem::Springs springs);
  // Once per step: the rigid-body blocks (and the factorisation).
  void setVolumes(const coupler::Volumes &volumes);
  // Every inner iteration: the velocities for the fluid's integrals (Eq. 32's fluid part).
  const std::vector<double> &solve(const coupler::Integrals &integrals);
  void storeStepDone(const coupler::StepDone &done);
  // After the last solve: sub-grid forces, springs, and the stresslets when asked for.
  void finishStep(const std::vector<GatheredParticle> &particles);
  // The above as the handlers of a step's exchange with the fluid (fluid_exchange.h).
  FluidExchange::Handlers exchangeHandlers(const std::vector<GatheredParticle> &particles);

  // transport none: a fluid at rest, or the simple shear `shearRate` about y = yCentre.
  void noFluidStep(const std::vector<GatheredParticle> &particles, long long step, double yCentre, double shearRate);
  // A step between fluid steps: the drag toward the target of held (from U, F^FDM of the last fluid
  // step, lastU). The fluid's stresslets stay those of the last fluid step.
  void heldStep(const std::vector<GatheredParticle> &particles, long long step, long long lastFluidStep,
                const std::vector<double> &lastU, HeldDrag &held);

  Results &results() { return results_; }
  const Results &results() const { return results_; }
  ParticleVelocitySystem *system() { return system_.get(); }
  // 6 per implicit wall spring block of the last step: its force on the particle (for the wall loads)
  const std::vector<double> &springWallForces() const { return springWallForces_; }
  // Of the last step: the fluid's inner iterations and lambda residual (0: a held step, 1: no fluid),
  // the most linear-solver iterations of a solve; of the run: the steps the fluid did not converge.
  int lastIterations = 0;
  double lastResidual = 0;
  long solverIterations = 0;
  long notConverged = 0;

 private:
  void setDrag(const std::vector<GatheredParticle> &particles, long long step);
  void finishStepUntimed(const std::vector<GatheredParticle> &particles);  // finishStep's work
  // the fluid's force of a solve against the drag D: the drag target minus D u
  void dragForces(const coupler::Integrals &target);

  ParticleVelocitySystem::Settings settings_;
  CouplingTiming &counts_;
  double alphaLambda_ = 0, rhoFluid_ = 0, viscosity_ = 0, meshSize_ = 0;
  std::unique_ptr<ParticleVelocitySystem> system_;
  Results results_;
  std::vector<double> springWallForces_;
  int n_ = 0;
  long factorisationsCounted_ = 0, downdatesCounted_ = 0, backSubstitutionsCounted_ = 0;
};

}  // namespace fdm

#endif
