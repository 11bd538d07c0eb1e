/* fix fdm/couple -- couples LIGGGHTS to the fictitious-domain fluid solver fdmFoam.

   Syntax (docs/dem.md):
     fix ID all fdm/couple [transport socket|file] [host H] [port P] [portfile F] [directory D]
                           [connect_timeout s] [timeout s] [record FILE] [gravity gx gy gz] [move yes|no]

   Every time step: moves the particles with their velocity (initial_integrate, paper 4.3 step 1),
   then (final_integrate, after every pair and fix force is in f and torque) sends the particles
   to fdmFoam and, every inner iteration, solves Eq. (31) for all particle velocities with Eigen
   from the integrals it receives, until fdmFoam reports convergence. Replaces fix nve/sphere. */

#ifdef FIX_CLASS
#else

#ifndef FDM_FIX_FDM_COUPLE_H
#define FDM_FIX_FDM_COUPLE_H

#include "fix.h"
#include "fdm/coupler.h"

#include <memory>
#include <string>
#include <vector>

namespace LAMMPS_NS {

class FixFdmCouple : public Fix {
 public:
  FixFdmCouple(class LAMMPS *, int, char **);
  ~FixFdmCouple();
  int setmask();
  void init();
  void setup(int);
  void initial_integrate(int);
  void final_integrate();
  void post_run();
  double compute_vector(int);

  // Called by the fdmDEM driver after the input script: tells fdmFoam to finish.
  static void finishAll();

 private:
  // Per particle, by tag (index tag-1), gathered on rank 0.
  struct Particle { double x[3], radius, v[3], omega[3], f[3], torque[3], mass, density; };

  void connectAndHandshake();
  void gather(std::vector<Particle> &particles);
  void checkConfiguration(const std::vector<Particle> &particles);
  void solveVelocities(const std::vector<Particle> &particles, const fdm::coupler::Message &integrals,
                       std::vector<double> &solution);
  void fail(const std::string &message);

  fdm::coupler::Options options_;
  double gravity_[3];
  bool move_;

  static std::unique_ptr<fdm::coupler::Transport> connection_;   // rank 0, kept across runs
  static double alphaLambda_, rhoFluid_;

  std::vector<double> solution_;     // 6N: (U, Omega) per particle, warm start of the next solve
  int lastIterations_;
  double lastResidual_;
  double solveTime_, exchangeTime_, gatherTime_;
  long steps_;
};

}  // namespace LAMMPS_NS

#endif
#endif
