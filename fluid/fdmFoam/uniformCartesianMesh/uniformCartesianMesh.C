#include "uniformCartesianMesh.H"
#include "volFields.H"
#include "cyclicPolyPatch.H"
#include "processorCyclicPolyPatch.H"
#include "DynamicList.H"

// * * * * * * * * * * * * Private Member Functions  * * * * * * * * * * * //

void Foam::uniformCartesianMesh::checkUniform() const
{
    // Every cell a cube of side delta_: the indicator functions (Eqs. 34-37)
    // and alpha_lambda = Delta^2 rho_f/eta assume one mesh size.
    const scalar cellVolume = pow3(delta_);
    const scalarField& V = mesh_.V();

    forAll(V, celli)
    {
        if (mag(V[celli] - cellVolume) > 1e-6*cellVolume)
        {
            FatalErrorInFunction
                << "The mesh (constant/polyMesh) is not a uniform Cartesian "
                << "mesh: cell " << celli << " at "
                << mesh_.cellCentres()[celli] << " has volume " << V[celli]
                << " but cubes of side Delta = " << delta_
                << " have " << cellVolume << nl
                << "    fdmFoam needs cubic cells of one size "
                << "(blockMesh with equal spacing in x, y and z)."
                << exit(FatalError);
        }
    }

    const vector L = bounds_.span();
    for (direction d = 0; d < vector::nComponents; ++d)
    {
        const scalar n = L[d]/delta_;
        if (mag(n - std::round(n)) > 1e-6*n)
        {
            FatalErrorInFunction
                << "The mesh extent in direction " << d << " (" << L[d]
                << ") is not a whole number of cells of size " << delta_
                << exit(FatalError);
        }
    }
}


void Foam::uniformCartesianMesh::findPeriodicDirections()
{
    periodic_ = Vector<bool>(false, false, false);
    const polyBoundaryMesh& patches = mesh_.boundaryMesh();

    // Sum of |face normal| per global cyclic patch. On a decomposed mesh the
    // faces of a cyclic split between processors sit on processorCyclic
    // patches, which refer to it; a processor may hold none of its faces.
    const label nGlobal = patches.nNonProcessor();
    List<vector> sumNormal(nGlobal, Zero);
    for (const polyPatch& pp : patches)
    {
        label owner = -1;
        if (isA<processorCyclicPolyPatch>(pp))
        {
            owner = refCast<const processorCyclicPolyPatch>(pp).referPatchID();
        }
        else if (pp.index() < nGlobal && isA<cyclicPolyPatch>(pp))
        {
            owner = pp.index();
        }
        if (owner < 0)
        {
            continue;
        }
        forAll(pp, facei)
        {
            sumNormal[owner] += cmptMag(pp.faceNormals()[facei]);
        }
    }
    Pstream::listCombineGather(sumNormal, plusEqOp<vector>());
    Pstream::listCombineScatter(sumNormal);

    forAll(sumNormal, patchi)
    {
        const vector& n = sumNormal[patchi];
        if (isA<cyclicPolyPatch>(patches[patchi]) && mag(n) > 0)
        {
            const direction d =
                (n.x() >= n.y() && n.x() >= n.z()) ? 0 : (n.y() >= n.z() ? 1 : 2);
            periodic_[d] = true;
        }
    }
}


void Foam::uniformCartesianMesh::buildCellMap()
{
    const vectorField& C = mesh_.cellCentres();
    const point& origin = bounds_.min();

    Vector<label> lo(labelMax, labelMax, labelMax);
    Vector<label> hi(labelMin, labelMin, labelMin);
    List<Vector<label>> ijk(C.size());

    forAll(C, celli)
    {
        for (direction d = 0; d < 3; ++d)
        {
            ijk[celli][d] = label(std::floor((C[celli][d] - origin[d])/delta_));
            lo[d] = min(lo[d], ijk[celli][d]);
            hi[d] = max(hi[d], ijk[celli][d]);
        }
    }

    if (C.empty())
    {
        localLo_ = Vector<label>(0, 0, 0);
        localN_ = Vector<label>(0, 0, 0);
        cellMap_.clear();
        return;
    }

    localLo_ = lo;
    localN_ = Vector<label>(hi.x()-lo.x()+1, hi.y()-lo.y()+1, hi.z()-lo.z()+1);
    cellMap_.setSize(localN_.x()*localN_.y()*localN_.z(), -1);

    forAll(C, celli)
    {
        const label li = ijk[celli].x() - lo.x();
        const label lj = ijk[celli].y() - lo.y();
        const label lk = ijk[celli].z() - lo.z();
        cellMap_[li + localN_.x()*(lj + localN_.y()*lk)] = celli;
    }
}


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::uniformCartesianMesh::uniformCartesianMesh(const fvMesh& mesh)
:
    mesh_(mesh),
    bounds_(mesh.points(), true),
    delta_(Foam::cbrt(gMax(mesh.V()))),
    nCells_(),
    periodic_(false, false, false)
{
    checkUniform();
    const vector L = bounds_.span();
    nCells_ = Vector<label>
    (
        label(std::round(L.x()/delta_)),
        label(std::round(L.y()/delta_)),
        label(std::round(L.z()/delta_))
    );
    findPeriodicDirections();
    buildCellMap();

    Info<< "Uniform Cartesian mesh: " << nCells_.x() << " x " << nCells_.y()
        << " x " << nCells_.z() << " cells of size Delta = " << delta_
        << ", bounds " << bounds_
        << ", periodic (x y z) = (" << periodic_.x() << " " << periodic_.y()
        << " " << periodic_.z() << ")" << endl;
}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

Foam::List<Foam::labelList> Foam::uniformCartesianMesh::boxFacePatches() const
{
    const polyBoundaryMesh& patches = mesh_.boundaryMesh();

    // onFace[6*patchi + f]: patch patchi has a face on box face f. A patch
    // may hold no face on a processor, and a cyclic split by the
    // decomposition lives on processorCyclic patches: gather over processors.
    const label nGlobal = patches.nNonProcessor();
    labelList onFace(6*nGlobal, 0);
    const scalar tol = 1e-6*delta_;

    for (const polyPatch& pp : patches)
    {
        label owner = -1;
        if (pp.index() < nGlobal)
        {
            owner = pp.index();
        }
        else if (isA<processorCyclicPolyPatch>(pp))
        {
            owner = refCast<const processorCyclicPolyPatch>(pp).referPatchID();
        }
        if (owner < 0)
        {
            continue;   // processor boundary: not a face of the box
        }
        for (const point& c : pp.faceCentres())
        {
            for (direction d = 0; d < 3; ++d)
            {
                if (mag(c[d] - bounds_.min()[d]) < tol)
                {
                    onFace[6*owner + 2*d] = 1;
                }
                else if (mag(c[d] - bounds_.max()[d]) < tol)
                {
                    onFace[6*owner + 2*d + 1] = 1;
                }
            }
        }
    }
    Pstream::listCombineGather(onFace, maxEqOp<label>());
    Pstream::listCombineScatter(onFace);

    List<labelList> result(6);
    for (label f = 0; f < 6; ++f)
    {
        DynamicList<label> onThis;
        for (label patchi = 0; patchi < nGlobal; ++patchi)
        {
            if (onFace[6*patchi + f])
            {
                onThis.append(patchi);
            }
        }
        result[f].transfer(onThis);
    }
    return result;
}
