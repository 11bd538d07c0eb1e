// Eq. (31) within a coupled time step (coupled_velocity_solve.h).
#include "coupled_velocity_solve.h"

#include "isolated_sphere_drag.h"
#include "message_text.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace fdm {

namespace cpl = coupler;
using System = ParticleVelocitySystem;

namespace {

// What the system cannot know: the mesh size, and when (iteration 0: the step's Volumes).
std::runtime_error problem(const System::Error &e, double meshSize, uint64_t step, uint32_t iteration)
{
  if (e.kind == System::Error::noVolume)
    return std::runtime_error(std::string(e.what()) + ": is it smaller than a mesh cell (" + text::number(meshSize) +
                              ")?");
  if (e.kind == System::Error::fluidValue)
    return std::runtime_error(std::string(e.what()) + " at step " + std::to_string(step) +
                              (iteration > 0 ? ", inner iteration " + std::to_string(iteration) : std::string()));
  return std::runtime_error(e.what());
}

}  // namespace

CoupledVelocitySolve::CoupledVelocitySolve(const System::Settings &settings, CouplingTiming &counts)
    : settings_(settings), counts_(counts)
{
}

void CoupledVelocitySolve::resize(int n)
{
  n_ = n;
  if (results_.solution.size() == size_t(6) * n) return;
  results_.solution.assign(size_t(6) * n, 0.0);
  results_.hydro.assign(size_t(6) * n, 0.0);
  results_.fluidStress.assign(size_t(7) * n, 0.0);
  results_.subgrid.assign(size_t(6) * n, 0.0);
  results_.stress.assign(size_t(20) * n, 0.0);
}

void CoupledVelocitySolve::Results::perAtomRow(long index, int n, bool stresslets, double *row) const
{
  const bool known = index >= 0 && index < n && hydro.size() == size_t(6) * n;
  for (int c = 0; c < 6; c++) {
    row[c] = known ? hydro[size_t(6) * index + c] : 0.0;
    row[6 + c] = known ? subgrid[size_t(6) * index + c] : 0.0;
  }
  if (stresslets)
    for (int c = 0; c < 20; c++) row[12 + c] = known ? stress[size_t(20) * index + c] : 0.0;
}

void CoupledVelocitySolve::assemble(const std::vector<GatheredParticle> &particles, std::vector<double> pairBlocks,
                                    std::vector<double> wallBlocks, System::Springs springs)
{
  const ParticleStepProfile::Clock::time_point start = ParticleStepProfile::now();
  std::vector<System::Particle> loads(n_);
  for (int p = 0; p < n_; p++) {
    const GatheredParticle &q = particles[p];
    System::Particle &l = loads[p];
    for (int d = 0; d < 3; d++) {
      l.x[d] = q.x[d];
      l.force[d] = q.f[d];
      l.torque[d] = q.torque[d];
    }
    l.radius = q.radius;
    l.mass = q.mass;
    l.density = q.density;
  }
  if (!system_) {
    System::Settings settings = settings_;
    settings.alphaLambda = alphaLambda_;
    settings.rhoFluid = rhoFluid_;
    system_.reset(new System(settings));
  }
  system_->assemble(std::move(loads), std::move(pairBlocks), std::move(wallBlocks), std::move(springs));
  counts_.parts.lap(ParticleStepProfile::systemAssembly, start);
}

void CoupledVelocitySolve::setVolumes(const cpl::Volumes &volumes)
{
  std::vector<System::RigidVolume> rigid(n_);
  for (int p = 0; p < n_; p++) {
    const cpl::ParticleVolume &v = volumes.particles[p];
    rigid[p].Vu = v.Vu;
    std::copy(v.m1, v.m1 + 3, rigid[p].m1);
    std::copy(v.J, v.J + 6, rigid[p].J);
  }
  const ParticleStepProfile::Clock::time_point start = ParticleStepProfile::now();
  try {
    system_->setVolumes(rigid);
  } catch (const System::Error &e) {
    throw problem(e, meshSize_, volumes.step, 0);
  }
  counts_.parts.lap(ParticleStepProfile::systemFactorisation, start);
}

const std::vector<double> &CoupledVelocitySolve::solve(const cpl::Integrals &integrals)
{
  std::vector<double> fluid(size_t(6) * n_);
  for (int p = 0; p < n_; p++)
    for (int d = 0; d < 3; d++) {
      fluid[size_t(6) * p + d] = integrals.particles[p].F[d];
      fluid[size_t(6) * p + 3 + d] = integrals.particles[p].T[d];
    }
  const ParticleStepProfile::Clock::time_point start = ParticleStepProfile::now();
  const double factorisedBefore = system_->factorisationSeconds();
  try {
    results_.solution = system_->solve(fluid);
  } catch (const System::Error &e) {
    throw problem(e, meshSize_, integrals.step, integrals.iteration);
  }
  counts_.parts.lap(ParticleStepProfile::systemSolves, start);
  // the factorisations the Coulomb rounds fell back to are factorisations, not solves
  const double refactorised = system_->factorisationSeconds() - factorisedBefore;
  counts_.parts.add(ParticleStepProfile::systemSolves, -refactorised);
  counts_.parts.add(ParticleStepProfile::systemFactorisation, refactorised);
  const long iterations = system_->lastIterations();
  counts_.coulombRoundsMax = std::max(counts_.coulombRoundsMax, system_->lastRounds());
  counts_.solves++;
  counts_.solverIterations += iterations;
  counts_.solverIterationsMax = std::max(counts_.solverIterationsMax, iterations);
  solverIterations = std::max(solverIterations, iterations);
  return results_.solution;
}

void CoupledVelocitySolve::storeStepDone(const cpl::StepDone &done)
{
  for (int p = 0; p < n_; p++) {
    for (int d = 0; d < 3; d++) {
      results_.hydro[size_t(6) * p + d] = done.forces[p].F[d];
      results_.hydro[size_t(6) * p + 3 + d] = done.forces[p].T[d];
    }
    if (settings_.stresslets) {
      for (int c = 0; c < 6; c++) results_.fluidStress[size_t(7) * p + c] = done.stresslets[p].S[c];
      results_.fluidStress[size_t(7) * p + 6] = done.stresslets[p].trace;
    }
  }
  lastIterations = int(done.iterations);
  lastResidual = done.residual;
  if (!done.converged) notConverged++;
}

void CoupledVelocitySolve::finishStep(const std::vector<GatheredParticle> &particles)
{
  const ParticleStepProfile::Clock::time_point start = ParticleStepProfile::now();
  finishStepUntimed(particles);
  counts_.parts.lap(ParticleStepProfile::systemResults, start);
}

void CoupledVelocitySolve::finishStepUntimed(const std::vector<GatheredParticle> &particles)
{
  results_.subgrid = system_->subgridForces();
  counts_.contactSlides += system_->slidingSwitches();
  const ParticleVelocitySystem::SlidingCount sliding = system_->slidingAtEnd();
  counts_.slidingAtEnd += sliding.sliding;
  counts_.slidingAlongFriction += sliding.alongFriction;
  counts_.stuckAgain += system_->stickingSwitches();
  const ParticleVelocitySystem::CoulombConsistency law = system_->coulombConsistency();
  counts_.offCoulomb += law.inconsistent;
  counts_.offCoulombWorst = std::max(counts_.offCoulombWorst, law.worst);
  counts_.chordForceMax = std::max(counts_.chordForceMax, system_->largestChordForce());
  counts_.factorisations += system_->factorisations() - factorisationsCounted_;
  factorisationsCounted_ = system_->factorisations();
  counts_.downdates += system_->downdates() - downdatesCounted_;
  downdatesCounted_ = system_->downdates();
  counts_.backSubstitutions += system_->backSubstitutions() - backSubstitutionsCounted_;
  backSubstitutionsCounted_ = system_->backSubstitutions();
  // the implicit part of the contact forces (Eq. C2) and of their stresslet (Eq. 52); the wall springs'
  // forces for the wall loads
  std::vector<double> springStress(size_t(6) * n_, 0.0);
  results_.springs = system_->springForces(settings_.stresslets ? &springStress : nullptr, &springWallForces_);
  if (!settings_.stresslets) return;
  std::vector<double> subgrid(size_t(7) * n_, 0.0);  // S^SG, s^SG: 7 per particle
  system_->addSubgridStresslets(subgrid);
  for (int p = 0; p < n_; p++) {
    double *out = &results_.stress[size_t(20) * p];
    for (int c = 0; c < 7; c++) out[c] = results_.fluidStress[size_t(7) * p + c] + subgrid[size_t(7) * p + c];
    for (int c = 0; c < 6; c++) out[7 + c] = particles[p].contactStress[c] + springStress[size_t(6) * p + c];
    for (int c = 0; c < 7; c++) out[13 + c] = subgrid[size_t(7) * p + c];
  }
}

FluidExchange::Handlers CoupledVelocitySolve::exchangeHandlers(const std::vector<GatheredParticle> &particles)
{
  FluidExchange::Handlers h;
  h.volumes = [this](const cpl::Volumes &volumes) { setVolumes(volumes); };
  h.integrals = [this](const cpl::Integrals &integrals) -> const std::vector<double> & { return solve(integrals); };
  h.stepDone = [this, &particles](const cpl::StepDone &done) {
    storeStepDone(done);
    finishStep(particles);
  };
  return h;
}

void CoupledVelocitySolve::setDrag(const std::vector<GatheredParticle> &particles, long long step)
{
  setVolumes(isolatedSphereVolumes(particles, step, viscosity_, alphaLambda_, rhoFluid_));
}

void CoupledVelocitySolve::dragForces(const cpl::Integrals &target)
{
  // the far-field (Stokes) force: F = D (u_target - U)
  const std::vector<double> drag = system_->rigidBlocksTimes(results_.solution);
  for (int p = 0; p < n_; p++)
    for (int d = 0; d < 3; d++) {
      results_.hydro[size_t(6) * p + d] = target.particles[p].F[d] - drag[size_t(6) * p + d];
      results_.hydro[size_t(6) * p + 3 + d] = target.particles[p].T[d] - drag[size_t(6) * p + 3 + d];
    }
}

void CoupledVelocitySolve::noFluidStep(const std::vector<GatheredParticle> &particles, long long step, double yCentre,
                                       double shearRate)
{
  setDrag(particles, step);
  cpl::Integrals atRest;  // no fluid: no fluid force
  atRest.step = uint64_t(step);
  atRest.iteration = 1;
  atRest.particles.assign(n_, cpl::ForceTorque());
  if (shearRate != 0)
    backgroundShearDrag(particles, yCentre, viscosity_, shearRate, atRest,
                        settings_.stresslets ? &results_.fluidStress : nullptr);
  solve(atRest);
  dragForces(atRest);
  finishStep(particles);
  lastIterations = 1;
}

void CoupledVelocitySolve::heldStep(const std::vector<GatheredParticle> &particles, long long step,
                                    long long lastFluidStep, const std::vector<double> &lastU, HeldDrag &held)
{
  // At unchanged positions Eq. (31) with the drag target D U + F^FDM gives the fluid step's velocities
  // again (to the inner iteration's tolerance); R^SG, the contact springs and the position update follow
  // the particles as in every step: they change within a fluid step, where the far field does not.
  setDrag(particles, step);   // Eq. (31)'s rigid-body blocks become D
  const std::vector<double> dragTimesLastU = system_->rigidBlocksTimes(lastU);
  std::vector<double> lastTarget(size_t(6) * n_);
  for (size_t k = 0; k < lastTarget.size(); k++) lastTarget[k] = dragTimesLastU[k] + results_.hydro[k];
  const std::vector<double> b = held.target(lastTarget, step, lastFluidStep);
  cpl::Integrals target;
  target.step = uint64_t(step);
  target.iteration = 1;
  target.particles.resize(n_);
  for (int p = 0; p < n_; p++)
    for (int d = 0; d < 3; d++) {
      target.particles[p].F[d] = b[size_t(6) * p + d];
      target.particles[p].T[d] = b[size_t(6) * p + 3 + d];
    }
  solve(target);
  dragForces(target);
  finishStep(particles);
  lastIterations = 0;
}

}  // namespace fdm
