// One step's exchange with the fluid (dem/fluid_exchange.h) against a scripted fluid, without LIGGGHTS
// or sockets: the order of the messages, the velocities sent back for each inner iteration, and the
// problems named (a message of the wrong type or of another step), and the Step message itself.
#include "fluid_exchange.h"

#include <gtest/gtest.h>

#include <deque>
#include <stdexcept>

namespace cpl = fdm::coupler;

namespace {

// A fluid that sends its script, whatever it receives, and keeps what it was sent.
class ScriptedFluid : public cpl::Transport {
 public:
  void send(const cpl::Message &m) override { sent.push_back(m); }
  cpl::Message receive() override
  {
    if (script.empty()) throw cpl::CouplerError("the script is over");
    cpl::Message m = script.front();
    script.pop_front();
    return m;
  }
  void close() noexcept override {}
  std::string describe() const override { return "scripted fluid"; }
  std::deque<cpl::Message> script;
  std::vector<cpl::Message> sent;
};

cpl::Step stepMessage(long long step, int n)
{
  cpl::Step s;
  s.step = uint64_t(step);
  s.dt = 0.1;
  s.lastStep = 10;
  s.particles.resize(n);
  for (int p = 0; p < n; p++) {
    s.particles[p].tag = p + 1;
    s.particles[p].radius = 1;
    for (int d = 0; d < 3; d++) s.particles[p].x[d] = 2.0 * p + d;
  }
  return s;
}

cpl::Volumes volumes(long long step, int n)
{
  cpl::Volumes v;
  v.step = uint64_t(step);
  v.particles.resize(n);
  for (int p = 0; p < n; p++) v.particles[p].Vu = 4.0 + p;
  return v;
}

cpl::Integrals integrals(long long step, uint32_t iteration, int n)
{
  cpl::Integrals in;
  in.step = uint64_t(step);
  in.iteration = iteration;
  in.particles.assign(n, cpl::ForceTorque());
  for (int p = 0; p < n; p++) in.particles[p].F[0] = 10.0 * iteration + p;
  return in;
}

cpl::StepDone done(long long step, int n)
{
  cpl::StepDone d;
  d.step = uint64_t(step);
  d.iterations = 2;
  d.converged = true;
  d.forces.assign(n, cpl::ForceTorque());
  return d;
}

// Handlers that answer U_x = F_x / Vu and record what they saw.
struct Recorder {
  std::vector<double> vu, u;
  std::vector<uint32_t> iterations;
  bool finished = false;
  fdm::FluidExchange::Handlers handlers()
  {
    fdm::FluidExchange::Handlers h;
    h.volumes = [this](const cpl::Volumes &v) {
      for (const cpl::ParticleVolume &p : v.particles) vu.push_back(p.Vu);
    };
    h.integrals = [this](const cpl::Integrals &in) -> const std::vector<double> & {
      iterations.push_back(in.iteration);
      u.assign(6 * in.particles.size(), 0.0);
      for (size_t p = 0; p < in.particles.size(); p++) u[6 * p] = in.particles[p].F[0] / vu[p];
      return u;
    };
    h.stepDone = [this](const cpl::StepDone &) { finished = true; };
    return h;
  }
};

}  // namespace

TEST(FluidExchange, AnswersEveryInnerIterationUntilStepDone)
{
  const int n = 2;
  ScriptedFluid fluid;
  fluid.script = {volumes(7, n).toMessage(), integrals(7, 1, n).toMessage(), integrals(7, 2, n).toMessage(),
                  done(7, n).toMessage()};
  Recorder r;
  fdm::FluidExchange(fluid, n, false).run(stepMessage(7, n), r.handlers());
  EXPECT_TRUE(r.finished);
  EXPECT_EQ(r.vu, std::vector<double>({4.0, 5.0}));
  EXPECT_EQ(r.iterations, std::vector<uint32_t>({1, 2}));
  // Step, then one Velocities per Integrals, with the iteration and the handler's velocities
  ASSERT_EQ(fluid.sent.size(), 3u);
  EXPECT_EQ(fluid.sent[0].type, cpl::MessageType::Step);
  EXPECT_EQ(cpl::Step::fromMessage(fluid.sent[0], n).particles[1].x[2], 4.0);
  for (uint32_t k = 1; k <= 2; k++) {
    const cpl::Velocities v = cpl::Velocities::fromMessage(fluid.sent[k], n);
    EXPECT_EQ(v.step, 7u);
    EXPECT_EQ(v.iteration, k);
    EXPECT_EQ(v.particles[1].U[0], (10.0 * k + 1) / 5.0);
  }
}

TEST(FluidExchange, AMessageOfTheWrongTypeOrStepIsNamed)
{
  const int n = 1;
  Recorder r;
  ScriptedFluid early;   // Integrals where the step's Volumes are due
  early.script = {integrals(3, 1, n).toMessage()};
  try {
    fdm::FluidExchange(early, n, false).run(stepMessage(3, n), r.handlers());
    FAIL() << "no error";
  } catch (const std::runtime_error &e) {
    EXPECT_STREQ(e.what(), "coupling: expected Volumes from the fluid solver, got Integrals (step 3)");
  }
  ScriptedFluid late;    // the Integrals of another step
  late.script = {volumes(3, n).toMessage(), integrals(2, 1, n).toMessage()};
  try {
    fdm::FluidExchange(late, n, false).run(stepMessage(3, n), r.handlers());
    FAIL() << "no error";
  } catch (const std::runtime_error &e) {
    EXPECT_STREQ(e.what(), "coupling: the fluid solver sent Integrals of step 2 during step 3");
  }
}

TEST(FluidExchange, TheStepCarriesWrappedPositionsAndTheLastSolvedVelocities)
{
  fdm::ParticleBox box;
  for (int d = 0; d < 3; d++) {
    box.lo[d] = 0;
    box.hi[d] = box.length[d] = 10;
    box.periodic[d] = d == 0;
  }
  fdm::GatheredParticle p = fdm::GatheredParticle();
  p.x[0] = 12.5;   // through the periodic face: wrapped to 2.5
  p.x[1] = 3;
  p.radius = 1;
  p.v[0] = 9;      // the Adams-Bashforth rate of this move, not U_n
  const std::vector<double> solved = {1, 2, 3, 4, 5, 6};
  const cpl::Step s = fdm::FluidExchange::makeStep({p}, box, 4, 0.2, 10, true, solved);
  EXPECT_EQ(s.step, 4u);
  EXPECT_EQ(s.dt, 0.2);
  EXPECT_TRUE(s.checkpoint);
  EXPECT_EQ(s.particles[0].tag, 1);
  EXPECT_EQ(s.particles[0].x[0], 2.5);
  EXPECT_EQ(s.particles[0].x[1], 3.0);
  EXPECT_EQ(s.particles[0].velocity.U[0], 1.0);
  EXPECT_EQ(s.particles[0].velocity.omega[2], 6.0);
  // before the first solve: the velocities the input gave
  EXPECT_EQ(fdm::FluidExchange::makeStep({p}, box, 1, 0.1, 10, false, {}).particles[0].velocity.U[0], 9.0);
}
