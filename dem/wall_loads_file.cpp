// The particles' loads on the walls, a line per step (wall_loads_file.h).
#include "wall_loads_file.h"

#include <sys/stat.h>

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace fdm {

WallLoadsFile::~WallLoadsFile()
{
  if (out_) std::fclose(out_);
}

std::string WallLoadsFile::line(long long step, const StepLoads &loads) const
{
  std::vector<double> subgrid(3 * walls_.size(), 0.0);
  const std::vector<double> &blocks = loads.subgridBlockForces;
  if (!loads.subgridBlockWall.empty()) {
    if (blocks.size() != 6 * loads.subgridBlockWall.size())
      throw std::runtime_error("walls: " + std::to_string(blocks.size() / 6) + " wall blocks in Eq. (31) but " +
                               std::to_string(loads.subgridBlockWall.size()) + " wall indices");
    for (size_t b = 0; b < loads.subgridBlockWall.size(); b++) {
      const size_t k = size_t(std::lround(loads.subgridBlockWall[b]));
      for (int d = 0; d < 3; d++) subgrid[3 * k + d] -= blocks[6 * b + d];
    }
  }
  std::vector<double> contact(3 * walls_.size(), 0.0);
  for (size_t k = 0; k < contact.size() && k < loads.contactLoads.size(); k++) contact[k] = loads.contactLoads[k];
  const std::vector<double> &springs = loads.springBlockForces;
  if (!loads.springBlockWall.empty()) {
    if (springs.size() != 6 * loads.springBlockWall.size())
      throw std::runtime_error("walls: " + std::to_string(springs.size() / 6) + " implicit wall springs in Eq. (31) but " +
                               std::to_string(loads.springBlockWall.size()) + " wall indices");
    for (size_t b = 0; b < loads.springBlockWall.size(); b++) {
      const size_t k = size_t(std::lround(loads.springBlockWall[b]));
      for (int d = 0; d < 3; d++) contact[3 * k + d] -= springs[6 * b + d];
    }
  }
  std::ostringstream text;
  text.precision(12);
  text << step;
  for (size_t k = 0; k < walls_.size(); k++) {
    for (int d = 0; d < 3; d++) text << ' ' << subgrid[3 * k + d];
    for (int d = 0; d < 3; d++) text << ' ' << contact[3 * k + d];
  }
  text << '\n';
  return text.str();
}

void WallLoadsFile::write(long long step, double dt, bool append, const StepLoads &loads)
{
  static const char *faceNames[6] = {"xlo", "xhi", "ylo", "yhi", "zlo", "zhi"};
  if (!out_) {
    // a resumed run appends to the file it continues; one without it (fdmRun --from-snapshot, a fresh
    // case folder) starts it with the header
    struct stat st;
    const bool header = !append || ::stat(path_.c_str(), &st) != 0 || st.st_size == 0;
    out_ = std::fopen(path_.c_str(), append ? "a" : "w");
    if (!out_) throw std::runtime_error("walls: cannot open " + path_ + " for writing");
    if (header) {
      std::fprintf(out_, "# fix fdm/couple walls: force of the particles on each wall [N]: sub-grid lubrication "
                         "(Eq. D.6) and contact; timestep %.17g\n# step", dt);
      for (const Wall &w : walls_)
        for (const char *part : {"subgrid", "contact"})
          for (const char *c : {"X", "Y", "Z"}) std::fprintf(out_, " %s:%s%s", faceNames[2 * w.axis + w.side], part, c);
      std::fprintf(out_, "\n");
    }
  }
  const std::string text = line(step, loads);
  if (std::fwrite(text.data(), 1, text.size(), out_) != text.size() || std::fflush(out_) != 0)
    throw std::runtime_error("walls: could not write step " + std::to_string(step) + " to " + path_ +
                             " (disk full or not writable?)");
}

}  // namespace fdm
