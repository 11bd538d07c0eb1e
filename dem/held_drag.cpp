// The held drag of the steps between fluid steps (held_drag.h).
#include "held_drag.h"

#include <algorithm>

namespace fdm {

std::vector<double> HeldDrag::target(const std::vector<double> &lastFluidTarget, long long step,
                                     long long lastFluidStep)
{
  if (!extrapolated_) return lastFluidTarget;
  State &s = state_;
  if (s.lastStep != lastFluidStep) {
    s.before.swap(s.last);
    s.beforeStep = s.lastStep;
    s.last = lastFluidTarget;
    s.lastStep = lastFluidStep;
  }
  const bool twoSteps = s.beforeStep >= 0 && s.beforeStep < s.lastStep && s.before.size() == s.last.size();
  const double f = twoSteps ? std::min(1.0, double(step - s.lastStep) / double(s.lastStep - s.beforeStep)) : 0.0;
  std::vector<double> b(s.last.size());
  for (size_t k = 0; k < b.size(); k++) b[k] = s.last[k] + (twoSteps ? f * (s.last[k] - s.before[k]) : 0.0);
  return b;
}

}  // namespace fdm
