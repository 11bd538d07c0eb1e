/* fix fdm/couple -- couples LIGGGHTS to the fictitious-domain fluid solver fdmFoam.

   Syntax (docs/dem.md):
     fix ID all fdm/couple [transport socket|file] [host H] [port P] [portfile F] [directory D]
                           [connect_timeout s] [timeout s] [record FILE] [gravity gx gy gz] [move yes|no]

   Every time step: moves the particles with their velocity (initial_integrate, paper 4.3 step 1),
   then (final_integrate, after every pair and fix force is in f and torque) sends the particles
   to fdmFoam and, every inner iteration, solves Eq. (31) for all particle velocities with Eigen
   from the integrals it receives, until fdmFoam reports convergence. Replaces fix nve/sphere.

   Outputs: global vector [inner iterations of the last step, last lambda residual, particle-solve
   seconds, exchange seconds]; per-atom array [Fx Fy Fz Tx Ty Tz] = hydrodynamic force and torque
   of the last StepDone. */

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
  double memory_usage();

  // Called by the fdmDEM driver on every rank after the input script: tells fdmFoam to finish,
  // prints the timing over all runs, closes the connection.
  static void finishAll(class LAMMPS *lmp);
  // Best effort, at exit after an error: sends Error(why) to the fluid solver if still connected.
  static void abandon(const std::string &why);

 private:
  // One particle as gathered on rank 0, stored by tag (index tag-1).
  struct Particle {
    double x[3], radius, v[3], omega[3], f[3], torque[3], mass, density;
  };
  // Wall-clock seconds spent in the three parts of the particle side's work.
  struct Timing {
    double solve, exchange, gatherScatter;
    long steps;
    Timing() : solve(0), exchange(0), gatherScatter(0), steps(0) {}
    void add(const Timing &t);
  };

  void connectAndHandshake();
  std::string checkFluidHello(const fdm::coupler::Message &hello) const;
  void gather(std::vector<Particle> &particles);
  std::string checkConfiguration(const std::vector<Particle> &particles) const;
  std::string findOverlap(const std::vector<Particle> &particles) const;
  fdm::coupler::Message makeStep(const std::vector<Particle> &particles) const;
  void solveVelocities(const std::vector<Particle> &particles, const fdm::coupler::Message &integrals);
  void storeStepDone(const fdm::coupler::Message &done);
  void scatter();
  void fillPerAtomArray();
  void allAgree(const std::string &problemOnRank0);
  void fail(const std::string &message);
  void printTiming(const char *what, const Timing &t, double wall, int runs) const;

  fdm::coupler::Options options_;
  double gravity_[3];
  bool move_;

  // The connection and what the fluid said at the handshake live as long as the process: an input
  // may run many times (and even unfix / fix again) over one coupled session.
  static std::unique_ptr<fdm::coupler::Transport> connection_;  // rank 0 only
  static bool connected_;                                          // every rank: handshake done
  static int sessionParticles_;                                    // N told to the fluid at the handshake
  static double alphaLambda_, rhoFluid_, delta_;
  static Timing total_;
  static int runs_;
  static double sessionStart_;

  int atomsAtInit_;                // atom count when init() checked the tags 1..N
  int natoms_;                     // N, particles are tags 1..N
  std::vector<double> solution_;   // 6N: (U, Omega) per particle by tag; warm start of the next solve
  std::vector<double> hydro_;      // 6N: hydrodynamic force and torque of the last StepDone, by tag
  int lastIterations_;
  double lastResidual_;
  long notConverged_;              // steps where the fluid reported converged=0
  Timing run_;                     // this run
  double runStart_;
  int nmax_;                       // rows allocated in array_atom
  double **perAtom_;
};

}  // namespace LAMMPS_NS

#endif
