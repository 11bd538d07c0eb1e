/* Where the particle side's wall time goes, by part of the particle step, and the breakdown fix
   fdm/couple prints after every run and fdmDEM after the input (docs/dem.md, "Outputs"):

     sub-grid blocks        pair_style fdm/subgrid building R^SG of its pairs and wall gaps (collectBlocks)
     Eq. 31 assembly        the matrix R^SG + springs from the gathered records
     Eq. 31 factorisation   the rigid-body blocks from the fluid's volumes, and every factorisation: the
                            step's and those the Coulomb rounds fall back to (past the downdates' room)
     Eq. 31 solves          the back-substitutions (or CG) of every inner iteration, with their Coulomb rounds
                            and their downdates (the columns' solves)
     Eq. 31 results         after the last solve: sub-grid and spring forces, stresslets
     contact                the pair style's contact forces (compute) and the implicit spring blocks
     position update        the move (initial_integrate) and the plan of the next one
     exchange incl. fluid   sending to fdmFoam and waiting for it (its solves included)
     gather/scatter         the particles and the block records to rank 0, the results back
     rest of the step       the remainder of the wall time: LIGGGHTS's neighbour lists, communication and
                            output (from its own timers when given), and everything else

   Whole loops are timed (steady_clock), never a pair or a particle. The parts are one rank's (the
   adapter says which); the rest is what the wall time leaves after them, so the rows add up to it.
   No LIGGGHTS. */

#ifndef FDM_PARTICLE_STEP_PROFILE_H
#define FDM_PARTICLE_STEP_PROFILE_H

#include <algorithm>
#include <chrono>
#include <string>

namespace fdm {

class ParticleStepProfile {
 public:
  enum Part {
    subgridBlocks,
    systemAssembly,
    systemFactorisation,
    systemSolves,
    systemResults,
    contact,
    positionUpdate,
    fluidExchange,
    gatherScatter,
    timedParts   // the number of parts above
  };
  using Clock = std::chrono::steady_clock;

  // LIGGGHTS's own timers of the same stretch (Timer::array: neighbour lists, communication, output),
  // the known share of the rest; negative: not available
  struct LiggghtsTimers {
    double neighbour = -1, communication = -1, output = -1;
  };

  static Clock::time_point now() { return Clock::now(); }
  // adds the time since `since` to `part` and returns now, the start of whatever follows
  Clock::time_point lap(Part part, Clock::time_point since);
  void add(Part part, double seconds) { seconds_[part] += seconds; }
  // A stretch of `seconds` that began when timed() was timedBefore: what the parts timed within it do
  // not hold (never below 0) goes to `part`
  void addUntimed(Part part, double seconds, double timedBefore)
  {
    seconds_[part] += std::max(0.0, seconds - (timed() - timedBefore));
  }
  double seconds(Part part) const { return seconds_[part]; }
  double timed() const;                   // the sum of the parts
  static const char *name(Part part);

  // another run's parts added (the session's total)
  void add(const ParticleStepProfile &other);
  void addLiggghts(const LiggghtsTimers &timers);
  const LiggghtsTimers &liggghts() const { return liggghts_; }

  // The breakdown, a header and one line per row, each ending with a newline:
  //   "fdm/couple particle step by part (<what>; <whose>; <steps> steps, <fluid steps> with the fluid, <wall> s):"
  //   "    <part>  <seconds> s  <share of wall> %  <ms per step> ms/step"
  // then the rest of the step (wall minus the parts, never below 0) and, if LIGGGHTS's timers were
  // given, its split: neighbour lists, communication, output, other.
  std::string report(const std::string &what, const std::string &whose, double wall, long steps,
                     long fluidSteps) const;

 private:
  double seconds_[timedParts] = {};
  LiggghtsTimers liggghts_;
};

}  // namespace fdm

#endif
