/* Position update of the particles (paper 4.3, step 1) with a gap-preserving correction for close
   pairs and wall gaps (docs/dem.md, "Position update").

   The particles have no inertia: x_{n+1} = x_n + dt * (displacement rate), where the rate is
   U_n (Euler) or 3/2 U_n - 1/2 U_{n-1} (Adams-Bashforth 2). A straight step moves two spheres
   that turn around each other apart, by O((|U_t| dt)^2 / r) per step with Euler and O(dt^4) with
   AB2. Near contact in shear (gaps of 1e-4 a) that drift is as large as the gap and breaks the
   fore-aft symmetry of Stokes flow unless dt is tiny (the paper uses dt = 1e-4 / shear rate).

   The correction: every surface gap h of a close pair or of a particle and a wall is integrated in
   its own variable, log h, with the same multistep formula,
       h_{n+1} = h_n exp( dt [3/2 (hdot/h)_n - 1/2 (hdot/h)_{n-1}] ),   hdot = d.(U_2 - U_1),
   and the straight step is then moved along the lines of centres (Gauss-Seidel sweeps, each pair
   shared in inverse proportion to the radii, walls do not move) until every such gap has its
   target; gaps inside contact springs (h < h_r) and closed ones are held at the gap the straight
   step gives them. The target is exact for a rigid rotation (h unchanged) and for a lubrication squeeze at
   constant force (hdot/h constant), keeps gaps positive at any dt, and differs from the straight
   step by O(dt^3): the scheme stays second order. Where the targets contradict each other (the
   sweeps stall more than half a target off: dense clusters, large dt), the step falls back to the
   straight step with every gap kept from closing below min(target, h_n). A compromise that
   misses its targets by less is held to the same bounds: it never closes a gap, a held contact gap
   least of all, below where the fallback would have kept it. Plain C++ (no LIGGGHTS),
   tested in dem/tests/test_position_update.cpp. */

#ifndef FDM_POSITION_UPDATE_H
#define FDM_POSITION_UPDATE_H

#include <vector>

namespace fdm {
namespace motion {

// A planar wall: the plane x[axis] = position; the particles are on its upper side (side 0, a
// "lo" face of the box) or its lower side (side 1, a "hi" face). Walls move only in their plane.
struct Wall {
  int axis, side;
  double position;
};

struct Configuration {
  int n = 0;                        // particles, index 0..n-1
  std::vector<double> x, radius;    // 3n positions at step n (U_n was solved there), n radii
  std::vector<double> u;            // 6n (U, Omega) of step n
  std::vector<double> xPrevious;    // 3n positions of step n-1, empty on the first step
  std::vector<double> uPrevious;    // 6n velocities of step n-1, empty on the first step
  double period[3] = {0, 0, 0};     // box lengths of the periodic directions (0: not periodic)
};

struct Options {
  bool adamsBashforth = true;        // AB2 rate (Euler when false or on the first step)
  bool gapCorrection = true;         // the log-gap correction of close pairs and walls
  double maxLogStep = 1.0;           // |dt (hdot/h)| per step is limited to this (gap factor e)
  // The targets are second-order accurate, O(dt^3) apart from a set of positions that meets them
  // all when closed loops of close pairs (rings through a periodic box, triangles) constrain each
  // other: the sweeps stop at this fraction of each target gap, or after maxSweeps.
  double tolerance = 1e-4;
  int maxSweeps = 30;
  double fallback = 0.5;             // still this far from a target after the sweeps: the fallback,
                                     // the straight step with every gap kept above its bound
  int maxBoundSweeps = 200;          // sweeps of the fallback
  // Gaps below the roughness height h_r are held by contact springs (hdot not ~ h): they get no
  // log target. With holdContactGaps they (and closed gaps) are held at the gap the straight step
  // gives them while the other gaps are corrected, the displacement the implicit springs assumed;
  // without, they are left alone and a particle's other corrections may move them.
  double contactGap = 0;
  bool holdContactGaps = true;
};

struct Statistics {
  long pairGaps = 0, wallGaps = 0;   // gaps given a target this step
  long limited = 0;                  // targets where maxLogStep applied
  long heldGaps = 0;                 // contact or closed gaps held at their straight-step value
  int sweeps = 0;                    // Gauss-Seidel sweeps used
  double worst = 0;                  // largest |gap - target| / target met in the last sweep
  bool fallback = false;             // the targets could not be met: the straight step, with every gap
                                     // kept from closing below min(target, h_n)
  int boundSweeps = 0;               // sweeps of the fallback, or of the bounds of a compromise
  double worstBound = 0;             // largest relative violation of a bound left by them
  double compromiseMiss = 0;         // a compromise (no fallback, targets missed by more than the
                                     // tolerance): its largest relative violation of a bound before
                                     // the bound sweeps pushed it apart (0: it met them all)
};

// The displacement rates (6n: translation, rotation) of the step from n to n+1: x_{n+1} = x_n +
// dt * rate. Gaps are corrected for the listed pairs (index pairs, 2 per pair) and for every
// particle within one radius of a wall (h < a).
Statistics displacementRates(const Configuration &c, const std::vector<int> &closePairs,
                             const std::vector<Wall> &walls, double dt, const Options &options,
                             std::vector<double> &rate);

}  // namespace motion
}  // namespace fdm

#endif
