/* The fluid's part of Eq. (31) where no fluid solve gives it: each particle as an isolated sphere in
   Stokes flow, drag D = diag(6 pi eta a, 8 pi eta a^3). Used with transport none (DEM only: a fluid at
   rest, or a simple shear with background_shear) and on the particle steps between fluid steps
   (fluid_every K, held_drag.h), where the rigid-body blocks of Eq. (31) become D. No LIGGGHTS. */

#ifndef FDM_ISOLATED_SPHERE_DRAG_H
#define FDM_ISOLATED_SPHERE_DRAG_H

#include "fdm/coupler.h"
#include "gathered_particles.h"

#include <vector>

namespace fdm {

// "Volumes" whose rigid-body blocks of Eq. (31), (rho_f/alpha_lambda) [Vu, J], are the drag D, so that
// Eq. (31) reads [D + R^SG] u = F^c + F^ext + buoyant weight + the fluid's part.
coupler::Volumes isolatedSphereVolumes(const std::vector<GatheredParticle> &particles, long long step,
                                       double viscosity, double alphaLambda, double rhoFluid);

// The simple shear u = G (y - y_centre) e_x, whose vorticity turns a sphere at Omega = -G/2 e_z: each
// sphere's drag toward it, 6 pi eta a u(x_p) and 8 pi eta a^3 Omega, is set in integrals; with
// fluidStress (7 per particle: S xx xy xz yy yz zz, trace s) the sphere's own stresslet in it,
// (20/3) pi eta a^3 E with E_xy = G/2 (Kim & Karrila's S, docs/dem.md).
void backgroundShearDrag(const std::vector<GatheredParticle> &particles, double yCentre, double viscosity,
                         double shearRate, coupler::Integrals &integrals, std::vector<double> *fluidStress);

}  // namespace fdm

#endif
