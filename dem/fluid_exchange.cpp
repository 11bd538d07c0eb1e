// One time step's exchange with the fluid solver (fluid_exchange.h).
#include "fluid_exchange.h"

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

namespace fdm {

namespace cpl = coupler;

namespace {

double now()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

cpl::Message FluidExchange::receive(bool volumes, long long step)
{
  const cpl::Message m = connection_.receive();
  const bool expected = volumes ? m.type == cpl::MessageType::Volumes
                                : m.type == cpl::MessageType::Integrals || m.type == cpl::MessageType::StepDone;
  if (!expected)
    throw std::runtime_error(std::string("coupling: expected ") + (volumes ? "Volumes" : "Integrals or StepDone") +
                             " from the fluid solver, got " + cpl::messageTypeName(m.type) + " (step " +
                             std::to_string(step) + ")");
  if (m.step != uint64_t(step))
    throw std::runtime_error(std::string("coupling: the fluid solver sent ") + cpl::messageTypeName(m.type) +
                             " of step " + std::to_string(m.step) + " during step " + std::to_string(step));
  return m;
}

FluidExchange::Seconds FluidExchange::run(const cpl::Step &step, const Handlers &handlers)
{
  Seconds seconds;
  const long long n = (long long) step.step;
  double t0 = now();
  connection_.send(step.toMessage());
  const cpl::Message volumes = receive(true, n);
  double t1 = now();
  seconds.exchange += t1 - t0;
  handlers.volumes(cpl::Volumes::fromMessage(volumes, particles_));
  t0 = now();
  seconds.handlers += t0 - t1;
  while (true) {
    const cpl::Message m = receive(false, n);
    t1 = now();
    seconds.exchange += t1 - t0;
    if (m.type == cpl::MessageType::StepDone) {
      handlers.stepDone(cpl::StepDone::fromMessage(m, stresslets_, particles_));
      seconds.handlers += now() - t1;
      return seconds;
    }
    const cpl::Integrals integrals = cpl::Integrals::fromMessage(m, particles_);
    const std::vector<double> &u = handlers.integrals(integrals);
    cpl::Velocities reply;
    reply.step = integrals.step;
    reply.iteration = integrals.iteration;
    reply.particles.resize(particles_);
    for (int p = 0; p < particles_; p++)
      for (int d = 0; d < 3; d++) {
        reply.particles[p].U[d] = u[size_t(6) * p + d];
        reply.particles[p].omega[d] = u[size_t(6) * p + 3 + d];
      }
    t0 = now();
    seconds.handlers += t0 - t1;
    connection_.send(reply.toMessage());
  }
}

cpl::Step FluidExchange::makeStep(const std::vector<GatheredParticle> &particles, const ParticleBox &box,
                                  long long step, double fluidDt, long long lastStep, bool checkpoint,
                                  const std::vector<double> &solvedVelocities)
{
  cpl::Step s;
  s.step = uint64_t(step);
  s.dt = fluidDt;
  s.lastStep = lastStep;
  s.checkpoint = checkpoint;
  const size_t n = particles.size();
  s.particles.resize(n);
  const bool solved = solvedVelocities.size() == 6 * n;
  for (size_t p = 0; p < n; p++) {
    const GatheredParticle &q = particles[p];
    cpl::StepParticle &out = s.particles[p];
    out.tag = (long long) p + 1;
    for (int d = 0; d < 3; d++) {
      double x = q.x[d];
      if (box.periodic[d]) x -= box.length[d] * std::floor((x - box.lo[d]) / box.length[d]);
      out.x[d] = x;
      // v may hold this step's Adams-Bashforth displacement rate: U_n is the last solve's
      out.velocity.U[d] = solved ? solvedVelocities[6 * p + d] : q.v[d];
      out.velocity.omega[d] = solved ? solvedVelocities[6 * p + 3 + d] : q.omega[d];
    }
    out.radius = q.radius;
  }
  return s;
}

}  // namespace fdm
