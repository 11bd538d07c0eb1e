/* pair_style fdm/subgrid -- close interactions of the FDM suspension model (Orsi, Lobry & Peters 2023):
   the frame-invariant sub-grid lubrication blocks (Eq. 21 with Appendix C.2 for pairs, Eq. D.6 for
   walls) and the frictional contact of section 6 (roughness height h_r, Coulomb friction mu_s).

   Syntax (docs/dem.md):
     pair_style fdm/subgrid [lubrication yes|no] [model calibrated|cutoff] [calibration FILE] [cutoff k]
                            [wall_cutoff k] [contact kn kt mu_s h_r] [wall FACE ux uy uz] ... [unstable_step error|warn]
                            [contact_integration implicit|explicit]
     pair_coeff * *

   The contact forces go into f and torque at every force evaluation, like any LIGGGHTS pair style
   (they enter F^c of Eq. 32). With contact_integration implicit (the default) the springs are also
   taken into Eq. (31) at the end of the step (contact_springs.h, docs/contact.md 2b): the fix asks
   for their blocks (collectSpringBlocks) and adds the implicit part of the force after the solve. The sub-grid blocks are not forces: they are the matrix R^SG of
   Eq. (31), which fix fdm/couple solves implicitly. The fix asks for them once per time step
   (collectBlocks); the viscosity and mesh size are those the fluid solver announced at the
   handshake, asked of the coupling session (coupling_session.h), which also says which box faces
   are the fluid case's walls. The resistance functions come from the project's resistance library
   (dem/resistance/). */

#ifndef FDM_PAIR_FDM_SUBGRID_H
#define FDM_PAIR_FDM_SUBGRID_H

#include "pair.h"
#include "configuration_checks.h"
#include "subgrid_options.h"

#include <memory>
#include <string>
#include <vector>

namespace fdm {
namespace resistance {
class SubgridModel;
class SubgridCalibration;
}
}

namespace LAMMPS_NS {

class PairFdmSubgrid : public Pair {
 public:
  PairFdmSubgrid(class LAMMPS *);
  ~PairFdmSubgrid();
  void compute(int, int);
  void settings(int, char **);
  void coeff(int, char **);
  void init_style();
  void init_list(int, class NeighList *);
  double init_one(int, int);
  void *extract(const char *, int &);

  // A planar wall on a non-periodic face of the box, moving in its own plane (subgrid_options.h).
  using Wall = fdm::SubgridWall;

  // Blocks of R^SG of this rank's pairs and particle-wall gaps, for the fix to gather on rank 0, in
  // the records of fdm::subgrid (particle_velocity_system.h), with their stress rows if withStress;
  // wallIndex (if given): for each wall block, the index of its wall in walls() (the records do not say).
  void collectBlocks(bool withStress, std::vector<double> &pairs, std::vector<double> &walls,
                     std::vector<double> *wallIndex = nullptr);

  // The implicit contact springs of the last compute (records of fdm::springs, particle_velocity_system.h):
  // R_c = c1 dt B^T K B (Eq. C3 of docs/contact.md) with c1 the weight of U_{n+1} in the next
  // position update (3/2 ab2, 1 euler). Each contact once (the side of the lower tag keeps it).
  // wallIndex (optional): the wall (index in walls()) of each wall spring block, in the same order
  void collectSpringBlocks(double c1, double dt, std::vector<double> &pairs, std::vector<double> &walls,
                           std::vector<double> *wallIndex = nullptr) const;
  bool implicitContact() const { return contactActive() && options_.implicitContact; }

  bool lubricationActive() const { return options_.lubrication && model_; }
  bool contactActive() const { return options_.hr > 0; }
  double roughness() const { return options_.hr; }
  const std::vector<Wall> &walls() const { return options_.walls; }
  // The contact histories, for fix fdm/couple's checkpoints (null without contact, or without walls)
  class FixContactHistoryFdm *contactHistory() const;
  class FixPropertyAtom *wallHistory() const { return wallHistory_; }
  // per atom and wall: the tangential spring elongation (3) and whether the contact was on at the
  // last force evaluation (1, so that a new contact is known; see contactForces)
  static const int wallHistoryWidth = 4;
  // Per-atom contact stresslet S^c (Eq. 52: xx xy xz yy yz zz) of the last compute, if requested.
  void requestContactStress(bool on) { contactStressRequested_ = on; }
  const double *contactStress(int i) const
  {
    static const double none[6] = {0, 0, 0, 0, 0, 0};
    return contactStress_ && i < nmaxStress_ ? contactStress_[i] : none;
  }
  // The force this rank's particle-wall contacts exert on each wall in the last compute (minus the
  // contact force on the particles; 3 per wall, in the order of walls()), for fix fdm/couple's wall
  // loads (the momentum balance of a sheared suspension, docs/profiles.md).
  const std::vector<double> &wallContactLoads() const { return wallContactLoads_; }
  // Wall-clock seconds of this rank's contact forces (compute) since the last call, which resets them
  // (fix fdm/couple's breakdown of the particle step)
  double takeContactSeconds();
  // Contacts (pair and wall) found by this rank in the last compute.
  long contactsLast() const { return contactsLast_; }
  // The deepest overlap of two spheres this rank's last compute found: depth = -gap/min(a_i, a_j)
  // (negative: no overlap), the gap [m] and the two tags
  using Overlap = fdm::Overlap;   // configuration_checks.h
  const Overlap &deepestOverlap() const { return deepest_; }
  // The time-step limits of the contact springs, dt k/zeta below 1 (ab2) or 2 (euler), docs/contact.md
  // section 3c; called by fix fdm/couple, which knows the time step and its integrator.
  void checkTimeStep(double dt, bool adamsBashforth);

  int computeflag;   // read and reset by fix contacthistory (pre_exchange)

 private:
  void allocate();
  void fluidParameters();
  void checkCalibration();
  void contactForces();
  void wallContactForces();
  void contactLaw(const double n[3], double normalForce, const double vr[3], double dt, double shear[3],
                  double force[3], double nxft[3]) const;
  void addContactStress(int i, const double force[3], const double branch[3], double weight);
  std::string wallName(const Wall &w) const;
  void checkResolution();
  // Resistances of the contact modes at surface gap h (Stokes drag + sub-grid lubrication): two free
  // spheres of radius a (normal, and slip of the contact points), a sphere and a wall.
  // the keywords' values (subgrid_options.h), and the sub-grid model to be built anew (constructor: the defaults)
  void applySettings(const fdm::SubgridOptions &options);
  void pairResistance(double a, double h, double &normal, double &slip) const;
  void wallResistance(double a, double h, double &normal, double &slip) const;

  // settings
  fdm::SubgridOptions options_;    // the keywords of the pair_style line (subgrid_options.h)

  // from the fluid solver at the handshake (coupling session)
  double viscosity_, meshSize_;
  // pairs, walls: two cut-off models (their cut-offs differ); the calibrated model serves both
  std::shared_ptr<fdm::resistance::SubgridModel> model_, wallModel_;
  std::unique_ptr<fdm::resistance::SubgridCalibration> calibration_;  // model calibrated

  double rangeGap_;            // largest surface gap with any pair interaction (contact or lubrication)
  std::string uncalibratedTangential_;  // radius pairs whose sliding, rolling and twist the table lacks
  double rmin_, rmax_, distanceFactor_;
  class FixContactHistory *history_;
  class FixPropertyAtom *wallHistory_;
  bool contactStressRequested_;
  int nmaxStress_;
  double **contactStress_;
  long contactsLast_;
  double contactSeconds_ = 0;
  Overlap deepest_;
  std::vector<double> wallContactLoads_;  // 3 per wall: force of the contacts on the wall (this rank)
  bool reported_;
  double checkedTimeStep_;     // the time step last checked (checked again if it changes)
  // the contacts of the last compute, for the implicit spring blocks (local index j, or -1 - wall)
  struct Contact {
    int i, j;
    double n[3], leverI, leverJ, branch[3], weight;
    double normalForce, ft[3];  // F_n and the explicit tangential force on i (Coulomb's law in the solve)
  };
  std::vector<Contact> contacts_;
};

}  // namespace LAMMPS_NS

#endif
