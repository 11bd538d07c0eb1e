// Where the particle side's wall time goes (particle_step_profile.h).
#include "particle_step_profile.h"

#include <algorithm>
#include <cstdio>

namespace fdm {

ParticleStepProfile::Clock::time_point ParticleStepProfile::lap(Part part, Clock::time_point since)
{
  const Clock::time_point t = Clock::now();
  seconds_[part] += std::chrono::duration<double>(t - since).count();
  return t;
}

double ParticleStepProfile::timed() const
{
  double sum = 0;
  for (double s : seconds_) sum += s;
  return sum;
}

const char *ParticleStepProfile::name(Part part)
{
  switch (part) {
    case subgridBlocks: return "sub-grid blocks (pair style)";
    case systemAssembly: return "Eq. 31 assembly";
    case systemFactorisation: return "Eq. 31 rigid blocks + factorisation";
    case systemSolves: return "Eq. 31 solves";
    case systemResults: return "Eq. 31 forces after the solve";
    case contact: return "contact forces + spring blocks";
    case positionUpdate: return "position update";
    case fluidExchange: return "exchange incl. fluid (waiting)";
    case gatherScatter: return "gather/scatter";
    case timedParts: break;
  }
  return "?";
}

void ParticleStepProfile::add(const ParticleStepProfile &other)
{
  for (int p = 0; p < timedParts; p++) seconds_[p] += other.seconds_[p];
  addLiggghts(other.liggghts_);
}

void ParticleStepProfile::addLiggghts(const LiggghtsTimers &timers)
{
  // -1: not given (a run without LIGGGHTS's timers adds nothing to the known ones)
  auto sum = [](double mine, double theirs) { return theirs < 0 ? mine : std::max(mine, 0.0) + theirs; };
  liggghts_.neighbour = sum(liggghts_.neighbour, timers.neighbour);
  liggghts_.communication = sum(liggghts_.communication, timers.communication);
  liggghts_.output = sum(liggghts_.output, timers.output);
}

std::string ParticleStepProfile::report(const std::string &what, const std::string &whose, double wall, long steps,
                                        long fluidSteps) const
{
  char line[300];
  std::snprintf(line, sizeof line,
                "fdm/couple particle step by part (%s; %s; %ld steps, %ld with the fluid, %.4g s):\n", what.c_str(),
                whose.c_str(), steps, fluidSteps, wall);
  std::string out = line;
  auto row = [&](const char *name, double seconds) {
    std::snprintf(line, sizeof line, "    %-34s %10.4g s %6.1f %% %10.3f ms/step\n", name, seconds,
                  wall > 0 ? 100 * seconds / wall : 0.0, steps > 0 ? 1e3 * seconds / steps : 0.0);
    out += line;
  };
  for (int p = 0; p < timedParts; p++) row(name(Part(p)), seconds_[p]);
  const double rest = std::max(0.0, wall - timed());
  row("rest of the step", rest);
  const LiggghtsTimers &l = liggghts_;
  if (l.neighbour >= 0 && l.communication >= 0 && l.output >= 0) {
    // LIGGGHTS's timers time stretches outside the parts (its loop between the fix's calls): they
    // split the rest; what they do not cover (LIGGGHTS's other work, the run's setup) is "other"
    row("  of which neighbour lists", l.neighbour);
    row("  of which communication", l.communication);
    row("  of which output", l.output);
    const double known = l.neighbour + l.communication + l.output;
    row("  of which other", std::max(0.0, rest - known));
  }
  return out;
}

}  // namespace fdm
