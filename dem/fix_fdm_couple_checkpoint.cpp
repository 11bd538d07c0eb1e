// fix fdm/couple: checkpoint and resume (docs/coupling.md, "Checkpoint and resume").
//
// With `checkpoint N` the fix writes checkpoint/dem.<step> (in fdmDEM's working directory) at the end
// of every N-th step and of the last step of each run, and tells fdmFoam in that step's Step message
// to write its own (fields, lambda) at the same step. `fdmDEM -resume FILE` (fdmRun --resume) reads
// one back: the constructor of the fix sets the time step to the checkpoint's, so that the input's
// `run L upto` continues to the same last step; before the first step (setup_pre_exchange, i.e.
// before LIGGGHTS wraps, migrates and lists the atoms) every rank restores its particles, their contact
// history and the position update's history, so that the next step is the one the interrupted run
// would have made. The file itself (atomic write, layout, checks) is particle_checkpoint.h.
#include "fix_fdm_couple.h"

#include "coupling_session.h"
#include "fix_contact_history_fdm.h"
#include "gather_to_root.h"
#include "message_text.h"
#include "pair_fdm_subgrid.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "dump.h"
#include "error.h"
#include "fix_property_atom.h"
#include "output.h"
#include "update.h"

#include <sys/stat.h>

#include <cmath>
#include <limits>

using namespace LAMMPS_NS;
namespace ckpt = fdm::checkpoint;

namespace {

const char *directory = "checkpoint";
const char *prefix = "dem.";
// per particle in the array "atoms": x (3), v (3), omega (3), image, radius, mass, density, type
const int atomWidth = 14;

// Every rank's records [tag, count, values...] on rank 0, by tag: values[tag - 1].
std::vector<std::vector<double> > gatherByTag(const std::vector<double> &local, int natoms, MPI_Comm world, int me)
{
  const std::vector<double> all = fdm::gatherToRoot(local, world);
  std::vector<std::vector<double> > byTag(me == 0 ? size_t(natoms) : 0);
  for (size_t k = 0; k + 1 < all.size();) {
    const long tag = std::lround(all[k]);
    const size_t n = size_t(std::lround(all[k + 1]));
    if (tag >= 1 && tag <= natoms) byTag[tag - 1].assign(all.begin() + long(k + 2), all.begin() + long(k + 2 + n));
    k += 2 + n;
  }
  return byTag;
}

}  // namespace

bool FixFdmCouple::checkpointDue() const
{
  const long long every = options_.checkpointEvery;
  return every > 0 && update->ntimestep > 0 && (update->ntimestep % every == 0 || update->ntimestep == update->laststep);
}

void FixFdmCouple::writeCheckpoint()
{
  // every rank: its particles, their contact history; rank 0 adds the fix's own state and writes
  const double t0 = MPI_Wtime();
  FixContactHistoryFdm *history = pair_ ? pair_->contactHistory() : nullptr;
  FixPropertyAtom *wallHistory = pair_ ? pair_->wallHistory() : nullptr;
  const int wallWidth = wallHistory ? PairFdmSubgrid::wallHistoryWidth * int(pair_->walls().size()) : 0;
  // the history of this step is in the neighbour list; LIGGGHTS copies it to the atoms only
  // before atoms migrate: do it now (idempotent, as at every re-neighbouring)
  if (history) history->syncFromNeighbourList();

  std::vector<double> atoms, contacts, walls;
  for (int i = 0; i < atom->nlocal; i++) {
    const double tag = atom->tag[i];
    atoms.insert(atoms.end(), {tag, double(atomWidth)});
    for (int d = 0; d < 3; d++) atoms.push_back(atom->x[i][d]);
    for (int d = 0; d < 3; d++) atoms.push_back(atom->v[i][d]);
    for (int d = 0; d < 3; d++) atoms.push_back(atom->omega[i][d]);
    atoms.push_back(double(atom->image[i]));
    atoms.insert(atoms.end(), {atom->radius[i], atom->rmass[i], atom->density[i], double(atom->type[i])});
    if (history) {
      const std::vector<double> record = history->packAtom(i);
      contacts.insert(contacts.end(), {tag, double(record.size())});
      contacts.insert(contacts.end(), record.begin(), record.end());
    }
    if (wallWidth) {
      walls.insert(walls.end(), {tag, double(wallWidth)});
      for (int k = 0; k < wallWidth; k++) walls.push_back(wallHistory->array_atom[i][k]);
    }
  }
  const auto atomsByTag = gatherByTag(atoms, natoms_, world, comm->me);
  const auto contactsByTag = gatherByTag(contacts, natoms_, world, comm->me);
  const auto wallsByTag = gatherByTag(walls, natoms_, world, comm->me);

  std::string problem;
  if (comm->me == 0) {
    ckpt::ParticleCheckpoint c;
    c.step = update->ntimestep;
    c.lastStep = update->laststep;
    c.natoms = natoms_;
    c.dt = update->dt;
    for (int d = 0; d < 3; d++) {
      c.boxlo[d] = domain->boxlo[d];
      c.boxhi[d] = domain->boxhi[d];
    }
    std::vector<double> &a = c.arrays["atoms"];
    std::vector<double> &lengths = c.arrays["contactHistoryLength"];
    std::vector<double> &records = c.arrays["contactHistory"];
    std::vector<double> &wallValues = c.arrays["wallHistory"];
    for (int t = 0; t < natoms_; t++) {
      a.insert(a.end(), atomsByTag[t].begin(), atomsByTag[t].end());
      if (history) {
        lengths.push_back(double(contactsByTag[t].size()));
        records.insert(records.end(), contactsByTag[t].begin(), contactsByTag[t].end());
      }
      if (wallWidth) wallValues.insert(wallValues.end(), wallsByTag[t].begin(), wallsByTag[t].end());
    }
    // the position update's history (U_n, U_{n-1}, x_n, the planned rates) and the last outputs
    const fdm::CoupledVelocitySolve::Results &r = solve_.results();
    c.arrays["state"] = {plan_.planned ? 1.0 : 0.0, plan_.haveVelocities ? 1.0 : 0.0, double(solve_.lastIterations),
                         solve_.lastResidual, options_.adamsBashforth ? 1.0 : 0.0, options_.gapUpdate ? 1.0 : 0.0,
                         double(wallWidth)};
    c.arrays["currentVelocity"] = plan_.current;
    c.arrays["previousVelocity"] = plan_.previous;
    c.arrays["moveRate"] = plan_.planned ? plan_.rates : std::vector<double>();
    c.arrays["planPositions"] = plan_.planned ? plan_.positions : std::vector<double>();
    c.arrays["solution"] = r.solution;
    c.arrays["hydro"] = r.hydro;
    c.arrays["subgrid"] = r.subgrid;
    c.arrays["fluidStress"] = r.fluidStress;
    c.arrays["stress"] = r.stress;
    // held_drag: the mode (a resume must hold the drag as the run did) and, extrapolated, the last two
    // fluid steps' drag targets (a resumed run extrapolates as the one it continues)
    const fdm::HeldDrag::State &held = heldDrag_.state();
    c.arrays["heldDrag"] = {heldDrag_.extrapolated() ? 1.0 : 0.0, double(held.lastStep), double(held.beforeStep)};
    c.arrays["heldDragLast"] = held.last;
    c.arrays["heldDragBefore"] = held.before;
    // coulomb_solve: a resume must slide its contacts as the run did (docs/contact.md 2c)
    c.arrays["coulombSolve"] = {options_.coulombConsistent ? 1.0 : 0.0};
    const std::string file = std::string(directory) + "/" + prefix + std::to_string((long long) c.step);
    try {
      ::mkdir(directory, 0755);
      ckpt::writeAtomically(file, ckpt::encode(c));
      // the previous one stays until this one is complete, and is kept: the fluid's checkpoint of
      // this step may be the one a kill interrupted (fdmRun --resume takes the newest step both have)
      ckpt::prune(directory, prefix, c.step, 2);
    } catch (const ckpt::CheckpointError &e) {
      problem = std::string("checkpoint of step ") + std::to_string((long long) c.step) + ": " + e.what();
    }
    checkpointSeconds_ += MPI_Wtime() - t0;
  }
  if (!problem.empty()) fail(problem);
  MPI_Barrier(world);
}

void FixFdmCouple::readResumeCheckpoint()
{
  // every rank reads rank 0's bytes of the file; checks it belongs to this scene; sets the time step
  resumeFile_ = session_.resumeFile();
  std::vector<char> bytes;
  std::string problem;
  if (comm->me == 0) {
    try {
      bytes = ckpt::readFile(resumeFile_);
    } catch (const ckpt::CheckpointError &e) {
      problem = e.what();
    }
  }
  long long size = (long long) bytes.size();
  MPI_Bcast(&size, 1, MPI_LONG_LONG, 0, world);
  bytes.resize(size_t(size));
  MPI_Bcast(bytes.data(), int(size), MPI_CHAR, 0, world);
  ckpt::ParticleCheckpoint c;
  if (problem.empty()) {
    try {
      c = ckpt::decode(bytes, resumeFile_);
      c.array("atoms", (long long) atomWidth * c.natoms, resumeFile_);
    } catch (const ckpt::CheckpointError &e) {
      problem = e.what();
    }
  }
  const std::string other = resumeFile_ + " is from another scene: ";
  if (problem.empty() && c.natoms != (long long) atom->natoms)
    problem = other + "it holds " + std::to_string(c.natoms) + " particles, the LIGGGHTS input has " +
              std::to_string((long long) atom->natoms);
  for (int d = 0; d < 3 && problem.empty(); d++)
    if (std::fabs(c.boxlo[d] - domain->boxlo[d]) + std::fabs(c.boxhi[d] - domain->boxhi[d]) >
        1e-12 * (domain->boxhi[d] - domain->boxlo[d]))
      problem = other + "its box spans " + fdm::text::number(c.boxlo[d]) + " .. " + fdm::text::number(c.boxhi[d]) +
                " in " + "xyz"[d] + ", the LIGGGHTS input's " + fdm::text::number(domain->boxlo[d]) + " .. " +
                fdm::text::number(domain->boxhi[d]);
  if (problem.empty() && c.dt != update->dt)
    problem = resumeFile_ + " was written with the time step " + fdm::text::number(c.dt) + " s but the input's is " +
              fdm::text::number(update->dt) + " s: a resumed run must take the same steps";
  // the particles the input created must be those of the checkpoint (radius, density by ID)
  long long firstBad = std::numeric_limits<long long>::max();
  if (problem.empty()) {
    const std::vector<double> &a = c.arrays.at("atoms");
    for (int i = 0; i < atom->nlocal; i++) {
      const double *r = &a[size_t(atomWidth) * (atom->tag[i] - 1)];
      if (r[10] != atom->radius[i] || r[12] != atom->density[i]) firstBad = std::min(firstBad, (long long) atom->tag[i]);
    }
  }
  long long bad = firstBad;
  MPI_Allreduce(&firstBad, &bad, 1, MPI_LONG_LONG, MPI_MIN, world);
  if (problem.empty() && bad != std::numeric_limits<long long>::max()) {
    const double *r = &c.arrays.at("atoms")[size_t(atomWidth) * (bad - 1)];
    problem = other + "particle " + std::to_string(bad) + " has radius " + fdm::text::number(r[10]) + " and density " +
              fdm::text::number(r[12]) + " there but not in the LIGGGHTS input";
  }
  if (problem.empty()) {
    // written before held_drag existed: the drag was held constant
    const auto held = c.arrays.find("heldDrag");
    const bool extrapolated = held != c.arrays.end() && !held->second.empty() && held->second[0] != 0;
    if (extrapolated != heldDrag_.extrapolated())
      problem = resumeFile_ + " was written with held_drag " + (extrapolated ? "extrapolated" : "constant") +
                " but the input has held_drag " + (heldDrag_.extrapolated() ? "extrapolated" : "constant") +
                ": a resumed run must hold the fluid's force between fluid steps as the run it continues";
  }
  if (problem.empty()) {
    // written before coulomb_solve existed: the slides were frozen
    const auto coulomb = c.arrays.find("coulombSolve");
    const bool consistent = coulomb != c.arrays.end() && !coulomb->second.empty() && coulomb->second[0] != 0;
    if (consistent != options_.coulombConsistent)
      problem = resumeFile_ + " was written with coulomb_solve " + (consistent ? "consistent" : "frozen") +
                " but the input has coulomb_solve " + (options_.coulombConsistent ? "consistent" : "frozen") +
                ": a resumed run must slide its contacts as the run it continues (docs/contact.md 2c)";
  }
  if (!problem.empty()) error->all(FLERR, ("fdm/couple: cannot resume: " + problem).c_str());

  update->reset_timestep(bigint(c.step));
  session_.setResumeStep(c.step);
  resumed_ = true;
  resume_.reset(new ckpt::ParticleCheckpoint(std::move(c)));
  if (comm->me == 0 && screen)
    fprintf(screen, "fdm/couple: resuming from %s (step %lld of a run to step %lld)\n", resumeFile_.c_str(),
            resume_->step, resume_->lastStep);
}

void FixFdmCouple::continueDumps()
{
  // a resumed run continues the dumps of the interrupted one (fdmRun --resume cut them at the checkpoint)
  for (int i = 0; i < output->ndump; i++) {
    char append[] = "append", yes[] = "yes";
    char *args[] = {append, yes};
    output->dump[i]->modify_params(2, args);
  }
}

void FixFdmCouple::checkResumedRunLength()
{
  // `run N` instead of `run L upto` would run N steps more: the last step is checked against the
  // checkpoint's, or against -until's where the run was extended on purpose
  const long long until = session_.resumeUntil();
  if (resume_ && until > 0 && update->laststep != until)
    allAgree(comm->me != 0 ? std::string() :
             "resuming at step " + std::to_string(resume_->step) + " from " + resumeFile_ + " to step " +
             std::to_string(until) + " (-until) but this run command ends at step " +
             std::to_string((long long) update->laststep) + ": write it 'run " + std::to_string(until) +
             " upto' (fdmRun --resume --until does; docs/coupling.md)");
  if (resume_ && until == 0 && update->laststep != resume_->lastStep)
    allAgree(comm->me != 0 ? std::string() :
             "resuming at step " + std::to_string(resume_->step) + " from " + resumeFile_ + ": the run it belongs "
             "to ends at step " + std::to_string(resume_->lastStep) + " but this run command ends at step " +
             std::to_string((long long) update->laststep) + ": write it 'run " + std::to_string(resume_->lastStep) +
             " upto' (a resumed input runs to the same last step; fdmRun --resume --until L extends it to L; "
             "docs/coupling.md)");
}

void FixFdmCouple::setup_pre_exchange()
{
  if (resume_) restoreCheckpoint();
}

void FixFdmCouple::restoreCheckpoint()
{
  // every rank, its own atoms (LIGGGHTS then wraps, migrates and lists them); rank 0, the fix's state
  const ckpt::ParticleCheckpoint &c = *resume_;
  const std::vector<double> &a = c.arrays.at("atoms");
  const std::vector<double> &state = c.array("state", 7, resumeFile_);
  const int wallWidth = int(state[6]);
  FixContactHistoryFdm *history = pair_ ? pair_->contactHistory() : nullptr;
  FixPropertyAtom *wallHistory = pair_ ? pair_->wallHistory() : nullptr;
  const std::vector<double> &lengths = c.arrays.at("contactHistoryLength");
  if ((history != nullptr) != !lengths.empty() || (wallHistory ? PairFdmSubgrid::wallHistoryWidth * int(pair_->walls().size()) : 0) != wallWidth)
    error->all(FLERR, ("fdm/couple: cannot resume: " + resumeFile_ + " was written " +
                       (lengths.empty() ? "without" : "with") + " contact and with " + std::to_string(wallWidth / PairFdmSubgrid::wallHistoryWidth) +
                       " walls, the input's pair_style differs").c_str());
  std::vector<size_t> offset(size_t(c.natoms) + 1, 0);
  for (size_t t = 0; t < lengths.size(); t++) offset[t + 1] = offset[t] + size_t(lengths[t]);
  for (int i = 0; i < atom->nlocal; i++) {
    const long t = atom->tag[i] - 1;
    const double *r = &a[size_t(atomWidth) * t];
    for (int d = 0; d < 3; d++) {
      atom->x[i][d] = r[d];
      atom->v[i][d] = r[3 + d];
      atom->omega[i][d] = r[6 + d];
    }
    atom->image[i] = tagint(std::llround(r[9]));
    if (history) history->restoreAtom(i, &c.arrays.at("contactHistory")[offset[t]]);
    for (int k = 0; k < wallWidth; k++) wallHistory->array_atom[i][k] = c.arrays.at("wallHistory")[size_t(wallWidth) * t + k];
  }
  // a checkpoint's step is always one the fluid solved (fluidStepDue): the next fluid step spans from it
  schedule_.solved(c.step);
  plan_.planned = state[0] != 0;
  plan_.haveVelocities = state[1] != 0;
  solve_.lastIterations = int(state[2]);
  solve_.lastResidual = state[3];
  plan_.current = c.arrays.at("currentVelocity");
  plan_.previous = c.arrays.at("previousVelocity");
  plan_.rates = c.arrays.at("moveRate");
  plan_.positions = c.arrays.at("planPositions");
  fdm::CoupledVelocitySolve::Results &r = solve_.results();
  r.solution = c.arrays.at("solution");
  r.hydro = c.arrays.at("hydro");
  r.subgrid = c.arrays.at("subgrid");
  r.fluidStress = c.arrays.at("fluidStress");
  r.stress = c.arrays.at("stress");
  const auto held = c.arrays.find("heldDrag");
  if (held != c.arrays.end() && held->second.size() == 3) {
    fdm::HeldDrag::State state;
    state.lastStep = (long long) held->second[1];
    state.beforeStep = (long long) held->second[2];
    state.last = c.arrays.at("heldDragLast");
    state.before = c.arrays.at("heldDragBefore");
    heldDrag_.restore(state);
  }
}
