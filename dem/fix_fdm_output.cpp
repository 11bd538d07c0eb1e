// fix fdm/output: per-particle records and ParaView files of a coupled run (fix_fdm_output.h, docs/dem.md).
#include "fix_fdm_output.h"
#include "gather_to_root.h"

#include "coupling_session.h"
#include "output_options.h"

#include "atom.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "force.h"
#include "modify.h"
#include "update.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sys/stat.h>

using namespace LAMMPS_NS;
namespace rec = fdm::records;

namespace {

// fix fdm/couple's per-atom columns (docs/dem.md, Outputs), 0-based
const int cFluidF = 0, cFluidT = 3, cSubgridF = 6, cSubgridT = 9, cHydroS = 12, cHydroTrace = 18, cContactS = 19,
          cSubgridS = 25, cSubgridTrace = 31, coupleColumnsWithStresslets = 32;

// values gathered per particle before fdm/couple's columns: tag, type, x (3), unwrapped x (3),
// radius, v (3), omega (3), f (3), torque (3)
const int gTag = 0, gType = 1, gX = 2, gUnwrapped = 5, gRadius = 8, gV = 9, gOmega = 12, gF = 15, gTorque = 18,
          gCouple = 21;

// the particle record (particle_records.h): stresslets in full (not traceless), xx xy xz yy yz zz
std::vector<rec::Field> recordFields(bool stresslets)
{
  std::vector<rec::Field> f = {{"tag", 'l', 1},       {"type", 'i', 1},      {"image", 'i', 3},
                               {"x", 'f', 3},         {"radius", 'f', 1},    {"U", 'f', 3},
                               {"omega", 'f', 3},     {"F_fluid", 'f', 3},   {"T_fluid", 'f', 3},
                               {"F_subgrid", 'f', 3}, {"T_subgrid", 'f', 3}, {"F_dem", 'f', 3},
                               {"T_dem", 'f', 3}};
  if (stresslets) {
    f.push_back({"S_fluid", 'f', 6});
    f.push_back({"S_subgrid", 'f', 6});
    f.push_back({"S_contact", 'f', 6});
  }
  return f;
}

// the full stresslet (xx xy xz yy yz zz) from a traceless one and its trace
void fullStresslet(const double *traceless, double trace, double *out)
{
  for (int c = 0; c < 6; c++) out[c] = traceless[c];
  out[0] += trace / 3;
  out[3] += trace / 3;
  out[5] += trace / 3;
}

std::string number(double v)
{
  char s[40];
  std::snprintf(s, sizeof s, "%.17g", v);
  return s;
}

}  // namespace

FixFdmOutput::FixFdmOutput(LAMMPS *lmp, int narg, char **arg) :
  Fix(lmp, narg, arg), recordEvery_(0), vtkEvery_(0), append_(false), couple_(nullptr), stresslets_(false),
  coupleColumns_(0), width_(0), natoms_(0), opened_(false), lastVtkStep_(-1), seconds_(0), recordsThisRun_(0),
  vtkThisRun_(0)
{
  if (igroup != 0) error->all(FLERR, "fix fdm/output must be applied to group all");
  try {
    const fdm::OutputOptions o = fdm::parseOutputOptions(std::vector<std::string>(arg + std::min(3, narg), arg + narg));
    recordEvery_ = long(o.recordEvery);
    recordPath_ = o.recordPath;
    vtkEvery_ = long(o.vtkEvery);
    vtkDir_ = o.vtkDir;
    append_ = o.append;
  } catch (const fdm::KeywordError &e) {
    error->all(FLERR, e.what());
  }
  nevery = 1;
}

FixFdmOutput::~FixFdmOutput() {}

int FixFdmOutput::setmask() { return FixConst::END_OF_STEP; }

void FixFdmOutput::init()
{
  couple_ = nullptr;
  for (int i = 0; i < modify->nfix; i++)
    if (std::strcmp(modify->fix[i]->style, "fdm/couple") == 0) couple_ = modify->fix[i];
  if (!couple_)
    error->all(FLERR, "fix fdm/output needs fix fdm/couple (it writes that fix's per-particle results)");
  coupleColumns_ = couple_->size_peratom_cols;
  stresslets_ = coupleColumns_ >= coupleColumnsWithStresslets;
  width_ = gCouple + coupleColumns_;
  if (!atom->sphere_flag) error->all(FLERR, "fix fdm/output requires atom_style sphere");
}

bool FixFdmOutput::appending() const
{
  return append_ || !LAMMPS_NS::CouplingSession::instance().resumeFile().empty();
}

void FixFdmOutput::open()
{
  // once, at the first run: the particle count and the box are those of the coupled session
  natoms_ = long(atom->natoms);
  if (natoms_ < 1 || atom->map_tag_max != natoms_)
    error->all(FLERR, "fix fdm/output: the particles must have IDs 1..N without gaps");
  layout_ = rec::Layout(recordFields(stresslets_), natoms_);
  if (comm->me == 0) {
    try {
      if (recordEvery_) {
        std::string meta = "\"written_by\": \"fix fdm/output\", \"every\": " + std::to_string(recordEvery_) +
                           ", \"dt\": " + number(update->dt) + ", \"units\": \"si\", \"box_lo\": [" +
                           number(domain->boxlo[0]) + ", " + number(domain->boxlo[1]) + ", " + number(domain->boxlo[2]) +
                           "], \"box_hi\": [" + number(domain->boxhi[0]) + ", " + number(domain->boxhi[1]) + ", " +
                           number(domain->boxhi[2]) + "], \"periodic\": [" + std::to_string(domain->periodicity[0]) +
                           ", " + std::to_string(domain->periodicity[1]) + ", " + std::to_string(domain->periodicity[2]) +
                           "], \"stresslets\": \"full (not traceless), components xx xy xz yy yz zz, force x length\""
                           ", \"positions\": \"x wrapped into the periodic box; x + image * (box_hi - box_lo) unwrapped\"";
        // a resumed run (fdmDEM -resume, fdmRun --resume) continues the records of the run it
        // resumes: blocks up to the checkpoint step are kept, later ones cut
        records_.reset(new rec::Writer(recordPath_, layout_, meta, appending(), update->ntimestep));
        if (records_->blocksKept() && screen)
          fprintf(screen, "fix fdm/output: appending to %s after its %ld blocks up to step %lld\n", recordPath_.c_str(),
                  records_->blocksKept(), (long long) update->ntimestep);
      }
      if (vtkEvery_) {
        if (::mkdir(vtkDir_.c_str(), 0755) != 0 && errno != EEXIST)
          throw rec::Error("cannot create the folder " + vtkDir_ + ": " + std::strerror(errno));
        series_.reset(new fdm::vtk::Series(vtkDir_ + "/particles.pvd"));
        if (appending()) series_->load(update->get_cur_time() * (1 + 1e-12));
      }
    } catch (const rec::Error &e) {
      fail(e.what());
    }
  }
  opened_ = true;
}

void FixFdmOutput::fail(const std::string &message)
{
  // rank 0 (the others wait in the next collective call): the fluid solver is told why, then
  // error->one aborts every rank
  CouplingSession::instance().abandon("fdmDEM: fix fdm/output: " + message);
  error->one(FLERR, ("fix fdm/output: " + message).c_str());
}

void FixFdmOutput::setup(int)
{
  if (!opened_) open();
  seconds_ = 0;
  recordsThisRun_ = vtkThisRun_ = 0;
  // the particles where the run starts (their solved quantities are those of the last step, or
  // zero before the first): a VTK file if it is a write time, so that time 0 has its particles
  const bigint step = update->ntimestep;
  if (vtkEvery_ && step % vtkEvery_ == 0 && step != lastVtkStep_) write(false, true);
}

void FixFdmOutput::end_of_step()
{
  const bigint step = update->ntimestep;
  const bool record = recordEvery_ && step % recordEvery_ == 0;
  const bool vtk = vtkEvery_ && (step % vtkEvery_ == 0 || step == update->laststep) && step != lastVtkStep_;
  if (record || vtk) write(record, vtk);
}

void FixFdmOutput::write(bool record, bool vtk)
{
  const double t0 = MPI_Wtime();
  std::vector<double> byTag;
  if (gather(byTag)) {
    try {
      if (record) writeRecords(byTag);
      if (vtk) writeVtk(byTag);
    } catch (const rec::Error &e) {
      fail(e.what());
    }
  }
  if (vtk) lastVtkStep_ = update->ntimestep;
  recordsThisRun_ += record;
  vtkThisRun_ += vtk;
  seconds_ += MPI_Wtime() - t0;
}

bool FixFdmOutput::gather(std::vector<double> &byTag)
{
  const int nlocal = atom->nlocal;
  double **couple = couple_->array_atom;
  std::vector<double> buf(size_t(width_) * nlocal);
  for (int i = 0; i < nlocal; i++) {
    double *b = &buf[size_t(width_) * i];
    b[gTag] = atom->tag[i];
    b[gType] = atom->type[i];
    double unwrapped[3];
    domain->unmap(atom->x[i], atom->image[i], unwrapped);
    for (int d = 0; d < 3; d++) {
      b[gX + d] = atom->x[i][d];
      b[gUnwrapped + d] = unwrapped[d];
      b[gV + d] = atom->v[i][d];
      b[gOmega + d] = atom->omega[i][d];
      b[gF + d] = atom->f[i][d];
      b[gTorque + d] = atom->torque[i][d];
    }
    b[gRadius] = atom->radius[i];
    for (int c = 0; c < coupleColumns_; c++) b[gCouple + c] = couple ? couple[i][c] : 0.0;
  }
  const std::vector<double> all = fdm::gatherToRoot(buf, world);
  if (comm->me != 0) return false;
  if (long(all.size()) != natoms_ * width_)
    fail(std::to_string(all.size() / width_) + " particles where the run has " + std::to_string(natoms_) +
         " (particles cannot be inserted or deleted)");
  byTag.assign(all.size(), 0.0);
  std::vector<char> seen(natoms_, 0);
  for (size_t k = 0; k < all.size(); k += width_) {
    const long tag = std::lround(all[k + gTag]);
    if (tag < 1 || tag > natoms_ || seen[tag - 1])
      fail("particle ID " + std::to_string(tag) + " is out of 1.." + std::to_string(natoms_) + " or twice");
    seen[tag - 1] = 1;
    std::copy(all.begin() + k, all.begin() + k + width_, byTag.begin() + (tag - 1) * width_);
  }
  return true;
}

void FixFdmOutput::writeRecords(const std::vector<double> &byTag)
{
  const size_t bytes = layout_.recordBytes();
  std::vector<char> out(bytes * natoms_);
  const size_t oTag = layout_.offset("tag"), oType = layout_.offset("type"), oImage = layout_.offset("image"),
               oX = layout_.offset("x"), oRadius = layout_.offset("radius"), oU = layout_.offset("U"),
               oOmega = layout_.offset("omega"), oFf = layout_.offset("F_fluid"), oTf = layout_.offset("T_fluid"),
               oFs = layout_.offset("F_subgrid"), oTs = layout_.offset("T_subgrid"), oFd = layout_.offset("F_dem"),
               oTd = layout_.offset("T_dem");
  for (long p = 0; p < natoms_; p++) {
    const double *b = &byTag[size_t(width_) * p];
    const double *c = b + gCouple;
    char *r = &out[bytes * p];
    const int64_t tag = std::llround(b[gTag]);
    const int32_t type = int32_t(std::lround(b[gType]));
    std::memcpy(r + oTag, &tag, 8);
    std::memcpy(r + oType, &type, 4);
    double x[3];
    int32_t image[3];
    for (int d = 0; d < 3; d++) {
      // wrapped into the box as the fluid sees it (LIGGGHTS wraps only when it re-neighbours)
      x[d] = b[gX + d];
      image[d] = 0;
      if (domain->periodicity[d]) {
        const double L = domain->prd[d];
        x[d] -= L * std::floor((x[d] - domain->boxlo[d]) / L);
        if (x[d] >= domain->boxhi[d]) x[d] -= L;
        image[d] = int32_t(std::lround((b[gUnwrapped + d] - x[d]) / L));
      }
    }
    std::memcpy(r + oImage, image, 12);
    std::memcpy(r + oX, x, 24);
    std::memcpy(r + oRadius, &b[gRadius], 8);
    std::memcpy(r + oU, &b[gV], 24);
    std::memcpy(r + oOmega, &b[gOmega], 24);
    std::memcpy(r + oFf, c + cFluidF, 24);
    std::memcpy(r + oTf, c + cFluidT, 24);
    std::memcpy(r + oFs, c + cSubgridF, 24);
    std::memcpy(r + oTs, c + cSubgridT, 24);
    std::memcpy(r + oFd, &b[gF], 24);
    std::memcpy(r + oTd, &b[gTorque], 24);
    if (stresslets_) {
      double fluid[6], subgrid[6], hydro[6], contact[6];
      fullStresslet(c + cHydroS, c[cHydroTrace], hydro);
      fullStresslet(c + cSubgridS, c[cSubgridTrace], subgrid);
      for (int k = 0; k < 6; k++) {
        fluid[k] = hydro[k] - subgrid[k];
        contact[k] = c[cContactS + k];
      }
      std::memcpy(r + layout_.offset("S_fluid"), fluid, 48);
      std::memcpy(r + layout_.offset("S_subgrid"), subgrid, 48);
      std::memcpy(r + layout_.offset("S_contact"), contact, 48);
    }
  }
  records_->write(int64_t(update->ntimestep), update->get_cur_time(), out.data());
}

void FixFdmOutput::writeVtk(const std::vector<double> &byTag)
{
  namespace vtk = fdm::vtk;
  const long n = natoms_;
  std::vector<double> points(3 * n);
  auto scalar = [&](const char *name, int column) {
    vtk::Array a{name, 1, std::vector<double>(n)};
    for (long p = 0; p < n; p++) a.values[p] = byTag[size_t(width_) * p + column];
    return a;
  };
  // vectors: a sum of gathered columns
  auto vector = [&](const char *name, std::initializer_list<int> columns) {
    vtk::Array a{name, 3, std::vector<double>(3 * n, 0.0)};
    for (long p = 0; p < n; p++)
      for (int col : columns)
        for (int d = 0; d < 3; d++) a.values[3 * p + d] += byTag[size_t(width_) * p + col + d];
    return a;
  };
  std::vector<vtk::Array> arrays = {scalar("radius", gRadius), scalar("type", gType), scalar("id", gTag)};
  arrays.push_back(scalar("diameter", gRadius));
  for (double &v : arrays.back().values) v *= 2;
  arrays.push_back(vector("U", {gV}));
  arrays.push_back(vector("omega", {gOmega}));
  arrays.push_back(vector("F_hydro", {gCouple + cFluidF, gCouple + cSubgridF}));
  arrays.push_back(vector("F_fluid", {gCouple + cFluidF}));
  arrays.push_back(vector("F_subgrid", {gCouple + cSubgridF}));
  arrays.push_back(vector("F_dem", {gF}));
  arrays.push_back(vector("T_hydro", {gCouple + cFluidT, gCouple + cSubgridT}));
  if (stresslets_) {
    // symmetric tensors in VTK's order xx yy zz xy yz xz
    const int vtkOrder[6] = {0, 3, 5, 1, 4, 2};
    vtk::Array hydro{"S_hydro", 6, {}}, fluid{"S_fluid", 6, {}}, subgrid{"S_subgrid", 6, {}}, contact{"S_contact", 6, {}};
    for (long p = 0; p < n; p++) {
      const double *c = &byTag[size_t(width_) * p + gCouple];
      double h[6], s[6];
      fullStresslet(c + cHydroS, c[cHydroTrace], h);
      fullStresslet(c + cSubgridS, c[cSubgridTrace], s);
      for (int k : vtkOrder) {
        hydro.values.push_back(h[k]);
        fluid.values.push_back(h[k] - s[k]);
        subgrid.values.push_back(s[k]);
        contact.values.push_back(c[cContactS + k]);
      }
    }
    for (auto *a : {&hydro, &fluid, &subgrid, &contact}) arrays.push_back(*a);
  }
  for (long p = 0; p < n; p++)
    for (int d = 0; d < 3; d++) {
      double x = byTag[size_t(width_) * p + gX + d];
      if (domain->periodicity[d]) x -= domain->prd[d] * std::floor((x - domain->boxlo[d]) / domain->prd[d]);
      points[3 * p + d] = x;
    }
  char name[64];
  std::snprintf(name, sizeof name, "particles_%09lld.vtp", (long long) update->ntimestep);
  vtk::writeParticles(vtkDir_ + "/" + name, points, arrays);
  // the time as OpenFOAM names its time folders (fdmFoam's time is step x dt): 12 digits, so that
  // ParaView puts the particles and the fluid of a write time at the same time
  char time[40];
  std::snprintf(time, sizeof time, "%.12g", update->get_cur_time());
  series_->add(std::atof(time), name);
}

void FixFdmOutput::post_run()
{
  if (comm->me != 0) return;
  char line[400];
  std::snprintf(line, sizeof line,
                "fix fdm/output: %ld record blocks (%zu bytes each, %zu per particle) and %ld VTK files in %.4g s\n",
                recordsThisRun_, layout_.blockBytes(), layout_.recordBytes(), vtkThisRun_, seconds_);
  if (screen) fputs(line, screen);
  if (logfile) fputs(line, logfile);
}
