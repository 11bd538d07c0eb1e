// The keywords of fix fdm/couple (couple_options.h).
#include "couple_options.h"

#include <cmath>

namespace fdm {

namespace {

const char *owner = "fix fdm/couple";

// between 0 and 1, both excluded: the relative tolerances
bool fraction(double x) { return x > 0 && x < 1; }

}  // namespace

ParticleVelocitySystem::Settings CoupleOptions::systemSettings() const
{
  ParticleVelocitySystem::Settings s;
  s.solver = solver;
  s.tolerance = tolerance;
  s.coulombTolerance = coulombTolerance;
  s.coulombConsistent = coulombConsistent;
  for (int d = 0; d < 3; d++) s.gravity[d] = gravity[d];
  s.stresslets = stresslets;
  return s;
}

motion::Options CoupleOptions::moveOptions() const
{
  motion::Options m;
  m.adamsBashforth = adamsBashforth;
  m.gapCorrection = gapUpdate;
  m.holdContactGaps = holdContactGaps;
  return m;
}

LAMMPS_NS::CouplingSession::Request CoupleOptions::sessionRequest() const
{
  LAMMPS_NS::CouplingSession::Request r;
  r.options = connection;
  r.viscosity = viscosity;
  r.meshSize = meshSize;
  r.fluidDensity = fluidDensity;
  r.stresslets = stresslets;
  r.checkpointEvery = checkpointEvery;
  return r;
}

CoupleOptions parseCoupleOptions(const std::vector<std::string> &args)
{
  using Solver = ParticleVelocitySystem::Solver;
  CoupleOptions o;
  coupler::Options &c = o.connection;
  c.name = "fluid solver fdmFoam";
  long long port = c.port;
  KeywordTable table(owner);
  // the connection to the fluid solver (coupler.h, Options)
  table.choice<std::string>("transport", {{"socket", "socket"}, {"file", "file"}, {"none", "none"}}, c.transport)
      .text("host", c.host)
      .integer("port", port)
      .text("portfile", c.portFile)
      .text("directory", c.directory)
      .number("connect_timeout", c.connectTimeout)
      .number("timeout", c.receiveTimeout)
      .text("record", c.recordFile);
  // transport none: the fluid's values
  table.number("viscosity", o.viscosity).number("mesh", o.meshSize).number("fluid_density", o.fluidDensity)
      .number("background_shear", o.backgroundShear,
              {[](double g) { return std::isfinite(g); }, "background_shear needs a finite shear rate [1/s]"});
  // the particles: loads, position update, Eq. (31)
  table.numbers("gravity", 3, o.gravity)
      .yesNo("move", o.move)
      .choice<bool>("integrator", {{"euler", false}, {"ab2", true}}, o.adamsBashforth)
      .choice<bool>("gap_update", {{"log", true}, {"none", false}}, o.gapUpdate)
      .choice<bool>("contact_gaps", {{"hold", true}, {"free", false}}, o.holdContactGaps)
      .choice<Solver>("solver", {{"cholmod", ParticleVelocitySystem::cholmod}, {"ldlt", ParticleVelocitySystem::ldlt},
                                 {"cg", ParticleVelocitySystem::cg}}, o.solver)
      .number("tolerance", o.tolerance, {fraction, "tolerance (relative residual of Eq. 31) must be in (0, 1)"})
      .number("coulomb_tolerance", o.coulombTolerance,
              {fraction, "coulomb_tolerance (of the sliding contacts' forces) must be in (0, 1)"})
      .choice<bool>("coulomb_solve", {{"frozen", false}, {"consistent", true}}, o.coulombConsistent)
      .yesNo("contact_chord", o.contactChord);
  // outputs, checkpoints, particle steps between fluid steps
  table.yesNo("stresslets", o.stresslets)
      .text("walls", o.wallFile, {[](const std::string &f) { return !f.empty(); }, "walls needs a file name"})
      .integer("checkpoint", o.checkpointEvery,
               {[](long long n) { return n >= 0; }, "checkpoint N needs N >= 0 steps (0: none)"})
      .integer("fluid_every", o.fluidEvery,
               {[](long long k) { return k >= 1; }, "fluid_every K needs K >= 1 particle steps per fluid step"})
      .choice<bool>("held_drag", {{"constant", false}, {"extrapolated", true}}, o.heldExtrapolated);
  table.parse(args, "see docs/dem.md");
  c.port = int(port);

  auto fail = [](const std::string &sentence) { throw KeywordError(std::string(owner) + ": " + sentence); };
  if (!o.hasFluid() && (!(o.viscosity > 0) || !(o.meshSize > 0) || !(o.fluidDensity > 0)))
    fail("transport none (DEM only, no fluid) needs viscosity eta [Pa s] and mesh Delta [m] (the sub-grid model's "
         "mesh size), both positive; fluid_density (default 1000 kg/m3) too");
  if (o.hasFluid() && o.backgroundShear != 0)
    fail("background_shear goes with transport none (with the fluid solver the walls drive the flow)");
  if (!o.hasFluid() && o.fluidEvery > 1)
    fail("fluid_every goes with the fluid solver (transport none has no fluid step)");
  if (!o.hasFluid() && o.stresslets && o.backgroundShear == 0)
    fail("stresslets need the fluid solver, or, with transport none, a background_shear (the isolated sphere's "
         "stresslet in it)");
  if (c.transport == "socket" && (port <= 0 || port > 65535) && c.portFile.empty())
    fail("give the fluid solver's port (port P) or its port file (portfile F)");
  if (c.transport == "file" && c.directory.empty()) fail("transport file needs directory D");
  if (!(c.connectTimeout > 0) || !(c.receiveTimeout > 0))
    fail("connect_timeout and timeout must be positive (seconds)");
  return o;
}

}  // namespace fdm
