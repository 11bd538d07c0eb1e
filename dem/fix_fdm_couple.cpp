// fix fdm/couple: the particle side of the coupled FDM method (Orsi, Lobry & Peters 2023, 4.2-4.4).
// See fix_fdm_couple.h for what it does and docs/dem.md for its use. This file is the LIGGGHTS
// adapter: atoms in and out, the collectives, the checks only LIGGGHTS can make.
#include "fix_fdm_couple.h"
#include "gather_to_root.h"

#include "configuration_checks.h"
#include "coupling_session.h"
#include "fluid_exchange.h"
#include "message_text.h"
#include "pair_fdm_subgrid.h"
#include "step_collectives.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "memory.h"
#include "modify.h"
#include "timer.h"
#include "update.h"

#include <algorithm>
#include <cstdio>

using namespace LAMMPS_NS;
namespace cpl = fdm::coupler;

namespace {

// Per-atom values gathered to rank 0: tag, then the fields of GatheredParticle (the contact
// stresslet only when stresslets are asked for).
const int gatherWidth = 19, gatherStressWidth = 6;

fdm::CoupleOptions parseOptions(Error *error, int narg, char **arg)
{
  try {
    return fdm::parseCoupleOptions(std::vector<std::string>(arg + std::min(3, narg), arg + narg));
  } catch (const fdm::KeywordError &e) {
    error->all(FLERR, e.what());
  }
  return fdm::CoupleOptions();
}

}  // namespace

FixFdmCouple::FixFdmCouple(LAMMPS *lmp, int narg, char **arg) :
  Fix(lmp, narg, arg), session_(CouplingSession::instance()), options_(parseOptions(error, narg, arg)),
  solve_(options_.systemSettings(), run_), schedule_(options_.fluidEvery), heldDrag_(options_.heldExtrapolated),
  plan_(options_.moveOptions()), pair_(nullptr), atomsAtInit_(0), natoms_(0), runStart_(0.0), nmax_(0),
  perAtom_(nullptr), checkpointSeconds_(0), resumed_(false)
{
  if (igroup != 0) error->all(FLERR, "fix fdm/couple must be applied to group all (every particle is in the fluid)");
  time_integrate = 1;
  vector_flag = 1;
  size_vector = 8;
  global_freq = 1;
  extvector = 0;
  peratom_flag = 1;
  peratom_freq = 1;
  perAtomColumns_ = fdm::CoupledVelocitySolve::Results::perAtomColumns(options_.stresslets);
  size_peratom_cols = perAtomColumns_;
  session_.attach(this, options_.sessionRequest());
  if (!session_.resumeFile().empty() && !session_.connected()) readResumeCheckpoint();
  // LIGGGHTS re-neighbours at every checkpoint step (initial_integrate names it): the positions a
  // checkpoint holds are then wrapped into the box and the neighbour lists built from them, as a
  // resumed run's set-up wraps and lists them (else a particle that crossed a periodic face since the
  // last re-neighbouring is wrapped at the resume but later in the uninterrupted run: x + L + dx is
  // not x + dx + L in floating point)
  if (options_.checkpointEvery > 0) {
    force_reneighbor = 1;
    next_reneighbor = -1;
  }
}

FixFdmCouple::~FixFdmCouple()
{
  session_.detach(this);
  memory->destroy(perAtom_);
}

int FixFdmCouple::setmask()
{
  // PRE_EXCHANGE: a resumed run restores its checkpoint in setup_pre_exchange
  return FixConst::INITIAL_INTEGRATE | FixConst::FINAL_INTEGRATE | FixConst::PRE_EXCHANGE;
}

void FixFdmCouple::init()
{
  session_.checkAtoms(lmp);
  atomsAtInit_ = int(atom->natoms);
  pair_ = dynamic_cast<PairFdmSubgrid *>(force->pair_match("fdm/subgrid", 1));
  if (pair_) pair_->requestContactStress(options_.stresslets);
  if (!options_.wallFile.empty() && (!pair_ || pair_->walls().empty()))
    error->all(FLERR, ("fix fdm/couple: walls " + options_.wallFile + " needs pair_style fdm/subgrid with its walls "
                       "(wall FACE ux uy uz): there are no walls to write the loads of").c_str());
  const std::string setup = fdm::couplingSetupProblem(force->newton_pair != 0, update->unit_style, update->dt);
  if (!setup.empty()) error->all(FLERR, setup.c_str());
  // the contact springs' stability limit depends on the time step and on this fix's integrator
  if (pair_) pair_->checkTimeStep(update->dt, options_.adamsBashforth);
  for (int i = 0; i < modify->nfix; i++) {
    const std::string problem = modify->fix[i] == this ? std::string() :
      fdm::otherFixProblem(modify->fix[i]->style, modify->fix[i]->id, modify->fix[i]->time_integrate != 0);
    if (!problem.empty()) error->all(FLERR, problem.c_str());
  }
  if (!comm->ghost_velocity && comm->me == 0)
    error->warning(FLERR, "fix fdm/couple: 'communicate single vel yes' is needed by the lubrication pair styles");
  if (resume_) continueDumps();
}

void FixFdmCouple::allAgree(const std::string &problemOnRank0)
{
  // The problem is known on rank 0 only; every rank must stop (and the fluid is told why).
  session_.stopIf(lmp, problemOnRank0);
}

void FixFdmCouple::fail(const std::string &message)
{
  // rank 0, in the middle of a step (the other ranks wait in MPI_Bcast): error->one aborts them all
  session_.abandon("fdmDEM: " + message);
  error->one(FLERR, ("fdm/couple: " + message).c_str());
}

fdm::ParticleBox FixFdmCouple::box() const
{
  fdm::ParticleBox b;
  for (int d = 0; d < 3; d++) {
    b.lo[d] = domain->boxlo[d];
    b.hi[d] = domain->boxhi[d];
    b.length[d] = domain->prd[d];
    b.periodic[d] = domain->periodicity[d] != 0;
  }
  return b;
}

void FixFdmCouple::gather(Particles &particles)
{
  const int nlocal = atom->nlocal;
  const bool withStress = options_.stresslets && pair_;
  const int width = gatherWidth + (withStress ? gatherStressWidth : 0);
  std::vector<double> buf(size_t(width) * nlocal);
  for (int i = 0; i < nlocal; i++) {   // in the order of fdm::particlesByTag
    double *b = &buf[size_t(width) * i];
    *b++ = atom->tag[i];
    b = std::copy(atom->x[i], atom->x[i] + 3, b);
    *b++ = atom->radius[i];
    for (double *v : {atom->v[i], atom->omega[i], atom->f[i], atom->torque[i]}) b = std::copy(v, v + 3, b);
    *b++ = atom->rmass[i];
    *b++ = atom->density[i];
    if (withStress) std::copy(pair_->contactStress(i), pair_->contactStress(i) + 6, b);
  }
  const std::vector<double> all = fdm::gatherToRoot(buf, world);
  if (comm->me != 0) return;
  const std::string problem = fdm::particlesByTag(all, width, withStress, natoms_, (long long) atom->natoms, particles);
  if (!problem.empty()) fail(problem);
}

void FixFdmCouple::setup(int)
{
  // Called before every run (not with 'run N pre no'): connect once, then check the particles
  // wherever the input has put them since (set atom ... between runs).
  const bool firstSetup = !session_.connected();
  checkResumedRunLength();
  resume_.reset();
  // the count of init(): LIGGGHTS may have dropped an atom since, which gather() must name
  session_.ensureConnected(lmp, atomsAtInit_);
  natoms_ = session_.particles();
  // fewer atoms than announced: gather() names the particle LIGGGHTS lost
  if (atom->natoms > natoms_ || atom->map_tag_max > natoms_)
    allAgree("the particles changed since the coupling started: " + std::to_string((long long) atom->natoms) +
             " atoms with IDs up to " + std::to_string(atom->map_tag_max) + " where the fluid solver was told of " +
             std::to_string(natoms_) + " (particles cannot be inserted during a coupled session)");
  solve_.setFluid(session_.alphaLambda(), session_.rhoFluid(), session_.viscosity(), session_.meshSize());
  solve_.resize(natoms_);
  Particles particles;
  gather(particles);
  // Overlaps and wall crossings are input errors in the configuration the input script gave (first
  // run, or positions set between runs of fixed particles); later runs, and a resumed session,
  // continue from where contacts (h_r > 0, finite kn) may legitimately have pressed particles a little
  // into each other or into a wall.
  const bool fromInput = (firstSetup && !resumed_) || !options_.move;
  allAgree(comm->me == 0 ? fdm::configurationProblem(particles, box(), fromInput) : std::string());
  // A planned position update continues the previous run only from where that run left the
  // particles: if the input has moved them since (set, displace_atoms, read_restart ...), the next
  // step starts afresh (Euler from the current velocities, then Adams-Bashforth again).
  int keepPlan = plan_.planned ? 1 : 0;
  if (comm->me == 0 && keepPlan)
    keepPlan = plan_.continuesFrom(particles, [this](double *d) { domain->minimum_image(d); }) ? 1 : 0;
  MPI_Bcast(&keepPlan, 1, MPI_INT, 0, world);
  if (!keepPlan) plan_.forget();
  fillPerAtomArray();
  runStart_ = MPI_Wtime();
  run_ = fdm::CouplingTiming();
  if (pair_) pair_->takeContactSeconds();  // the setup's force evaluation is not the run's
}

void FixFdmCouple::initial_integrate(int)
{
  // Step 1 of the algorithm (4.3): move the particles. Nothing else: there is no particle inertia
  // (Eqs. 28d-e). The displacement rates were planned at the end of the previous step
  // (planNextMove: Adams-Bashforth 2 with the log-gap correction of position_update.h); the very
  // first step moves with the velocities the input gave.
  if (force_reneighbor) next_reneighbor = checkpointDue() ? update->ntimestep : -1;
  if (!options_.move) return;
  const Profile::Clock::time_point start = Profile::now();
  const double dt = update->dt;
  for (int i = 0; i < atom->nlocal; i++) {
    if (plan_.planned) {
      // v and omega become the rates of this move, so that the contact springs of the pair style
      // (tangential displacement += dt v_rel) follow the contact points exactly; the solve at the
      // end of the step sets them to U_{n+1} again
      const double *rate = &plan_.rates[size_t(6) * (atom->tag[i] - 1)];
      for (int d = 0; d < 3; d++) {
        atom->v[i][d] = rate[d];
        atom->omega[i][d] = rate[3 + d];
      }
    }
    for (int d = 0; d < 3; d++) atom->x[i][d] += dt * atom->v[i][d];
  }
  run_.parts.lap(Profile::positionUpdate, start);
}

void FixFdmCouple::assembleSystem(const Particles &particles)
{
  // Every rank builds the sub-grid blocks of its own pairs and wall gaps from its neighbour list;
  // rank 0 collects them and assembles Eq. (31) once for the step (paper section 4.4.2).
  const bool wallLoads = !options_.wallFile.empty();
  std::vector<double> pairs, walls, wallIndex;
  long contacts = 0;
  Profile::Clock::time_point t = Profile::now();
  if (pair_) {
    pair_->collectBlocks(options_.stresslets, pairs, walls, wallLoads ? &wallIndex : nullptr);
    contacts = pair_->contactsLast();
    t = run_.parts.lap(Profile::subgridBlocks, t);
  }
  checkOverlaps();
  t = Profile::now();
  std::vector<double> allPairs = fdm::gatherToRoot(pairs, world);
  std::vector<double> allWalls = fdm::gatherToRoot(walls, world);
  t = run_.parts.lap(Profile::gatherScatter, t);
  // implicit contact springs (docs/contact.md 2b): c1 the weight of U_{n+1} in the next position
  // update (planNextMove: ab2 once a previous step exists), gamma = -c0/c1 the weight of U_n. Decided
  // on rank 0, which plans the position update: every rank must build its blocks with the same weight.
  fdm::ParticleVelocitySystem::Springs springs;
  int multistepFlag = plan_.multistep(natoms_);
  MPI_Bcast(&multistepFlag, 1, MPI_INT, 0, world);
  const bool multistep = multistepFlag != 0;
  wallLoads_.springBlockWall.clear();
  if (pair_ && pair_->implicitContact() && options_.move) {
    std::vector<double> springPairs, springWalls, springWallIndex;
    t = Profile::now();
    pair_->collectSpringBlocks(multistep ? 1.5 : 1.0, update->dt, springPairs, springWalls,
                               wallLoads ? &springWallIndex : nullptr);
    t = run_.parts.lap(Profile::contact, t);
    springs.pairs = fdm::gatherToRoot(springPairs, world);
    springs.walls = fdm::gatherToRoot(springWalls, world);
    if (wallLoads) wallLoads_.springBlockWall = fdm::gatherToRoot(springWallIndex, world);
    run_.parts.lap(Profile::gatherScatter, t);
    // Eq. (C5): the straight step's chord of a sliding or rolling pair, in its normal spring, from
    // U_n (kept in the checkpoints: a resumed run takes the same chord terms)
    plan_.springHistory(multistep, options_.contactChord, natoms_, update->dt, springs);
  }
  if (wallLoads) {
    // the wall of each block, gathered in the same rank order as the blocks; the contact loads summed
    wallLoads_.subgridBlockWall = fdm::gatherToRoot(wallIndex, world);
    wallLoads_.contactLoads = fdm::sumOnRoot(pair_->wallContactLoads(), 3 * pair_->walls().size(), world);
  }
  MPI_Reduce(&contacts, &blocks_.contacts, 1, MPI_LONG, MPI_SUM, 0, world);
  if (comm->me != 0) return;

  // whatever `move`: move no fixes the places, not the velocities, which are solved force-free as ever
  if (session_.hasFluid() && domain->xperiodic && domain->yperiodic && domain->zperiodic) {
    const std::string problem = fdm::periodicBalanceProblem(particles, box(), session_.gradP0(), session_.rhoFluid(),
                                                            options_.gravity, update->ntimestep);
    if (!problem.empty()) fail(problem);
  }
  try {
    solve_.assemble(particles, std::move(allPairs), std::move(allWalls), std::move(springs));
  } catch (const std::exception &e) {
    fail(e.what());
  }
  blocks_.pairBlocks = solve_.system()->pairBlocks();
  blocks_.wallBlocks = solve_.system()->wallBlocks();
}

void FixFdmCouple::final_integrate()
{
  // Steps 3-7 of the algorithm (4.3) seen from the particles: once per time step, after LIGGGHTS
  // has summed every force. Rank 0 talks to the fluid and solves; the result is broadcast.
  double t0 = MPI_Wtime();
  Profile::Clock::time_point t = Profile::now();
  Particles particles;
  gather(particles);
  run_.parts.lap(Profile::gatherScatter, t);
  run_.gatherScatter += MPI_Wtime() - t0;
  t0 = MPI_Wtime();
  solve_.solverIterations = 0;
  assembleSystem(particles);
  run_.solve += MPI_Wtime() - t0;

  const bigint step = update->ntimestep;
  const bool haveFluidForce = plan_.haveVelocities && solve_.results().hydro.size() == size_t(6) * natoms_;
  const bool fluidStep = options_.hasFluid() && schedule_.due(step, update->laststep, checkpointDue(), haveFluidForce);
  if (comm->me == 0) {
    try {
      if (fluidStep) {
        exchangeWithFluid(particles);
      } else {
        t0 = MPI_Wtime();
        const double timedBefore = run_.parts.timed();
        if (options_.hasFluid())
          solve_.heldStep(particles, step, schedule_.lastFluidStep(), plan_.current, heldDrag_);
        else
          solve_.noFluidStep(particles, step, 0.5 * (domain->boxlo[1] + domain->boxhi[1]), options_.backgroundShear);
        const double seconds = MPI_Wtime() - t0;
        run_.solve += seconds;
        // the drag's volumes and targets around the timed parts of Eq. (31)
        run_.parts.addUntimed(Profile::systemSolves, seconds, timedBefore);
      }
      if (!options_.wallFile.empty()) writeWallLoads();
    } catch (const std::exception &e) {
      fail(e.what());
    }
  }
  if (options_.move && comm->me == 0) {
    t0 = MPI_Wtime();
    t = Profile::now();
    planNextMove(particles);
    run_.parts.lap(Profile::positionUpdate, t);
    run_.solve += MPI_Wtime() - t0;
  }
  t0 = MPI_Wtime();
  t = Profile::now();
  scatter();
  run_.parts.lap(Profile::gatherScatter, t);
  run_.gatherScatter += MPI_Wtime() - t0;
  run_.steps++;
  if (fluidStep) {
    run_.fluidSteps++;
    schedule_.solved(step);
  }
  if (checkpointDue()) writeCheckpoint();
}

void FixFdmCouple::exchangeWithFluid(const Particles &particles)
{
  // rank 0: the step's messages with the fluid (fluid_exchange.h), Eq. (31) solved for each of its
  // inner iterations
  cpl::Transport *connection = session_.transport();
  if (!connection) fail("the connection to the fluid solver is closed");
  const bigint step = update->ntimestep;
  const cpl::Step message = fdm::FluidExchange::makeStep(particles, box(), step, schedule_.span(step, update->dt),
                                                         update->laststep, checkpointDue(), plan_.current);
  const double timedBefore = run_.parts.timed();
  const fdm::FluidExchange::Seconds seconds =
      fdm::FluidExchange(*connection, natoms_, options_.stresslets).run(message, solve_.exchangeHandlers(particles));
  run_.exchange += seconds.exchange;
  run_.solve += seconds.handlers;
  // the handlers' copies of the messages around the timed parts of Eq. (31)
  run_.parts.addUntimed(Profile::systemSolves, seconds.handlers, timedBefore);
  run_.parts.add(Profile::fluidExchange, seconds.exchange);
}

void FixFdmCouple::writeWallLoads()
{
  // rank 0, after the last inner iteration (wall_loads_file.h)
  if (!wallOut_) {
    std::vector<fdm::WallLoadsFile::Wall> walls;
    for (const PairFdmSubgrid::Wall &w : pair_->walls()) walls.push_back(fdm::WallLoadsFile::Wall{w.axis, w.side});
    wallOut_.reset(new fdm::WallLoadsFile(options_.wallFile, walls));
  }
  wallLoads_.subgridBlockForces = solve_.system()->wallBlockForces();
  wallLoads_.springBlockForces = solve_.springWallForces();
  wallOut_->write(update->ntimestep, update->dt, !session_.resumeFile().empty(), wallLoads_);
}

void FixFdmCouple::planNextMove(const Particles &particles)
{
  // rank 0, U_n just solved: the rates of the next position update (move_plan.h), with the log-gap
  // correction of the close pairs of Eq. (31) and of the walls
  std::vector<int> closePairs;
  std::vector<fdm::motion::Wall> walls;
  if (options_.gapUpdate && solve_.system()) closePairs = solve_.system()->closePairs();
  if (options_.gapUpdate && pair_)
    for (const PairFdmSubgrid::Wall &w : pair_->walls())
      walls.push_back(fdm::motion::Wall{w.axis, w.side, w.side == 0 ? domain->boxlo[w.axis] : domain->boxhi[w.axis]});
  const double contactGap = pair_ && pair_->contactActive() ? pair_->roughness() : 0.0;
  const fdm::motion::Statistics stats =
      plan_.plan(particles, box(), solve_.results().solution, closePairs, walls, update->dt, contactGap);
  run_.countMove(stats);
  // said once per run (the count is in the timing line): in dense packings it is the rule
  if (stats.fallback && run_.gapFallbacks == 1)
    error->warning(FLERR, fdm::MovePlan::fallbackWarning(update->ntimestep, stats).c_str());
}

void FixFdmCouple::scatter()
{
  // rank 0's plan, results and counters on every rank (step_collectives.h)
  fdm::broadcastStep(plan_, options_.move, solve_, blocks_, natoms_, options_.stresslets, world);
  const fdm::CoupledVelocitySolve::Results &r = solve_.results();
  // the implicit part of the contact forces: f and torque become the forces that moved the particles;
  // the velocities of the converged inner iteration are the particles' velocities of this step
  for (int i = 0; i < atom->nlocal; i++) {
    const size_t t = size_t(6) * (atom->tag[i] - 1);
    const double *u = &r.solution[t];
    for (int d = 0; d < 3; d++) {
      atom->v[i][d] = u[d];
      atom->omega[i][d] = u[3 + d];
      atom->f[i][d] += r.springs[t + d];
      atom->torque[i][d] += r.springs[t + 3 + d];
    }
  }
  fillPerAtomArray();
}

void FixFdmCouple::checkOverlaps()
{
  // Every rank (collective): the deepest overlap of the ranks' pairs (configuration_checks.h)
  if (!pair_ || !session_.hasFluid()) return;
  const fdm::Overlap worst = fdm::deepestOverlap(pair_->deepestOverlap(), cpl::contactOverlapTolerance, world);
  if (!(worst.depth > cpl::contactOverlapTolerance)) return;
  allAgree(comm->me != 0 ? std::string() :
           fdm::deepOverlapProblem(worst.tagI, worst.tagJ, worst.gap, worst.depth, update->ntimestep));
}

void FixFdmCouple::fillPerAtomArray()
{
  if (atom->nmax > nmax_) {
    nmax_ = atom->nmax;
    memory->destroy(perAtom_);
    memory->create(perAtom_, nmax_, perAtomColumns_, "fdm/couple:hydrodynamic");
    array_atom = perAtom_;
  }
  for (int i = 0; i < atom->nlocal; i++)
    solve_.results().perAtomRow(atom->tag[i] - 1, natoms_, options_.stresslets, perAtom_[i]);
}

void FixFdmCouple::post_run()
{
  const double now = MPI_Wtime();
  if (pair_) run_.parts.add(Profile::contact, pair_->takeContactSeconds());
  // LIGGGHTS's own timers of this run's loop (its Timer, zeroed before the loop; read before Finish)
  Profile::LiggghtsTimers liggghts;
  liggghts.neighbour = timer->array[TIME_NEIGHBOR];
  liggghts.communication = timer->array[TIME_COMM];
  liggghts.output = timer->array[TIME_OUTPUT];
  run_.parts.addLiggghts(liggghts);
  session_.addRun(run_.steps, run_.solve, run_.exchange, run_.gatherScatter);
  session_.addProfile(run_.parts, run_.fluidSteps);
  if (comm->me == 0) {
    const fdm::TimingContext c = {fdm::ParticleVelocitySystem::solverName(options_.solver), options_.adamsBashforth,
                                  options_.gapUpdate, options_.contactChord && pair_ && pair_->implicitContact(),
                                  blocks_.pairBlocks, blocks_.wallBlocks, blocks_.contacts, solve_.notConverged, options_.fluidEvery,
                                  options_.heldExtrapolated};
    const std::string line = fdm::timingLine("of this run", run_, now - runStart_, 1, c) +
                             run_.parts.report("this run", session_.whoseProfile(comm->nprocs), now - runStart_,
                                               run_.steps, run_.fluidSteps);
    if (screen) fputs(line.c_str(), screen);
    if (logfile) fputs(line.c_str(), logfile);
  }
  if (options_.checkpointEvery > 0 && comm->me == 0 && screen)
    fprintf(screen, "fdm/couple checkpoints: every %lld steps and at the end of the run, %.4g s of writing so far\n",
            options_.checkpointEvery, checkpointSeconds_);
  solve_.notConverged = 0;
  // a following 'run N pre no' skips setup(): its timing starts here
  run_ = fdm::CouplingTiming();
  runStart_ = now;
}

double FixFdmCouple::compute_vector(int n)
{
  switch (n) {
    case 0: return solve_.lastIterations;
    case 1: return solve_.lastResidual;
    case 2: return session_.totalSolve() + run_.solve;
    case 3: return session_.totalExchange() + run_.exchange;
    case 4: return solve_.solverIterations;
    case 5: return blocks_.pairBlocks;
    case 6: return blocks_.wallBlocks;
    case 7: return blocks_.contacts;
  }
  return 0.0;
}

double FixFdmCouple::memory_usage()
{
  const fdm::CoupledVelocitySolve::Results &r = solve_.results();
  return double(nmax_) * perAtomColumns_ * sizeof(double) + double(r.solution.size() + r.hydro.size()) * sizeof(double);
}
