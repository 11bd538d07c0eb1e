/* One time step's exchange with the fluid solver, seen from the particles (paper 4.3, steps 3-7;
   the protocol: docs/coupling.md): send the Step (positions x_n and the last solved velocities U_n),
   receive the step's Volumes (Eq. 31's rigid-body blocks, once per step, before the first Integrals),
   then answer every inner iteration's Integrals with the solution of Eq. (31) until the fluid sends
   StepDone. What to do with each message is the caller's (the handlers); this unit checks that each
   message is of the type and step expected and keeps the time spent waiting for the fluid apart from
   the time spent in the handlers. Rank 0; no LIGGGHTS. Problems are thrown (std::runtime_error,
   coupler::CouplerError), as are the handlers' own. */

#ifndef FDM_FLUID_EXCHANGE_H
#define FDM_FLUID_EXCHANGE_H

#include "fdm/coupler.h"
#include "gathered_particles.h"

#include <functional>
#include <vector>

namespace fdm {

class FluidExchange {
 public:
  struct Handlers {
    std::function<void(const coupler::Volumes &)> volumes;
    // the velocities of Eq. (31) for one inner iteration: 6 per particle (U, Omega) by tag
    std::function<const std::vector<double> &(const coupler::Integrals &)> integrals;
    std::function<void(const coupler::StepDone &)> stepDone;
  };
  // Wall-clock seconds of the step: exchange (sending, and waiting for the fluid, whose solves it
  // includes) and the handlers' (the particle solve).
  struct Seconds {
    double exchange = 0, handlers = 0;
  };

  FluidExchange(coupler::Transport &connection, int particles, bool stresslets)
      : connection_(connection), particles_(particles), stresslets_(stresslets) {}

  // The exchange of one step, whose Step message is `step`.
  Seconds run(const coupler::Step &step, const Handlers &handlers);

  // The Step message of particle step `step`: the positions in the box (LIGGGHTS wraps periodic
  // coordinates only when it re-neighbours), the last solved velocities U_n (6 per particle by tag;
  // empty before the first solve: then the particles' own v, omega), the fluid's time step (the
  // particle steps it spans, fluid_every) and whether both codes write a checkpoint at its end.
  static coupler::Step makeStep(const std::vector<GatheredParticle> &particles, const ParticleBox &box,
                                long long step, double fluidDt, long long lastStep, bool checkpoint,
                                const std::vector<double> &solvedVelocities);

 private:
  coupler::Message receive(bool volumes, long long step);

  coupler::Transport &connection_;
  int particles_;
  bool stresslets_;
};

}  // namespace fdm

#endif
