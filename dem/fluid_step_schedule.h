/* Which particle steps the fluid solves (fix fdm/couple fluid_every K, docs/dem.md "Particle steps
   between fluid steps"), and the time step each fluid step spans. No LIGGGHTS. */

#ifndef FDM_FLUID_STEP_SCHEDULE_H
#define FDM_FLUID_STEP_SCHEDULE_H

namespace fdm {

class FluidStepSchedule {
 public:
  explicit FluidStepSchedule(long long every = 1) : every_(every) {}
  long long every() const { return every_; }

  // Every K-th step, and always where the particle side has no fluid solution to hold yet (a session's
  // first step: haveSolution false), at a checkpoint (the fluid writes its own at the same step, so that
  // a resumed run continues both from one step) and at the last step of a run.
  bool due(long long step, long long lastStep, bool checkpoint, bool haveSolution) const
  {
    if (every_ <= 1 || lastFluidStep_ < 0 || !haveSolution) return true;
    return step % every_ == 0 || step == lastStep || checkpoint;
  }
  // The fluid's time step: the particle steps since its last one, times the particle step dt.
  double span(long long step, double dt) const
  {
    return lastFluidStep_ >= 0 && step > lastFluidStep_ ? double(step - lastFluidStep_) * dt : dt;
  }

  // The last step the fluid solved (-1: none yet in this session); a resumed run starts from its
  // checkpoint's step, always a fluid step.
  long long lastFluidStep() const { return lastFluidStep_; }
  void solved(long long step) { lastFluidStep_ = step; }

 private:
  long long every_;
  long long lastFluidStep_ = -1;
};

}  // namespace fdm

#endif
