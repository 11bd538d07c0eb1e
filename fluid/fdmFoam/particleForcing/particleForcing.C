#include "particleForcing.H"
#include "fdm/coupler.h"

// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::particleForcing::particleForcing
(
    const uniformCartesianMesh& grid,
    scalar b,
    scalar c,
    scalar alphaLambda,
    scalar rhoFluid
)
:
    grid_(grid),
    b_(b),
    c_(c),
    alpha_(alphaLambda),
    rhoFluid_(rhoFluid),
    offset_(1, 0),
    IuScale_(grid.mesh().nCells(), 1.0),
    covered_(grid.mesh().nCells(), false),
    du_(grid.mesh().nCells(), Zero),
    dLambda_(grid.mesh().nCells(), Zero),
    maxCoreSlip_(0),
    lambdaNorm_(0),
    wallOverlapReported_(false)
{}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

Foam::string Foam::particleForcing::checkInsideDomain
(
    const List<fdmParticle>& particles
) const
{
    // Periodic directions: the centre must be in the box (the DEM wraps it).
    // Walls: the sphere must be inside them, up to fdm::coupler::contactOverlapTolerance radii:
    // a contact spring pressed into a wall (pair_style fdm/subgrid contact,
    // docs/contact.md) overlaps it by a small fraction of the roughness h_r;
    // the indicator function just loses the thin cap beyond the wall (the
    // stencil is clipped there). Warned once; deeper is an escape: fatal.
    const boundBox& bb = grid_.bounds();
    const char* axis = "xyz";
    const scalar eps = 1e-12*grid_.delta();

    for (const fdmParticle& p : particles)
    {
        if (!(p.radius > 0))
        {
            OStringStream os;
            os  << "particle " << p.tag << " has radius " << p.radius;
            return os.str();
        }
        for (direction d = 0; d < 3; ++d)
        {
            const bool periodic = grid_.periodic()[d];
            const scalar margin = periodic ? 0 : p.radius;
            const scalar below = bb.min()[d] - (p.x[d] - margin);  // > 0: past the lower face
            const scalar above = (p.x[d] + margin) - bb.max()[d];  // > 0: past the upper face
            const scalar overlap = max(below, above);
            if (std::isfinite(p.x[d]) && overlap <= eps)
            {
                continue;
            }
            const scalar allowed = periodic ? 0 : fdm::coupler::contactOverlapTolerance*p.radius;
            const scalar face = below > above ? bb.min()[d] : bb.max()[d];
            if (std::isfinite(p.x[d]) && overlap <= allowed)
            {
                if (!wallOverlapReported_)
                {
                    wallOverlapReported_ = true;
                    Warning
                        << "fdmFoam: particle " << p.tag << " at " << p.x
                        << " with radius " << p.radius << " overlaps the wall "
                        << axis[d] << " = " << face << " by " << overlap
                        << " (" << overlap/p.radius << " radii): accepted as a "
                        << "contact pressed into the wall (up to "
                        << fdm::coupler::contactOverlapTolerance << " radii; the sphere's cap "
                        << "beyond the wall has no forcing). Reported once."
                        << endl;
                }
                continue;
            }
            OStringStream os;
            os  << "particle " << p.tag << " at " << p.x
                << " with radius " << p.radius << " lies outside the "
                << "OpenFOAM mesh (constant/polyMesh) in "
                << axis[d] << ": the mesh spans " << bb.min()[d]
                << " .. " << bb.max()[d];
            if (periodic)
            {
                os  << " (periodic)";
            }
            else
            {
                os  << " (walls): it crosses the wall " << axis[d] << " = "
                    << face << " by " << overlap << " (" << overlap/p.radius
                    << " radii, more than the " << fdm::coupler::contactOverlapTolerance
                    << " radii accepted for a contact pressed into a wall): "
                    << "it escapes through the wall";
            }
            return os.str();
        }
    }
    return string::null;
}


void Foam::particleForcing::setParticles(const List<fdmParticle>& particles)
{
    particles_ = particles;

    cell_.clear();
    Iu_.clear();
    Ilambda_.clear();
    r_.clear();
    offset_.setSize(particles_.size() + 1);

    const scalarField& V = grid_.mesh().V();
    scalarField IuSum(V.size(), 0.0);
    labelField count(V.size(), 0);

    const scalar delta = grid_.delta();
    const point& origin = grid_.bounds().min();
    const Vector<label>& n = grid_.nCells();

    forAll(particles_, p)
    {
        offset_[p] = cell_.size();
        const fdmParticle& part = particles_[p];
        const scalar reach = part.radius + c_*delta;

        // Range of global indices touched, unwrapped; periodic directions
        // wrap the index, bounded ones clip it.
        label lo[3], hi[3];
        for (direction d = 0; d < 3; ++d)
        {
            lo[d] = label(std::floor((part.x[d] - reach - origin[d])/delta));
            hi[d] = label(std::floor((part.x[d] + reach - origin[d])/delta));
            if (!grid_.periodic()[d])
            {
                lo[d] = max(lo[d], label(0));
                hi[d] = min(hi[d], n[d] - 1);
            }
        }

        for (label k = lo[2]; k <= hi[2]; ++k)
        for (label j = lo[1]; j <= hi[1]; ++j)
        for (label i = lo[0]; i <= hi[0]; ++i)
        {
            // Unwrapped centre relative to the particle: nearest image
            const point centre = origin + delta*vector(i + 0.5, j + 0.5, k + 0.5);
            const vector r = centre - part.x;
            const scalar dist = mag(r);
            // A cell centre exactly at the reach (a sphere on a lattice
            // point of the cell, as in mirror-symmetric scenes) must fall on
            // the same side at every mirror image: not the distance's last
            // bit but a margin of 1e-9 cells decides, and such cells are out.
            if (dist > reach - 1e-9*delta)
            {
                continue;
            }
            const label iw = (i % n[0] + n[0]) % n[0];
            const label jw = (j % n[1] + n[1]) % n[1];
            const label kw = (k % n[2] + n[2]) % n[2];
            const label celli = grid_.cellLabel(iw, jw, kw);
            if (celli < 0)
            {
                continue;   // on another processor
            }
            const scalar s = dist - part.radius;
            const scalar Iu = 0.5*(1 - std::tanh(b_*s/delta));     // Eq. (37)

            cell_.append(celli);
            Iu_.append(Iu);
            Ilambda_.append(1.0);                                  // Eq. (36)
            r_.append(r);
            IuSum[celli] += Iu;
            ++count[celli];
        }
    }
    offset_[particles_.size()] = cell_.size();

    // Overlaps: I_lambda = 1/n where n particles cover a cell
    forAll(cell_, e)
    {
        Ilambda_[e] = 1.0/count[cell_[e]];
    }
    DynamicList<label> coveredCells(cell_.size());
    forAll(count, celli)
    {
        covered_[celli] = count[celli] > 0;
        IuScale_[celli] = 1.0/max(scalar(1), IuSum[celli]);
        if (covered_[celli])
        {
            coveredCells.append(celli);
        }
    }
    coveredCells_.transfer(coveredCells);

    // The rigid-body block of Eq. (31) (fdm/coupler.h, Volumes): the discrete
    // sphere's volume, first moment and inertia tensor, so that U + Omega x r
    // integrates exactly as the fluid's u* does
    namespace layout = fdm::coupler::layout;
    const label nv = layout::volumesWidth;
    volumes_.setSize(nv*particles_.size());
    forAll(particles_, p)
    {
        scalar Vu = 0;
        vector m1(Zero);
        symmTensor J(Zero);
        for (label e = offset_[p]; e < offset_[p+1]; ++e)
        {
            const vector& r = r_[e];
            const scalar w = Iu_[e]*V[cell_[e]];
            Vu += w;
            m1 += w*r;
            J += w*(magSqr(r)*symmTensor::I - sqr(r));
        }
        scalar* rec = &volumes_[nv*p];
        rec[layout::volVu] = Vu;
        for (direction d = 0; d < 3; ++d)
        {
            rec[layout::volM1x + d] = m1[d];
        }
        rec[layout::volJxx] = J.xx();
        rec[layout::volJxy] = J.xy();
        rec[layout::volJxz] = J.xz();
        rec[layout::volJyy] = J.yy();
        rec[layout::volJyz] = J.yz();
        rec[layout::volJzz] = J.zz();
    }
}


void Foam::particleForcing::truncateLambda(volVectorField& lambda) const
{
    vectorField& l = lambda.primitiveFieldRef();
    forAll(l, celli)
    {
        if (!covered_[celli])
        {
            l[celli] = Zero;
        }
    }
    lambda.correctBoundaryConditions();
}


Foam::List<Foam::scalar> Foam::particleForcing::integrals
(
    const volVectorField& U,
    const volVectorField& lambda
) const
{
    // Per particle the coupler's Volumes record, then its Integrals record
    namespace layout = fdm::coupler::layout;
    const label nv = layout::volumesWidth;
    const label width = nv + layout::integralsWidth;
    List<scalar> result(width*particles_.size(), 0.0);

    const scalarField& V = grid_.mesh().V();
    const vectorField& u = U.primitiveField();
    const vectorField& l = lambda.primitiveField();

    forAll(particles_, p)
    {
        vector F(Zero), T(Zero);
        for (label e = offset_[p]; e < offset_[p+1]; ++e)
        {
            const label celli = cell_[e];
            const vector& r = r_[e];
            // Integrand of Eq. (32): I_u u*/alpha - I_lambda lambda^n
            const vector g = Iu_[e]*u[celli]/alpha_ - Ilambda_[e]*l[celli];
            F += g*V[celli];
            T += (r ^ g)*V[celli];
        }
        scalar* rec = &result[width*p];
        for (label k = 0; k < nv; ++k)
        {
            rec[k] = volumes_[nv*p + k];   // summed over processors below
        }
        for (direction d = 0; d < 3; ++d)
        {
            rec[nv + layout::iFx + d] = rhoFluid_*F[d];
            rec[nv + layout::iTx + d] = rhoFluid_*T[d];
        }
    }

    // Particles shared by processors: sum the partial integrals
    Pstream::listCombineGather(result, plusEqOp<scalar>());
    Pstream::listCombineScatter(result);
    return result;
}


Foam::scalar Foam::particleForcing::correct
(
    volVectorField& U,
    volVectorField& lambda,
    const List<scalar>& velocities
)
{
    const scalarField& V = grid_.mesh().V();
    vectorField& u = U.primitiveFieldRef();
    vectorField& l = lambda.primitiveFieldRef();

    // Corrections are computed from u* for every particle before any is
    // applied, so that overlapping particles see the same u*. They are
    // summed in fields kept zero outside the particles' cells (du_,
    // dLambda_), which are the only cells visited.
    vectorField& du = du_;
    vectorField& dLambda = dLambda_;
    scalar sumDl2 = 0, sumL2 = 0;
    maxCoreSlip_ = 0;

    forAll(particles_, p)
    {
        const vector Up(velocities[6*p], velocities[6*p+1], velocities[6*p+2]);
        const vector Wp(velocities[6*p+3], velocities[6*p+4], velocities[6*p+5]);
        for (label e = offset_[p]; e < offset_[p+1]; ++e)
        {
            const label celli = cell_[e];
            const vector slip = Up + (Wp ^ r_[e]) - u[celli];
            const vector dl = Ilambda_[e]*slip/alpha_;              // Eq. (38c)
            dLambda[celli] += dl;
            du[celli] += Iu_[e]*IuScale_[celli]*slip;               // Eq. (38d)
            if (Iu_[e] > 0.99)
            {
                maxCoreSlip_ = max(maxCoreSlip_, mag(slip));
            }
        }
    }
    for (const label celli : coveredCells_)
    {
        u[celli] += du[celli];
        l[celli] += dLambda[celli];
    }

    // The residual is the change of the cell's lambda, not the sum of each
    // particle's share: where two particles overlap (I_lambda = 0.5 each) and
    // move apart, the two shares stay finite and opposite at convergence.
    forAll(cell_, e)
    {
        // each covered cell once: weight by 1/count via Ilambda
        const label celli = cell_[e];
        sumDl2 += Ilambda_[e]*magSqr(dLambda[celli])*V[celli];
        sumL2 += Ilambda_[e]*magSqr(l[celli])*V[celli];
    }

    for (const label celli : coveredCells_)
    {
        du[celli] = Zero;
        dLambda[celli] = Zero;
    }

    reduce(sumDl2, sumOp<scalar>());
    reduce(sumL2, sumOp<scalar>());
    reduce(maxCoreSlip_, maxOp<scalar>());

    U.correctBoundaryConditions();
    lambda.correctBoundaryConditions();

    lambdaNorm_ = Foam::sqrt(sumL2);
    return Foam::sqrt(sumDl2/max(sumL2, VSMALL));
}


Foam::List<Foam::scalar> Foam::particleForcing::hydrodynamicForces
(
    const volVectorField& lambda
) const
{
    List<scalar> result(6*particles_.size(), 0.0);
    const scalarField& V = grid_.mesh().V();
    const vectorField& l = lambda.primitiveField();

    forAll(particles_, p)
    {
        vector F(Zero), T(Zero);
        for (label e = offset_[p]; e < offset_[p+1]; ++e)
        {
            const vector f = -rhoFluid_*Ilambda_[e]*l[cell_[e]]*V[cell_[e]];
            F += f;
            T += r_[e] ^ f;
        }
        for (direction d = 0; d < 3; ++d)
        {
            result[6*p + d] = F[d];
            result[6*p + 3 + d] = T[d];
        }
    }
    Pstream::listCombineGather(result, plusEqOp<scalar>());
    Pstream::listCombineScatter(result);
    return result;
}


Foam::List<Foam::scalar> Foam::particleForcing::stresslets
(
    const volVectorField& lambda,
    const volScalarField& p
) const
{
    const label width = 7;    // S(6), s: fdm::coupler::layout dSxx..dTrace
    List<scalar> result(width*particles_.size(), 0.0);
    const scalarField& V = grid_.mesh().V();
    const vectorField& l = lambda.primitiveField();
    const scalarField& pk = p.primitiveField();

    forAll(particles_, pi)
    {
        // Eq. (12): inside the particle the strain rate vanishes, so the
        // stress of Eq. (11) is the pressure alone. Same indicator and cells
        // as the force (hydrodynamicForces), so that overlaps split alike.
        symmTensor S(Zero);
        scalar s = 0;
        for (label e = offset_[pi]; e < offset_[pi+1]; ++e)
        {
            const label celli = cell_[e];
            const scalar w = rhoFluid_*Ilambda_[e]*V[celli];
            S -= w*dev(symm(l[celli]*r_[e]));
            s -= w*((l[celli] & r_[e]) + 3*pk[celli]);
        }
        scalar* rec = &result[width*pi];
        rec[0] = S.xx();
        rec[1] = S.xy();
        rec[2] = S.xz();
        rec[3] = S.yy();
        rec[4] = S.yz();
        rec[5] = S.zz();
        rec[6] = s;
    }

    // Particles shared by processors: sum the partial integrals
    Pstream::listCombineGather(result, plusEqOp<scalar>());
    Pstream::listCombineScatter(result);
    return result;
}


void Foam::particleForcing::indicator(volScalarField& field) const
{
    scalarField& f = field.primitiveFieldRef();
    f = 0;
    forAll(cell_, e)
    {
        f[cell_[e]] += Iu_[e];
    }
    field.correctBoundaryConditions();
}


void Foam::particleForcing::pseudoTimeCoefficient
(
    volScalarField& rDTau,
    scalar rInside,
    scalar rOutside
) const
{
    scalarField& f = rDTau.primitiveFieldRef();
    forAll(f, celli)
    {
        f[celli] = covered_[celli] ? rInside : rOutside;
    }
    rDTau.correctBoundaryConditions();
}
