/* What fix fdm/couple counts over a run (wall-clock seconds of the three parts of the particle side's
   work, and the same finer by part of the particle step (particle_step_profile.h), Eq. (31)'s solves,
   the position update's log-gap targets) and the timing line it prints at the end of each run
   (docs/dem.md, "Outputs"). No LIGGGHTS. */

#ifndef FDM_COUPLING_TIMING_H
#define FDM_COUPLING_TIMING_H

#include "particle_step_profile.h"
#include "position_update.h"

#include <algorithm>
#include <string>

namespace fdm {

struct CouplingTiming {
  double solve = 0, exchange = 0, gatherScatter = 0;
  ParticleStepProfile parts;            // the same seconds finer, by part of the particle step
  long steps = 0, fluidSteps = 0, solves = 0, solverIterations = 0, solverIterationsMax = 0;
  long gapTargets = 0, gapLimited = 0;  // log-gap targets of the position update, and those limited
  long gapHeld = 0;                     // contact (or closed) gaps held at their straight-step value
  long gapFallbacks = 0;                // steps where the targets contradicted each other (the fallback:
                                        // straight, every gap kept above its bound)
  int gapSweepsMax = 0;
  double gapBoundWorst = 0;             // largest relative bound violation the fallback left
  long gapCompromisesBounded = 0;       // steps whose compromise (no fallback) closed a gap below its bound
  double gapCompromiseMissMax = 0;      // and by how much, at most (relative to the gap)
  long contactSlides = 0;               // contacts that began to slide within their step (Coulomb's law at its end)
  long slidingAtEnd = 0;                // contacts that slide at the end of their step
  long slidingAlongFriction = 0;        // and of them those that slip along their friction force (contact.md 2c)
  long stuckAgain = 0;                  // sliding contacts that stuck again within their step (coulomb_solve consistent)
  long offCoulomb = 0;                  // contacts whose force at the end of their step is off Coulomb's law by > 1e-3
  double offCoulombWorst = 0;           // and the largest such relative difference
  long factorisations = 0;              // of Eq. (31) by the direct solvers: per step, and when the downdates grow too large
  long downdates = 0;                   // contacts that began to slide handled without a factorisation (Woodbury)
  long backSubstitutions = 0;           // of Eq. (31): one per Coulomb round of each solve
  long coulombRoundsMax = 0;            // the most rounds of one solve (100 stops the rounds where they stand)
  double chordForceMax = 0;             // the largest chord term of a pair spring (Eq. C5 of docs/contact.md) [N]

  // one step's position update
  void countMove(const motion::Statistics &stats)
  {
    gapTargets += stats.pairGaps + stats.wallGaps;
    gapLimited += stats.limited;
    gapHeld += stats.heldGaps;
    gapFallbacks += stats.fallback ? 1 : 0;
    gapBoundWorst = std::max(gapBoundWorst, stats.worstBound);
    gapCompromisesBounded += stats.compromiseMiss > 0 ? 1 : 0;
    gapCompromiseMissMax = std::max(gapCompromiseMissMax, stats.compromiseMiss);
    gapSweepsMax = std::max(gapSweepsMax, stats.sweeps);
  }
};

// How the run was set up, for the timing line.
struct TimingContext {
  const char *solverName;
  bool adamsBashforth, gapUpdate, chordTerms;   // chordTerms: the pair springs' chord terms are on
  long pairBlocks, wallBlocks, contacts;         // of the last step
  long notConverged;                             // steps the fluid reported not converged
  long long fluidEvery;
  bool heldExtrapolated;
};

// "fdm/couple timing <what> (<runs> runs, <steps> steps, <wall> s): ..." with a newline.
std::string timingLine(const char *what, const CouplingTiming &t, double wall, int runs, const TimingContext &c);

}  // namespace fdm

#endif
