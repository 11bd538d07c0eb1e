/* The fluid's force on the particle steps between fluid steps (fix fdm/couple fluid_every K, docs/dem.md
   "Particle steps between fluid steps"): held as the Stokes drag of an isolated sphere toward the
   velocity u_b the particle had relative to the fluid at the last fluid step, F = D (u_b - U). Its drag
   target b = D u_b = D U + F^FDM, from that step's converged U and F^FDM, is the same whichever held
   step of the cycle it is taken from (between fluid steps F = D (u_b - U)), so a held step needs no
   state of its own with the drag held constant, and a resumed run rebuilds b from the U and F^FDM of
   its checkpoint.

   held_drag extrapolated: b of a held step s is extrapolated linearly in time from the last two fluid
   steps s_n and s_{n-1}, b(s) = b_n + f (b_n - b_{n-1}), f = (s - s_n)/(s_n - s_{n-1}) at most 1 (a fluid
   step forced between the regular ones, at a run's end or a checkpoint, leaves a short interval whose
   slope must not be stretched over a longer one). The fluid's force changes along the step as the
   particles move (a pair turning about its contact sees the normal load of the shear change sign):
   held constant that change is lost for K - 1 steps, first order in the fluid's step; extrapolated, to
   second order. Until a session's second fluid step the drag is held constant. The two targets are the
   state a checkpoint carries. No LIGGGHTS. */

#ifndef FDM_HELD_DRAG_H
#define FDM_HELD_DRAG_H

#include <vector>

namespace fdm {

class HeldDrag {
 public:
  explicit HeldDrag(bool extrapolated = false) : extrapolated_(extrapolated) {}
  bool extrapolated() const { return extrapolated_; }

  // The drag target of held step `step` (6 per particle: force, torque), given b = D U + F^FDM of the
  // last fluid step `lastFluidStep` (constant: returned as it is; extrapolated: kept as b_n at the first
  // held step after each fluid step).
  std::vector<double> target(const std::vector<double> &lastFluidTarget, long long step, long long lastFluidStep);

  // What a checkpoint keeps of the extrapolation: b_n, b_{n-1} and their steps (-1: none yet).
  struct State {
    std::vector<double> last, before;
    long long lastStep = -1, beforeStep = -1;
  };
  const State &state() const { return state_; }
  void restore(const State &state) { state_ = state; }

 private:
  bool extrapolated_;
  State state_;
};

}  // namespace fdm

#endif
