// pair_style fdm/subgrid: sub-grid lubrication blocks and frictional contact (see pair_fdm_subgrid.h,
// docs/dem.md).
#include "pair_fdm_subgrid.h"

#include "contact_springs.h"
#include "coupling_session.h"
#include "fix_contact_history_fdm.h"
#include "particle_velocity_system.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "fix_property_atom.h"
#include "force.h"
#include "memory.h"
#include "modify.h"
#include "neigh_list.h"
#include "neigh_request.h"
#include "neighbor.h"
#include "update.h"

#include "fdm/resistance/blocks.hpp"
#include "fdm/resistance/subgrid_calibration.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>

using namespace LAMMPS_NS;
namespace res = fdm::resistance;

namespace {

std::string fmt(double x)
{
  std::ostringstream os;
  os.precision(6);
  os << x;
  return os.str();
}
}  // namespace

PairFdmSubgrid::PairFdmSubgrid(LAMMPS *lmp) :
  Pair(lmp), computeflag(0), viscosity_(0),
  meshSize_(0), rangeGap_(0), rmin_(0), rmax_(0), distanceFactor_(1.0), history_(nullptr), wallHistory_(nullptr),
  contactStressRequested_(false), nmaxStress_(0), contactStress_(nullptr), contactsLast_(0), reported_(false),
  checkedTimeStep_(0)
{
  single_enable = 0;
  no_virial_fdotr_compute = 1;
  applySettings(fdm::SubgridOptions());
}

void PairFdmSubgrid::applySettings(const fdm::SubgridOptions &o)
{
  // A pair_style line given again (LAMMPS calls settings() on the same object) starts from the defaults
  // too: what it does not say is not kept from the earlier line, and the sub-grid model is built anew.
  options_ = o;
  model_.reset();
  wallModel_.reset();
  calibration_.reset();
  uncalibratedTangential_.clear();
  reported_ = false;
}

PairFdmSubgrid::~PairFdmSubgrid()
{
  if (history_) modify->delete_fix("contacthistory");
  if (wallHistory_) modify->delete_fix("fdm_wall_history");
  memory->destroy(contactStress_);
  if (allocated) {
    memory->destroy(setflag);
    memory->destroy(cutsq);
  }
}

void PairFdmSubgrid::allocate()
{
  allocated = 1;
  const int n = atom->ntypes;
  memory->create(setflag, n + 1, n + 1, "pair:setflag");
  for (int i = 1; i <= n; i++)
    for (int j = i; j <= n; j++) setflag[i][j] = 0;
  memory->create(cutsq, n + 1, n + 1, "pair:cutsq");
}

void PairFdmSubgrid::settings(int narg, char **arg)
{
  try {
    applySettings(fdm::parseSubgridOptions(std::vector<std::string>(arg, arg + narg)));
  } catch (const fdm::KeywordError &e) {
    error->all(FLERR, e.what());
  }
}

void PairFdmSubgrid::coeff(int narg, char **arg)
{
  if (narg != 2) error->all(FLERR, "pair_coeff for fdm/subgrid: pair_coeff * * (the parameters are in pair_style)");
  if (!allocated) allocate();
  int ilo, ihi, jlo, jhi;
  force->bounds(arg[0], atom->ntypes, ilo, ihi);
  force->bounds(arg[1], atom->ntypes, jlo, jhi);
  for (int i = ilo; i <= ihi; i++)
    for (int j = std::max(jlo, i); j <= jhi; j++) setflag[i][j] = 1;
}

std::string PairFdmSubgrid::wallName(const Wall &w) const { return fdm::faceName(2 * w.axis + w.side); }

void PairFdmSubgrid::fluidParameters()
{
  // The viscosity and the mesh size are the fluid case's, from the coupling session's handshake
  // (it connects now if this is the first run). Without fix fdm/couple there is no fluid: contact only.
  CouplingSession &session = CouplingSession::instance();
  if (!session.attached()) {
    model_.reset();
    wallModel_.reset();
    return;
  }
  session.ensureConnected(lmp);
  viscosity_ = session.viscosity();
  meshSize_ = session.meshSize();
  // Two cut-offs: the solver resolves a wall gap less well than a pair gap of the same width
  // (measured with cases/pairSqueeze and cases/wallSqueeze, docs/validation.md)
  if (options_.calibrated && options_.lubrication && !model_) {
    // the default: the functions measured with the solver itself (Appendix B; subgrid_calibration.hpp):
    // the squeeze functions and, where tabulated, the tangential pair and wall functions
    const std::string path =
        options_.calibrationFile.empty() ? res::SubgridCalibration::defaultPath() : options_.calibrationFile;
    try {
      calibration_.reset(new res::SubgridCalibration(res::SubgridCalibration::read(path)));
      model_ = std::make_shared<res::CalibratedSubgridModel>(*calibration_, meshSize_, options_.cutoffCells,
                                                             options_.wallCutoffCells);
      wallModel_ = model_;   // it holds both cut-offs
    } catch (const std::exception &e) {
      session.abandon(std::string("fdmDEM: pair fdm/subgrid: ") + e.what());
      error->all(FLERR, (std::string("pair fdm/subgrid: ") + e.what()).c_str());
    }
  }
  if (!model_) model_.reset(new res::CutoffSubgridModel(meshSize_, options_.cutoffCells));
  if (!wallModel_) wallModel_.reset(new res::CutoffSubgridModel(meshSize_, options_.wallCutoffCells));

  // The walls declared here are the fluid case's no-slip walls, with the same velocities.
  std::string problem;
  if (!session.hasFluid()) return;  // transport none: the walls are the ones declared here
  for (int face = 0; face < 6 && problem.empty(); face++) {
    int kind;
    double velocity[3];
    session.fluidFace(face, kind, velocity);
    const Wall *declared = nullptr;
    for (const Wall &w : options_.walls)
      if (2 * w.axis + w.side == face) declared = &w;
    const std::string u = "(" + fmt(velocity[0]) + " " + fmt(velocity[1]) + " " + fmt(velocity[2]) + ")";
    if (kind == CouplingSession::faceWall && !declared) {
      problem = std::string("the fluid case has a no-slip wall on ") + fdm::faceName(face) + " moving at " + u +
                " m/s, not declared to pair_style fdm/subgrid: add 'wall " + fdm::faceName(face) + " " + fmt(velocity[0]) +
                " " + fmt(velocity[1]) + " " + fmt(velocity[2]) + "'";
    } else if (declared && kind != CouplingSession::faceWall) {
      problem = std::string("pair_style fdm/subgrid declares a wall on ") + fdm::faceName(face) +
                " but the fluid case has " + CouplingSession::faceKindName(kind) + " there";
    } else if (declared) {
      double scale = 0, diff = 0;
      for (int d = 0; d < 3; d++) {
        scale = std::max(scale, std::max(std::fabs(velocity[d]), std::fabs(declared->velocity[d])));
        diff = std::max(diff, std::fabs(velocity[d] - declared->velocity[d]));
      }
      if (diff > 1e-9 * scale)
        problem = std::string("wall ") + fdm::faceName(face) + ": pair_style fdm/subgrid says it moves at (" +
                  fmt(declared->velocity[0]) + " " + fmt(declared->velocity[1]) + " " + fmt(declared->velocity[2]) +
                  ") m/s but the fluid case (0/U) at " + u + " m/s";
    }
  }
  if (!problem.empty()) {
    // tell the fluid solver why (it would otherwise only learn that fdmDEM stopped)
    session.abandon("fdmDEM: pair fdm/subgrid: " + problem);
    error->all(FLERR, ("pair fdm/subgrid: " + problem).c_str());
  }
}

void PairFdmSubgrid::checkCalibration()
{
  // Every radius pair of the scene (and every radius against the walls) must be in the table: a
  // pair outside it would have no measured correction (an error, naming it, rather than a silent
  // fallback). The neighbour range grows to the calibrated squeeze range.
  // the distinct radii of the scene over all ranks, with how many particles have each (a radius
  // held by one particle has no pair with itself)
  std::map<double, double> local;
  for (int i = 0; i < atom->nlocal; i++) local[atom->radius[i]] += 1;
  int n = int(local.size()), nmax = 0;
  MPI_Allreduce(&n, &nmax, 1, MPI_INT, MPI_MAX, world);
  std::vector<double> mine(2 * size_t(nmax), 0.0), all(2 * size_t(nmax) * comm->nprocs, 0.0);
  size_t k = 0;
  for (const auto &rc : local) {
    mine[k++] = rc.first;
    mine[k++] = rc.second;
  }
  MPI_Allgather(mine.data(), 2 * nmax, MPI_DOUBLE, all.data(), 2 * nmax, MPI_DOUBLE, world);
  std::map<double, double> counts;
  for (size_t m = 0; m + 1 < all.size(); m += 2)
    if (all[m] > 0) counts[all[m]] += all[m + 1];
  std::vector<double> radii;
  for (const auto &rc : counts) radii.push_back(rc.first);
  auto fail = [this](const std::string &problem) {
    CouplingSession::instance().abandon("fdmDEM: pair fdm/subgrid: " + problem);  // the fluid is told why
    error->all(FLERR, ("pair fdm/subgrid: " + problem).c_str());
  };
  if (radii.size() > 16)
    fail("model calibrated: " + fmt(double(radii.size())) + " different radii; the calibration serves a few sizes "
         "(docs/dem.md)");
  for (size_t a = 0; a < radii.size(); a++) {
    for (size_t b = a; b < radii.size(); b++) {
      if (b == a && counts[radii[a]] < 2) continue;
      if (!calibration_->coversPair(radii[a], radii[b], meshSize_))
        fail("model calibrated: no squeeze calibration for radii " + fmt(radii[a]) + " and " + fmt(radii[b]) +
             " at mesh size " + fmt(meshSize_) + " (a1/Delta " + fmt(radii[a] / meshSize_) + ", a2/a1 " +
             fmt(radii[b] / radii[a]) + ") in " + calibration_->path() + ", which has " + calibration_->coverage() +
             ": add it (python3 -m fdmsubgrid.calibration) or use 'model cutoff'");
      rangeGap_ = std::max(rangeGap_, calibration_->pairRange(radii[a], radii[b], meshSize_) * rmin_);
      double K[4];
      if (!calibration_->pairInternalCorrection(radii[a], radii[b], meshSize_, 0.1, K))
        uncalibratedTangential_ += (uncalibratedTangential_.empty() ? "" : ", ") + fmt(radii[a]) + "-" + fmt(radii[b]);
    }
    if (!options_.walls.empty()) {
      if (!calibration_->coversWall(radii[a], meshSize_))
        fail("model calibrated: no wall squeeze calibration for radius " + fmt(radii[a]) + " at mesh size " +
             fmt(meshSize_) + " (a/Delta " + fmt(radii[a] / meshSize_) + ") in " + calibration_->path() +
             ", which has " + calibration_->coverage() + ": add it or use 'model cutoff'");
    }
  }
}

void PairFdmSubgrid::init_style()
{
  if (!atom->sphere_flag) error->all(FLERR, "pair_style fdm/subgrid requires atom_style sphere");
  if (force->newton_pair) error->all(FLERR, "pair_style fdm/subgrid requires newton off");
  if (options_.hr > 0 && !comm->ghost_velocity)
    error->all(FLERR, "pair_style fdm/subgrid with contact needs ghost velocities: 'communicate single vel yes'");
  for (const Wall &w : options_.walls)
    if (domain->periodicity[w.axis])
      error->all(FLERR, ("pair_style fdm/subgrid: wall " + wallName(w) + " on a periodic boundary: make the " +
                         std::string(1, "xyz"[w.axis]) + " boundary fixed (boundary ... f ...)").c_str());

  fluidParameters();
  // A pair missing from the list for a step has no lubrication and no contact at all: rebuild as
  // soon as any particle has moved half the skin (LIGGGHTS's default delays the check 10 steps).
  if ((neighbor->delay > 0 || neighbor->every > 1 || !neighbor->dist_check) && comm->me == 0)
    error->warning(FLERR, "pair_style fdm/subgrid: close pairs can be missed between neighbour-list builds: "
                          "use 'neigh_modify delay 0 every 1 check yes'");

  double rmin = 1e300, rmax = 0;
  for (int i = 0; i < atom->nlocal; i++) {
    rmin = std::min(rmin, atom->radius[i]);
    rmax = std::max(rmax, atom->radius[i]);
  }
  MPI_Allreduce(&rmin, &rmin_, 1, MPI_DOUBLE, MPI_MIN, world);
  MPI_Allreduce(&rmax, &rmax_, 1, MPI_DOUBLE, MPI_MAX, world);
  if (!(rmax_ > 0)) error->all(FLERR, "pair_style fdm/subgrid: no particles (or no positive radius) to interact");
  checkResolution();

  // Pairs up to this surface gap must be in the neighbour list, and keep their contact history:
  // LIGGGHTS's granular list includes r < (r_i + r_j) * contact_distance_factor (+ skin).
  rangeGap_ = std::max(options_.hr, lubricationActive() ? options_.cutoffCells * meshSize_ : 0.0);
  if (lubricationActive() && calibration_) checkCalibration();
  distanceFactor_ = 1.0 + 1.000001 * rangeGap_ / (2.0 * rmin_);
  if (rangeGap_ > 0) neighbor->register_contact_dist_factor(distanceFactor_);

  if (contactActive() && !history_) {
    const char *args[] = {"contacthistory", "all", "contacthistory", "3", "shearx", "1", "sheary", "1", "shearz", "1"};
    modify->add_fix(10, const_cast<char **>(args));
    history_ = dynamic_cast<FixContactHistoryFdm *>(modify->fix[modify->find_fix("contacthistory")]);
    if (!history_) error->all(FLERR, "pair fdm/subgrid: fix contacthistory is not the fdmDEM one (FixContactHistoryFdm)");
  }
  if (contactActive() && !options_.walls.empty() && !wallHistory_) {
    // tangential spring elongation against each wall, per atom: migrates with the atom
    std::vector<std::string> args = {"fdm_wall_history", "all", "property/atom", "fdmWallShear", "vector", "yes", "no", "no"};
    for (size_t k = 0; k < wallHistoryWidth * options_.walls.size(); k++) args.push_back("0");
    std::vector<char *> argv;
    for (std::string &s : args) argv.push_back(&s[0]);
    wallHistory_ = modify->add_fix_property_atom(int(argv.size()), argv.data(), "pair fdm/subgrid");
  }

  int request = neighbor->request(this);
  neighbor->requests[request]->half = 0;
  neighbor->requests[request]->gran = 1;
  if (contactActive()) {
    request = neighbor->request(this);
    neighbor->requests[request]->id = 1;
    neighbor->requests[request]->half = 0;
    neighbor->requests[request]->granhistory = 1;
    neighbor->requests[request]->dnum = 3;
  }

  if (comm->me == 0 && !reported_) {
    // Say what is active in this scene: a correction nobody can see is a correction nobody trusts.
    std::string line = "pair fdm/subgrid: ";
    if (lubricationActive())
      line += "sub-grid lubrication ON (pairs within a surface gap of " +
              (calibration_ ? "up to " + fmt(rangeGap_) + " m (the calibrated squeeze, sliding, rolling and twist" +
                                  (uncalibratedTangential_.empty() ? std::string()
                                   : " except for radii " + uncalibratedTangential_ + ", whose are the cut-off model's") +
                                  "; the stresslets within " + fmt(options_.cutoffCells) + " mesh cells)"
                            : fmt(options_.cutoffCells) + " mesh cells = " +
                                  fmt(options_.cutoffCells * meshSize_) + " m") +
              (options_.walls.empty() ? std::string()
               : calibration_ ? ", walls within a surface gap of up to " + fmt(wallModel_->wallRange(rmax_) * rmax_) +
                                    " m (eps = " + fmt(wallModel_->wallRange(rmax_)) + ", the calibrated wall functions)"
                              : ", walls within " + fmt(options_.wallCutoffCells) + " mesh cells = " +
                                    fmt(options_.wallCutoffCells * meshSize_) + " m") + "; viscosity " +
              fmt(viscosity_) + " Pa s; " + model_->describe() + ")";
    else
      line += std::string("sub-grid lubrication OFF (") + (model_ || !options_.lubrication ? "lubrication no" :
              "no fix fdm/couple: no fluid") + ")";
    if (options_.walls.empty()) line += "; no walls (no wall search)";
    for (const Wall &w : options_.walls)
      line += "; wall " + wallName(w) + " at velocity (" + fmt(w.velocity[0]) + " " + fmt(w.velocity[1]) + " " +
              fmt(w.velocity[2]) + ")";
    if (contactActive())
      line += "; contact ON (kn " + fmt(options_.kn) + " N/m, kt " + fmt(options_.kt) + " N/m, mu_s " +
              fmt(options_.mu) + ", h_r " + fmt(options_.hr) +
              " m" + (options_.walls.empty() ? "" : ", also with the walls") + "; springs " +
              (options_.implicitContact ? "implicit in Eq. 31" : "explicit") + ")";
    else
      line += "; contact OFF (h_r = 0: no contact search)";
    line += "\n";
    if (screen) fputs(line.c_str(), screen);
    if (logfile) fputs(line.c_str(), logfile);
    reported_ = true;
  }
}

void PairFdmSubgrid::checkResolution()
{
  // The cut-off model subtracts the theory at xi_c = k Delta/a: below a/Delta = k/0.37 (1.76 for pairs
  // at k = 0.65, 2.03 for walls at 0.75) xi_c passes 0.37, where the twist resistance of the theory
  // stops growing towards contact and the block is clipped (docs/resistance.md, "Dissipation
  // safeguard"); the model was measured for a/Delta 2 ... 20 and validated at 4 and 5.
  if (!lubricationActive() || comm->me != 0 || reported_) return;
  const double smallest = rmin_ / meshSize_, largest = rmax_ / meshSize_;
  const double lowest = 2.0, highest = 20.0;
  if (smallest < lowest * (1 - 1e-9) || largest > highest * (1 + 1e-9))
    error->warning(FLERR, ("pair_style fdm/subgrid: particle radius over mesh size a/Delta from " + fmt(smallest) +
                           " to " + fmt(largest) + " (radii " + fmt(rmin_) + " .. " + fmt(rmax_) + " m, Delta " +
                           fmt(meshSize_) + " m) is outside the range the cut-off sub-grid model covers, a/Delta " +
                           fmt(lowest) + " .. " + fmt(highest) + " (docs/dem.md): " +
                           (smallest < lowest * (1 - 1e-9) ? "the flow between the particles is not resolved down to the "
                                                "cut-off gap, the corrections are not meaningful"
                                              : "measured up to 20 only")).c_str());
}

void PairFdmSubgrid::pairResistance(double a, double h, double &normal, double &slip) const
{
  // Two equal free spheres along x: translation and rotation resistances (Stokes drag of each sphere
  // plus the sub-grid pair block). Normal: equal and opposite forces along the line of centres over
  // the closing speed. Slip: equal and opposite tangential forces at the contact points (with their
  // moments) over the slip speed of the contact points (Resistance.zeta_pair_slip in
  // cases/contactTuning, docs/contact.md 3c).
  typedef Eigen::Matrix<double, 12, 12> Matrix12;
  typedef Eigen::Matrix<double, 12, 1> Vector12;
  const double pi = 3.14159265358979323846, eta = viscosity_;
  Matrix12 M = Matrix12::Zero();
  for (int k = 0; k < 3; k++) {
    M(k, k) = M(6 + k, 6 + k) = 6 * pi * eta * a;
    M(3 + k, 3 + k) = M(9 + k, 9 + k) = 8 * pi * eta * a * a * a;
  }
  res::PairBlock block;
  const double x1[3] = {0, 0, 0}, x2[3] = {2 * a + h, 0, 0};
  if (lubricationActive() && res::subgridPairBlock(*model_, x1, x2, a, a, eta, block))
    for (int r = 0; r < 12; r++)
      for (int c = 0; c < 12; c++) M(r, c) += block.R[r][c];
  const Eigen::FullPivLU<Matrix12> lu(M);
  Vector12 load = Vector12::Zero();
  load(0) = 1;    // sphere 1 pushed towards sphere 2 (+x), sphere 2 towards 1
  load(6) = -1;
  Vector12 u = lu.solve(load);
  normal = 1.0 / (u(0) - u(6));
  // unit force along +y at the contact points (a, 0, 0) of sphere 1 and (-a, 0, 0) relative to sphere
  // 2's centre, opposite: torques a e_z on both
  // (the contact point in the middle of the gap, lever arms l = a + h/2, as the contact law has them)
  const double l = a + 0.5 * h;
  load.setZero();
  load(1) = 1;
  load(5) = l;
  load(7) = -1;
  load(11) = l;
  u = lu.solve(load);
  // slip of the contact points along y: (u1 + w1 x l e_x) - (u2 + w2 x (-l e_x))
  slip = 1.0 / ((u(1) + l * u(5)) - (u(7) - l * u(11)));
}

void PairFdmSubgrid::wallResistance(double a, double h, double &normal, double &slip) const
{
  // A sphere at gap h from a wall below it (normal -y into the wall): pushed onto it, and pulled along
  // x at its contact point (0, -a, 0).
  typedef Eigen::Matrix<double, 6, 6> Matrix6;
  typedef Eigen::Matrix<double, 6, 1> Vector6;
  const double pi = 3.14159265358979323846, eta = viscosity_;
  Matrix6 M = Matrix6::Zero();
  for (int k = 0; k < 3; k++) {
    M(k, k) = 6 * pi * eta * a;
    M(3 + k, 3 + k) = 8 * pi * eta * a * a * a;
  }
  res::WallBlock block;
  const double x[3] = {0, 0, 0}, wallPoint[3] = {0, -(a + h), 0}, intoWall[3] = {0, -1, 0};
  if (lubricationActive() && res::subgridWallBlock(*wallModel_, x, a, wallPoint, intoWall, eta, block))
    for (int r = 0; r < 6; r++)
      for (int c = 0; c < 6; c++) M(r, c) += block.R[r][c];
  const Eigen::FullPivLU<Matrix6> lu(M);
  Vector6 load = Vector6::Zero();
  load(1) = -1;
  Vector6 u = lu.solve(load);
  normal = -1.0 / u(1);
  // force +x at (0, -a, 0): torque (-a e_y) x e_x = a e_z; contact point velocity u + w x (-a e_y)
  load.setZero();
  load(0) = 1;
  load(5) = a;
  u = lu.solve(load);
  slip = 1.0 / (u(0) + a * u(5));
}

void PairFdmSubgrid::checkTimeStep(double dt, bool adamsBashforth)
{
  // contact_integration explicit (docs/contact.md 3c): an explicit spring k against the implicit resistance zeta of its mode is
  // stable for r = dt k/zeta < 1 (ab2) or 2 (euler). zeta grows as the gap closes, so it is smallest
  // at the contact gap h_r (where a contact starts) and largest at h = 0 (the lubrication is frozen at
  // 1e-5 a): a step beyond the limit at h_r is stable only for contacts pressed deeper (a warning),
  // beyond the limit at h = 0 for no contact at all (an error, unless unstable_step warn).
  // The smallest particles have the smallest resistances; with lubrication the run does not blow
  // up but its contacts are wrong (limit cycles, overlaps pinned by the frozen lubrication).
  if (!contactActive() || !(viscosity_ > 0) || dt == checkedTimeStep_) return;
  checkedTimeStep_ = dt;
  const double factor = adamsBashforth ? 1.0 : 2.0;
  struct Mode {
    std::string name;
    double k, zetaContact, zetaTouching;
  };
  std::vector<Mode> modes;
  const double a = rmin_;
  // with mu_s = 0 the tangential force is capped at 0: the spring never acts
  const bool tangentialSpring = options_.kt > 0 && options_.mu > 0;
  if (atom->natoms > 1) {
    double n0, s0, n1, s1;
    pairResistance(a, options_.hr, n0, s0);
    pairResistance(a, 0.0, n1, s1);
    modes.push_back({"normal spring of two spheres", options_.kn, n0, n1});
    if (tangentialSpring) modes.push_back({"tangential spring of two spheres", options_.kt, s0, s1});
  }
  if (!options_.walls.empty()) {
    double n0, s0, n1, s1;
    wallResistance(a, options_.hr, n0, s0);
    wallResistance(a, 0.0, n1, s1);
    modes.push_back({"normal spring of a sphere on a wall", options_.kn, n0, n1});
    if (tangentialSpring) modes.push_back({"tangential spring of a sphere on a wall", options_.kt, s0, s1});
  }
  if (modes.empty()) return;
  const Mode *worst = &modes[0];
  for (const Mode &m : modes)
    if (m.zetaContact / m.k < worst->zetaContact / worst->k) worst = &m;
  const double limit = factor * worst->zetaContact / worst->k;
  if (dt <= limit) return;
  if (options_.implicitContact) {
    // implicit springs (docs/contact.md 2b, Eq. C4): no stability limit from them; say how far
    // beyond the explicit limit the step is (the contacts then settle within a few steps)
    if (comm->me == 0) {
      const std::string line = "pair fdm/subgrid: time step " + fmt(dt) + " s is " + fmt(dt / limit) + " times the "
                               "explicit springs' stability limit " + fmt(limit) + " s (the " + worst->name +
                               " at the contact gap h_r): stable with the implicit springs (contact_integration "
                               "implicit; docs/contact.md 3c), the contact relaxation zeta/k is shorter than a step\n";
      if (screen) fputs(line.c_str(), screen);
      if (logfile) fputs(line.c_str(), logfile);
    }
    return;
  }
  double limitTouching = 1e300;
  const Mode *never = nullptr;
  for (const Mode &m : modes)
    if (factor * m.zetaTouching / m.k < limitTouching) {
      limitTouching = factor * m.zetaTouching / m.k;
      never = &m;
    }
  const std::string how = "(docs/contact.md 3c: dt k/zeta < " + fmt(factor) + " with " +
                          (adamsBashforth ? "integrator ab2" : "integrator euler") + "; zeta the resistance of the "
                          "mode, Stokes drag" + (lubricationActive() ? " + sub-grid lubrication" : "") +
                          ", for the smallest spheres, a = " + fmt(a) + " m, viscosity " + fmt(viscosity_) + " Pa s)";
  if (dt > limitTouching) {
    const std::string message = "pair_style fdm/subgrid: time step " + fmt(dt) + " s is beyond the stability limit of "
                                "the contact springs at every gap: the " + never->name + " (k " + fmt(never->k) +
                                " N/m) needs dt < " + fmt(limitTouching) + " s even at zero gap (zeta " +
                                fmt(never->zetaTouching) + " N s/m), and dt < " + fmt(limit) + " s at the contact gap "
                                "h_r = " + fmt(options_.hr) + " m (the " + worst->name + ", zeta " +
                                fmt(worst->zetaContact) +
                                " N s/m) " + how;
    if (options_.unstableStepIsError) {
      CouplingSession &session = CouplingSession::instance();
      if (session.connected()) session.abandon("fdmDEM: " + message);
      error->all(FLERR, (message + "; 'unstable_step warn' to run anyway").c_str());
    }
    if (comm->me == 0) error->warning(FLERR, message.c_str());
    return;
  }
  if (comm->me == 0)
    error->warning(FLERR, ("pair_style fdm/subgrid: time step " + fmt(dt) + " s is beyond the stability limit " +
                           fmt(limit) + " s of the " + worst->name + " (k " + fmt(worst->k) + " N/m, zeta " +
                           fmt(worst->zetaContact) + " N s/m at the contact gap h_r = " + fmt(options_.hr) + " m) " +
                           how +
                           ": stable only for contacts pressed deeper into the roughness layer (zeta grows as the "
                           "gap closes); an unstable contact shows no NaN, only wrong gaps and forces").c_str());
}

void PairFdmSubgrid::init_list(int id, NeighList *ptr)
{
  if (id == 0) list = ptr;
  else if (id == 1) listgranhistory = ptr;
}

double PairFdmSubgrid::init_one(int, int)
{
  // the ghost cut-off: the largest centre distance at which two particles interact
  return 2.0 * rmax_ * distanceFactor_;
}

void *PairFdmSubgrid::extract(const char *name, int &dim)
{
  dim = 0;
  if (std::strcmp(name, "computeflag") == 0) return &computeflag;
  return nullptr;
}

void PairFdmSubgrid::compute(int eflag, int vflag)
{
  if (eflag || vflag) ev_setup(eflag, vflag);
  else evflag = vflag_fdotr = 0;
  computeflag = 1;
  contactsLast_ = 0;
  contacts_.clear();
  wallContactLoads_.assign(3 * options_.walls.size(), 0.0);
  deepest_ = Overlap();
  if (contactStressRequested_) {
    if (atom->nmax > nmaxStress_) {
      nmaxStress_ = atom->nmax;
      memory->destroy(contactStress_);
      memory->create(contactStress_, nmaxStress_, 6, "pair:fdm/subgrid:contactStress");
    }
    for (int i = 0; i < atom->nlocal; i++)
      for (int c = 0; c < 6; c++) contactStress_[i][c] = 0.0;
  }
  if (!contactActive()) return;  // lubrication is no force here: it is R^SG in Eq. (31)
  const auto start = std::chrono::steady_clock::now();
  contactForces();
  if (!options_.walls.empty()) wallContactForces();
  contactSeconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double PairFdmSubgrid::takeContactSeconds()
{
  const double seconds = contactSeconds_;
  contactSeconds_ = 0;
  return seconds;
}

void PairFdmSubgrid::addContactStress(int i, const double force[3], const double branch[3], double weight)
{
  // Eq. (52): S^c_p += 1/2 a_p/(a_p + a_p') (F ⊗ x + x ⊗ F), x from p to the partner
  static const int comp[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
  for (int c = 0; c < 6; c++) {
    const int a = comp[c][0], b = comp[c][1];
    contactStress_[i][c] += 0.5 * weight * (force[a] * branch[b] + branch[a] * force[b]);
  }
}

FixContactHistoryFdm *PairFdmSubgrid::contactHistory() const
{
  return dynamic_cast<FixContactHistoryFdm *>(history_);
}

void PairFdmSubgrid::contactLaw(const double n[3], double normalForce, const double vr[3], double dt, double shear[3],
                                double force[3], double nxft[3]) const
{
  // The tangential spring and the Coulomb cap shared by pair and wall contacts: the elongation
  // accumulates the tangential relative velocity of the contact points over dt (0 in setup force
  // evaluations, which do not advance time and hand a copy of it), stays in the tangent plane, and kt |shear| is capped
  // at mu_s |F_n| (sliding: the spring is reset to the cap). Returns the total force on the
  // particle on the n side, and n x F_t for the torques.
  const double vn = vr[0] * n[0] + vr[1] * n[1] + vr[2] * n[2];
  for (int d = 0; d < 3; d++) shear[d] += (vr[d] - vn * n[d]) * dt;
  const double sn = shear[0] * n[0] + shear[1] * n[1] + shear[2] * n[2];
  for (int d = 0; d < 3; d++) shear[d] -= sn * n[d];
  double ft[3] = {-options_.kt * shear[0], -options_.kt * shear[1], -options_.kt * shear[2]};
  const double ftNorm = std::sqrt(ft[0] * ft[0] + ft[1] * ft[1] + ft[2] * ft[2]);
  const double ftMax = options_.mu * normalForce;
  if (ftNorm > ftMax) {
    const double scale = ftMax / ftNorm;
    for (int d = 0; d < 3; d++) {
      ft[d] *= scale;
      if (options_.kt > 0) shear[d] = -ft[d] / options_.kt;
    }
  }
  for (int d = 0; d < 3; d++) force[d] = normalForce * n[d] + ft[d];
  nxft[0] = n[1] * ft[2] - n[2] * ft[1];
  nxft[1] = n[2] * ft[0] - n[0] * ft[2];
  nxft[2] = n[0] * ft[1] - n[1] * ft[0];
}

void PairFdmSubgrid::contactForces()
{
  // Section 6 (Gallier et al. 2014): contact once the surface gap is below h_r; linear normal
  // spring kn (h_r - gap); tangential spring kt on the elongation accumulated during the contact
  // (kept by LIGGGHTS's contact history), capped at mu_s |F_n| (no static/dynamic distinction).
  double **x = atom->x, **v = atom->v, **f = atom->f, **omega = atom->omega, **torque = atom->torque;
  const double *radius = atom->radius;
  const int nlocal = atom->nlocal;
  const double dt = update->setupflag ? 0.0 : update->dt;  // setup force evaluations do not advance time
  int **firstTouch = listgranhistory->firstneigh;
  double **firstShear = listgranhistory->firstdouble;

  for (int ii = 0; ii < list->inum; ii++) {
    const int i = list->ilist[ii];
    const int *jlist = list->firstneigh[i];
    int *touch = firstTouch[i];
    double *allShear = firstShear[i];
    for (int jj = 0; jj < list->numneigh[i]; jj++) {
      const int j = jlist[jj] & NEIGHMASK;
      double *shear = &allShear[3 * jj];
      const double del[3] = {x[i][0] - x[j][0], x[i][1] - x[j][1], x[i][2] - x[j][2]};
      const double rsq = del[0] * del[0] + del[1] * del[1] + del[2] * del[2];
      const double reach = radius[i] + radius[j] + options_.hr;
      if (rsq >= reach * reach) {  // apart: the contact and its history end now
        touch[jj] = 0;
        shear[0] = shear[1] = shear[2] = 0.0;
        continue;
      }
      // with implicit springs a contact's tangential spring starts loading on the step after it
      // formed: the move that closed the gap was made without the spring in Eq. (31), and loading
      // it with that move's slip would be an explicit kick k_t dt v_t, unstable once k_t dt/zeta_t
      // exceeds a few (docs/contact.md 2b, "New contacts")
      const bool fresh = !touch[jj];
      touch[jj] = 1;
      const double r = std::sqrt(rsq);
      const double n[3] = {del[0] / r, del[1] / r, del[2] / r};  // from j to i
      const double normalForce = options_.kn * (reach - r);
      // the contact point in the middle of the gap: lever arms l = a + h/2 (l_i + l_j = r), so that a
      // rigid motion of the pair does not slip the contact points (docs/contact.md 2, Eq. C1)
      const double halfGap = 0.5 * (r - radius[i] - radius[j]);
      const double leverI = radius[i] + halfGap, leverJ = radius[j] + halfGap;
      const double depth = -2 * halfGap / std::min(radius[i], radius[j]);
      if (depth > deepest_.depth) {
        deepest_.depth = depth;
        deepest_.gap = 2 * halfGap;
        deepest_.tagI = atom->tag[i];
        deepest_.tagJ = atom->tag[j];
      }
      // relative velocity of the contact points: v_i - v_j - (l_i w_i + l_j w_j) x n
      double w[3], vr[3];
      for (int d = 0; d < 3; d++) w[d] = leverI * omega[i][d] + leverJ * omega[j][d];
      const double wxn[3] = {w[1] * n[2] - w[2] * n[1], w[2] * n[0] - w[0] * n[2], w[0] * n[1] - w[1] * n[0]};
      for (int d = 0; d < 3; d++) vr[d] = v[i][d] - v[j][d] - wxn[d];
      // a setup force evaluation (a run's start, a resumed run's first) reads the spring and leaves it
      // as it is: the law's projection onto the tangent plane and its Coulomb cap, applied again at
      // the same positions, may move it by an ulp, and a resumed run would not continue the springs of
      // the run it continues (contactLaw on a copy)
      double force[3], nxft[3], setupShear[3] = {shear[0], shear[1], shear[2]};
      contactLaw(n, normalForce, vr, options_.implicitContact && fresh ? 0.0 : dt,
                 update->setupflag ? setupShear : shear, force, nxft);
      for (int d = 0; d < 3; d++) {
        f[i][d] += force[d];
        torque[i][d] -= leverI * nxft[d];
      }
      const double weightI = radius[i] / (radius[i] + radius[j]);
      if (options_.implicitContact && (j < nlocal || atom->tag[i] < atom->tag[j]))
        contacts_.push_back(Contact{i, j, {n[0], n[1], n[2]}, leverI, leverJ, {-del[0], -del[1], -del[2]}, weightI,
                                    normalForce, {force[0] - normalForce * n[0],
                                    force[1] - normalForce * n[1], force[2] - normalForce * n[2]}});
      if (contactStressRequested_) {
        const double branch[3] = {-del[0], -del[1], -del[2]};  // x_j - x_i
        addContactStress(i, force, branch, weightI);
      }
      if (j < nlocal) {  // newton off: a ghost's owner adds its share itself
        const double minus[3] = {-force[0], -force[1], -force[2]};
        for (int d = 0; d < 3; d++) {
          f[j][d] -= force[d];
          torque[j][d] -= leverJ * nxft[d];
        }
        if (contactStressRequested_) addContactStress(j, minus, del, 1.0 - weightI);
      }
      // a pair with a ghost is listed from both sides (across ranks or a periodic face): count it
      // on the side of the lower tag, as collectBlocks keeps its block
      if (j < nlocal || atom->tag[i] < atom->tag[j]) contactsLast_++;
    }
  }
}

void PairFdmSubgrid::wallContactForces()
{
  // The same contact law against each declared wall (the wall has no radius: the branch vector of
  // Eq. 52 is the particle's, from its centre to the wall).
  double **x = atom->x, **v = atom->v, **f = atom->f, **omega = atom->omega, **torque = atom->torque;
  const double *radius = atom->radius;
  const double dt = update->setupflag ? 0.0 : update->dt;
  double **history = wallHistory_->array_atom;
  for (int i = 0; i < atom->nlocal; i++) {
    for (size_t k = 0; k < options_.walls.size(); k++) {
      const Wall &wall = options_.walls[k];
      double *shear = &history[i][wallHistoryWidth * k];
      double &touching = shear[3];
      // n: from the wall into the fluid; h: centre-to-wall distance
      const double h = wall.side == 0 ? x[i][wall.axis] - domain->boxlo[wall.axis] :
                                        domain->boxhi[wall.axis] - x[i][wall.axis];
      const double gap = h - radius[i];
      if (gap >= options_.hr) {
        shear[0] = shear[1] = shear[2] = touching = 0.0;
        continue;
      }
      const bool fresh = touching == 0.0;   // a new contact: as for pairs (contactForces)
      touching = 1.0;
      double n[3] = {0, 0, 0};
      n[wall.axis] = wall.side == 0 ? 1.0 : -1.0;
      const double normalForce = options_.kn * (options_.hr - gap);
      double vr[3];
      const double aw[3] = {radius[i] * omega[i][0], radius[i] * omega[i][1], radius[i] * omega[i][2]};
      const double wxn[3] = {aw[1] * n[2] - aw[2] * n[1], aw[2] * n[0] - aw[0] * n[2], aw[0] * n[1] - aw[1] * n[0]};
      for (int d = 0; d < 3; d++) vr[d] = v[i][d] - wall.velocity[d] - wxn[d];
      // a setup force evaluation leaves the spring as it is (as for pairs, contactForces)
      double force[3], nxft[3], setupShear[3] = {shear[0], shear[1], shear[2]};
      contactLaw(n, normalForce, vr, options_.implicitContact && fresh ? 0.0 : dt,
                 update->setupflag ? setupShear : shear, force, nxft);
      for (int d = 0; d < 3; d++) {
        f[i][d] += force[d];
        torque[i][d] -= radius[i] * nxft[d];
        wallContactLoads_[3 * k + d] -= force[d];
      }
      const double branch[3] = {-h * n[0], -h * n[1], -h * n[2]};
      if (contactStressRequested_) addContactStress(i, force, branch, 1.0);
      if (options_.implicitContact)
        contacts_.push_back(Contact{i, -1 - int(k), {n[0], n[1], n[2]}, radius[i], 0.0,
                                    {branch[0], branch[1], branch[2]}, 1.0, normalForce,
                                    {force[0] - normalForce * n[0], force[1] - normalForce * n[1],
                                     force[2] - normalForce * n[2]}});
      contactsLast_++;
    }
  }
}

void PairFdmSubgrid::collectSpringBlocks(double c1, double dt, std::vector<double> &pairs,
                                         std::vector<double> &walls, std::vector<double> *wallIndex) const
{
  // Eqs. (C1)-(C3) of docs/contact.md: the springs at the end of the step, for the contacts the last
  // compute found (the neighbour lists and local indices have not changed since). Every contact
  // with friction enters with both springs, and with the friction tail the solve needs to let it
  // slide within the step (docs/contact.md 2c); one without friction (mu_s = 0) has only its normal
  // spring.
  pairs.clear();
  walls.clear();
  if (wallIndex) wallIndex->clear();
  if (!implicitContact()) return;
  const int *tag = atom->tag;
  double R[144], term[6];
  for (const Contact &c : contacts_) {
    // every frictional contact: the solve decides whether it slides (2c)
    const double kt = options_.mu > 0 ? options_.kt : 0.0;
    if (c.j >= 0) {
      fdm::contact::pairSpringBlock(c.n, c.leverI, c.leverJ, options_.kn, kt, c1 * dt, R);
      pairs.push_back(tag[c.i]);
      pairs.push_back(tag[c.j]);
      pairs.insert(pairs.end(), R, R + 144);
      pairs.insert(pairs.end(), c.branch, c.branch + 3);
      pairs.push_back(c.weight);
      // the friction tail (fdm::springs): Coulomb's law at the end of the step (docs/contact.md 2c)
      pairs.insert(pairs.end(), c.n, c.n + 3);
      pairs.insert(pairs.end(), {c.leverI, c.leverJ, kt * c1 * dt, options_.mu, c.normalForce, options_.kn * c1 * dt});
      pairs.insert(pairs.end(), c.ft, c.ft + 3);
    } else {
      const Wall &w = options_.walls[size_t(-1 - c.j)];
      fdm::contact::wallSpringBlock(c.n, c.leverI, options_.kn, kt, c1 * dt, dt, w.velocity, R, term);
      walls.push_back(tag[c.i]);
      walls.insert(walls.end(), R, R + 36);
      walls.insert(walls.end(), term, term + 6);
      walls.insert(walls.end(), c.branch, c.branch + 3);
      walls.insert(walls.end(), c.n, c.n + 3);
      walls.insert(walls.end(), {c.leverI, kt * c1 * dt, kt * dt, options_.mu, c.normalForce, options_.kn * c1 * dt});
      walls.insert(walls.end(), c.ft, c.ft + 3);
      walls.insert(walls.end(), w.velocity, w.velocity + 3);
      if (wallIndex) wallIndex->push_back(double(-1 - c.j));
    }
  }
}

void PairFdmSubgrid::collectBlocks(bool withStress, std::vector<double> &pairs, std::vector<double> &walls,
                                   std::vector<double> *wallIndex)
{
  pairs.clear();
  walls.clear();
  if (wallIndex) wallIndex->clear();
  if (!lubricationActive()) return;
  double **x = atom->x;
  const double *radius = atom->radius;
  const int *tag = atom->tag;
  const int nlocal = atom->nlocal;
  res::PairBlock block;
  for (int ii = 0; ii < list->inum; ii++) {
    const int i = list->ilist[ii];
    const int *jlist = list->firstneigh[i];
    for (int jj = 0; jj < list->numneigh[i]; jj++) {
      const int j = jlist[jj] & NEIGHMASK;
      // newton off: a pair across ranks (or through a periodic face) is listed from both sides;
      // the side of the lower tag keeps it. A particle next to its own image is skipped.
      if (j >= nlocal && tag[i] >= tag[j]) continue;
      // the same symmetric gap the resistance library uses: xi = 2r/(a1+a2) - 2
      if (!res::subgridPairBlock(*model_, x[i], x[j], radius[i], radius[j], viscosity_, block)) continue;
      pairs.push_back(tag[i]);
      pairs.push_back(tag[j]);
      pairs.insert(pairs.end(), &block.R[0][0], &block.R[0][0] + 144);
      if (withStress) pairs.insert(pairs.end(), &block.stress[0][0], &block.stress[0][0] + fdm::subgrid::pairStressRecord);
    }
  }
  res::WallBlock wallBlock;
  for (size_t k = 0; k < options_.walls.size(); k++) {
    const Wall &w = options_.walls[k];
    double point[3] = {0, 0, 0}, normal[3] = {0, 0, 0};  // normal into the wall (Appendix A.2)
    point[w.axis] = w.side == 0 ? domain->boxlo[w.axis] : domain->boxhi[w.axis];
    normal[w.axis] = w.side == 0 ? -1.0 : 1.0;
    for (int i = 0; i < nlocal; i++) {
      if (!res::subgridWallBlock(*wallModel_, x[i], radius[i], point, normal, viscosity_, wallBlock)) continue;
      double rhs[6], stressRhs[7];
      res::wallVelocityTerm(wallBlock, w.velocity, rhs, stressRhs);
      walls.push_back(tag[i]);
      if (wallIndex) wallIndex->push_back(double(k));
      walls.insert(walls.end(), &wallBlock.R[0][0], &wallBlock.R[0][0] + 36);
      walls.insert(walls.end(), rhs, rhs + 6);
      if (withStress) {
        walls.insert(walls.end(), &wallBlock.stress[0][0], &wallBlock.stress[0][0] + 42);
        walls.insert(walls.end(), stressRhs, stressRhs + 7);
      }
    }
  }
}
