/* fix fdm/couple walls FILE: per step, the force of the particles on each wall of pair_style
   fdm/subgrid (docs/dem.md), split into sub-grid lubrication (minus each wall block's force on its
   particle, Eq. D.6) and contact (minus the wall contact forces of the step's force evaluation and of the
   implicit springs' increment over the step, Eq. C2 of docs/contact.md): the particle side of the momentum
   balance of a sheared suspension (docs/profiles.md). One text line per step after a two-line header; a
   resumed run appends (fdmRun --resume cut the file at the checkpoint, fdm/checkpoint.py), writing the header
   first if the file is missing or empty (fdmRun --from-snapshot in a fresh case folder). Rank 0; no
   LIGGGHTS. Problems are thrown as std::runtime_error("walls: ..."). */

#ifndef FDM_WALL_LOADS_FILE_H
#define FDM_WALL_LOADS_FILE_H

#include <cstdio>
#include <string>
#include <vector>

namespace fdm {

class WallLoadsFile {
 public:
  struct Wall {
    int axis, side;   // side 0: the low face of the axis, 1: the high one
  };
  // What Eq. (31) and the pair style give of one step. Blocks are listed with the index of their wall.
  struct StepLoads {
    std::vector<double> subgridBlockForces;  // 6 per sub-grid wall block: its force (and torque) on the particle
    std::vector<double> subgridBlockWall;    // the wall of each sub-grid block
    std::vector<double> contactLoads;        // 3 per wall: the contacts' force on it, summed over the ranks
    std::vector<double> springBlockForces;   // 6 per implicit wall spring block: its force on the particle
    std::vector<double> springBlockWall;     // the wall of each spring block
  };

  WallLoadsFile(std::string path, std::vector<Wall> walls) : path_(std::move(path)), walls_(std::move(walls)) {}
  ~WallLoadsFile();
  WallLoadsFile(const WallLoadsFile &) = delete;
  WallLoadsFile &operator=(const WallLoadsFile &) = delete;

  // Opens the file at the first call (append: a resumed run), then writes the step's line.
  void write(long long step, double dt, bool append, const StepLoads &loads);

  // The line of one step: per wall, sub-grid X Y Z then contact X Y Z [N].
  std::string line(long long step, const StepLoads &loads) const;

 private:
  std::string path_;
  std::vector<Wall> walls_;
  FILE *out_ = nullptr;
};

}  // namespace fdm

#endif
