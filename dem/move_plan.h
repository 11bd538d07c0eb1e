/* The position update of fix fdm/couple between two steps (position_update.h, paper 4.3 step 1) and the
   history it needs: U_n and U_{n-1} (by tag), the positions x_n it starts from and the displacement rates
   it planned (x_{n+1} = x_n + dt rate). Rank 0 plans at the end of a step, once U_n is solved; every rank
   holds the rates and velocities the fix broadcasts, and a checkpoint carries them all. No LIGGGHTS. */

#ifndef FDM_MOVE_PLAN_H
#define FDM_MOVE_PLAN_H

#include "gathered_particles.h"
#include "particle_velocity_system.h"
#include "position_update.h"

#include <functional>
#include <string>
#include <vector>

namespace fdm {

class MovePlan {
 public:
  explicit MovePlan(const motion::Options &options) : options_(options) {}
  bool adamsBashforth() const { return options_.adamsBashforth; }
  bool gapCorrection() const { return options_.gapCorrection; }

  // Rank 0, U_n (u) just solved at the positions x_n of the step (particles): the rates of the next
  // step. closePairs and walls: the gaps to integrate in log h; contactGap: h_r of the contact springs
  // (0 without contact). current still holds U_{n-1} here.
  motion::Statistics plan(const std::vector<GatheredParticle> &particles, const ParticleBox &box,
                          const std::vector<double> &u, const std::vector<int> &closePairs,
                          const std::vector<motion::Wall> &walls, double dt, double contactGap);
  // Rank 0: whether the particles are where the plan starts from (minimumImage: the box's, in place); if
  // the input has moved them since (set, displace_atoms, read_restart ...) the next step starts afresh.
  bool continuesFrom(const std::vector<GatheredParticle> &particles,
                     const std::function<void(double *)> &minimumImage) const;
  // Afresh: Euler from the current velocities, then Adams-Bashforth again.
  void forget();
  // Rank 0: whether the next step is a multistep one (Adams-Bashforth with a previous step), which the
  // implicit contact springs must know (docs/contact.md 2b).
  bool multistep(int particles) const;
  // The history the implicit contact springs take from the plan (docs/contact.md 2b): with multistep
  // (the next position update is Adams-Bashforth 2) U_n weighs gamma = 1/3; with chordTerms (contact_chord
  // yes) the pair springs' chord term (Eq. C5) is estimated from U_n over dt, if U_n is known for the n
  // particles. springs.previous is U_n when either needs it.
  void springHistory(bool multistep, bool chordTerms, int n, double dt,
                     ParticleVelocitySystem::Springs &springs) const;
  // Every rank, the step's velocities U_{n+1} broadcast: they become the current ones.
  void solved(const std::vector<double> &u);

  // Said once per run when a step's targets contradict each other (the fallback).
  static std::string fallbackWarning(long long step, const motion::Statistics &stats);

  bool planned = false, haveVelocities = false;
  std::vector<double> rates;       // 6N by tag: the planned displacement rates
  std::vector<double> positions;   // 3N by tag: x_n, where they start from (rank 0)
  std::vector<double> current, previous;  // 6N by tag: U_n, U_{n-1}

 private:
  motion::Options options_;
};

}  // namespace fdm

#endif
