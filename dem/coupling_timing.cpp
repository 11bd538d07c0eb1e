// The timing line of fix fdm/couple (coupling_timing.h).
#include "coupling_timing.h"

#include <cstdio>

namespace fdm {

std::string timingLine(const char *what, const CouplingTiming &t, double wall, int runs, const TimingContext &c)
{
  const double percent = wall > 0 ? 100.0 / wall : 0.0;
  std::string gapStats = " (gap_update none)";
  if (c.gapUpdate) {
    char g[400];
    std::snprintf(g, sizeof g, " with log gaps: %.3g gap targets and %.3g held contact gaps per step, at most %d "
                  "sweeps, %ld limited, %ld steps with contradictory targets (straight, gaps kept above their "
                  "bounds to %.2g), %ld steps whose compromise was pushed back to the bounds (by up to %.2g of a gap)",
                  t.steps ? double(t.gapTargets) / t.steps : 0.0, t.steps ? double(t.gapHeld) / t.steps : 0.0,
                  t.gapSweepsMax, t.gapLimited, t.gapFallbacks, t.gapBoundWorst, t.gapCompromisesBounded,
                  t.gapCompromiseMissMax);
    gapStats = g;
  }
  std::string chordStats;
  if (c.chordTerms) {
    char s[120];
    std::snprintf(s, sizeof s, ", pair springs' chord terms up to %.3g N", t.chordForceMax);
    chordStats = s;
  }
  const std::string notConverged = c.notConverged ? ", " + std::to_string(c.notConverged) + " steps not converged" : "";
  const std::string fluidEvery =
      c.fluidEvery > 1 ? "; fluid_every " + std::to_string(c.fluidEvery) + ": the fluid solved in " +
                             std::to_string(t.fluidSteps) + " of the steps" +
                             (c.heldExtrapolated ? ", the held drag extrapolated" : "")
                       : "";
  char coulomb[200];
  std::snprintf(coulomb, sizeof coulomb, ", %ld stuck again within their step, %ld off Coulomb's law by more than 1e-3 "
                "(worst %.2g)", t.stuckAgain, t.offCoulomb, t.offCoulombWorst);
  char line[1700];
  std::snprintf(line, sizeof line,
                "fdm/couple timing %s (%d run%s, %ld steps, %.4g s): particle solve %.4g s (%.1f %%), "
                "exchange incl. fluid %.4g s (%.1f %%), gather/scatter %.4g s (%.1f %%); Eq. 31: %ld solves, "
                "%s iterations mean %.1f max %ld, %ld factorisations, %ld low-rank downdates, %ld back-substitutions "
                "(Coulomb rounds, at most %ld in a solve); last step %ld sub-grid pair blocks, %ld wall blocks, "
                "%ld contacts; %ld contacts began to slide within their step, %ld slid at its end (%ld of them along "
                "their friction force)%s%s; position update %s%s%s%s\n",
                what, runs, runs == 1 ? "" : "s", t.steps, wall, t.solve, t.solve * percent, t.exchange,
                t.exchange * percent, t.gatherScatter, t.gatherScatter * percent, t.solves, c.solverName,
                t.solves ? double(t.solverIterations) / t.solves : 0.0, t.solverIterationsMax, t.factorisations,
                t.downdates, t.backSubstitutions, t.coulombRoundsMax, c.pairBlocks, c.wallBlocks, c.contacts,
                t.contactSlides, t.slidingAtEnd, t.slidingAlongFriction, coulomb, chordStats.c_str(),
                c.adamsBashforth ? "ab2" : "euler", gapStats.c_str(), notConverged.c_str(), fluidEvery.c_str());
  return line;
}

}  // namespace fdm
