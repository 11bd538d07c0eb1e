#include "boxLattice.H"
#include "volMesh.H"
#include "cyclicFvPatch.H"
#include "processorFvPatch.H"
#include "processorCyclicFvPatch.H"
#include "emptyFvPatch.H"
#include "boundBox.H"
#include "OStringStream.H"
#include <map>
#include <memory>

// * * * * * * * * * * * * * * * Local Functions * * * * * * * * * * * * * * //

namespace
{
    const char* axisName(const int a)
    {
        return a == 0 ? "x" : (a == 1 ? "y" : "z");
    }

    //- The axis of the largest component of |v| (a face normal's axis)
    int dominantAxis(const Foam::vector& v)
    {
        const Foam::vector m = Foam::cmptMag(v);
        return (m.x() >= m.y() && m.x() >= m.z()) ? 0 : (m.y() >= m.z() ? 1 : 2);
    }
}


// * * * * * * * * * * * * Private Member Functions  * * * * * * * * * * * * //

void Foam::boxLattice::recognise(const fvMesh& mesh)
{
    // Collective first (every processor of a decomposed mesh takes part):
    // the cell size, the box and the number of cells of the whole mesh
    const scalarField& V = mesh.V();
    const label nCells = returnReduce(V.size(), sumOp<label>());
    if (nCells == 0)
    {
        reason_ = "the mesh has no cells";
        return;
    }
    const scalar delta = Foam::cbrt(gMax(V));
    const boundBox bounds(mesh.points(), true);

    std::array<bool, 3> periodic{{false, false, false}}, walled{{false, false, false}};
    OStringStream why;
    for (int a = 0; a < 3 && reason_.empty(); ++a)
    {
        const scalar cells = bounds.span()[a]/delta;
        n_[a] = long(std::round(cells));
        if (mag(cells - n_[a]) > 1e-6*cells || n_[a] < 1)
        {
            why << "the extent along " << axisName(a) << " is "
                << cells << " cells, not a whole number";
            reason_ = why.str();
        }
    }
    if (reason_.empty() && long(nCells) != n_[0]*n_[1]*n_[2])
    {
        why << nCells << " cells do not fill a box of " << n_[0] << " x "
            << n_[1] << " x " << n_[2];
        reason_ = why.str();
    }
    if (reason_.empty())
    {
        recogniseLocal(mesh, delta, bounds, periodic, walled);
    }

    // Every processor's part must be one: the first reason found is the
    // reason of all (the fallback is then taken everywhere alike)
    if (decomposed_)
    {
        List<string> reasons(Pstream::nProcs());
        reasons[Pstream::myProcNo()] = reason_;
        Pstream::gatherList(reasons);
        Pstream::scatterList(reasons);
        forAll(reasons, proci)
        {
            if (!reasons[proci].empty())
            {
                OStringStream first;
                first << "on processor " << proci << ": " << reasons[proci].c_str();
                reason_ = first.str();
                return;
            }
        }
        for (int a = 0; a < 3; ++a)
        {
            periodic[a] = returnReduce(periodic[a], orOp<bool>());
            walled[a] = returnReduce(walled[a], orOp<bool>());
        }
    }
    else if (!reason_.empty())
    {
        return;
    }

    wallAxis_ = -1;
    for (int a = 0; a < 3; ++a)
    {
        if (periodic[a] && walled[a])
        {
            why << "axis " << axisName(a) << " has both cyclic and wall faces";
            reason_ = why.str();
            return;
        }
        if (walled[a])
        {
            if (wallAxis_ >= 0)
            {
                why << "walls across " << axisName(wallAxis_) << " and "
                    << axisName(a) << ": FFTBox solves boxes with walls on at"
                    << " most one pair of faces";
                reason_ = why.str();
                return;
            }
            wallAxis_ = a;
        }
    }
    if (decomposed_ && wallAxis_ < 0)
    {
        why << "the mesh is decomposed over " << Pstream::nProcs()
            << " processors and is periodic along every axis: FFTBox solves"
            << " a decomposed box only with walls across one axis";
        reason_ = why.str();
    }
}


bool Foam::boxLattice::recogniseLocal
(
    const fvMesh& mesh,
    const scalar delta,
    const boundBox& bounds,
    std::array<bool, 3>& periodic,
    std::array<bool, 3>& walled
)
{
    OStringStream why;
    const scalarField& V = mesh.V();
    forAll(V, celli)
    {
        if (mag(V[celli] - pow3(delta)) > 1e-6*pow3(delta))
        {
            why << "cell " << celli << " has volume " << V[celli]
                << ", not that of a cube of side " << delta
                << " (the mesh is not a uniform Cartesian one)";
            reason_ = why.str();
            return false;
        }
    }

    // every lattice site holds one cell (here; the count above makes it
    // every site of the box)
    const vectorField& C = mesh.cellCentres();
    ijk_.setSize(C.size());
    std::vector<bool> filled(std::size_t(n_[0])*n_[1]*n_[2], false);
    forAll(C, celli)
    {
        for (int a = 0; a < 3; ++a)
        {
            ijk_[celli][a] =
                long(std::floor((C[celli][a] - bounds.min()[a])/delta));
            ijk_[celli][a] = std::min(std::max(ijk_[celli][a], 0L), n_[a] - 1);
        }
        const long site = ijk_[celli][0] + n_[0]*(ijk_[celli][1] + n_[1]*ijk_[celli][2]);
        if (filled[site])
        {
            why << "two cells share the lattice site of cell " << celli;
            reason_ = why.str();
            return false;
        }
        filled[site] = true;
    }

    // internal faces join lattice neighbours
    const labelUList& own = mesh.owner();
    const labelUList& nei = mesh.neighbour();
    faceAxis_.setSize(nei.size());
    forAll(nei, facei)
    {
        int axis = -1, steps = 0;
        for (int a = 0; a < 3; ++a)
        {
            const long d = ijk_[nei[facei]][a] - ijk_[own[facei]][a];
            if (d != 0)
            {
                ++steps;
                axis = (std::abs(d) == 1) ? a : -2;
            }
        }
        if (steps != 1 || axis < 0)
        {
            why << "internal face " << facei << " does not join two lattice"
                << " neighbours";
            reason_ = why.str();
            return false;
        }
        faceAxis_[facei] = static_cast<unsigned char>(axis);
    }

    // patches: cyclic pairs make an axis periodic, uncoupled patches on the
    // box's faces are walls, processor patches join the parts of a
    // decomposed box
    patchFaceAxis_.setSize(mesh.boundary().size());
    patchFaceOffset_.setSize(mesh.boundary().size());
    forAll(mesh.boundary(), patchi)
    {
        const fvPatch& patch = mesh.boundary()[patchi];
        if (patch.size() == 0)
        {
            continue;
        }
        if (isA<emptyFvPatch>(patch))
        {
            why << "patch " << patch.name() << " is empty (a 2-D mesh)";
            reason_ = why.str();
            return false;
        }
        if (isA<processorFvPatch>(patch))
        {
            // each face normal to an axis (a split within a plane makes a
            // staircase of faces normal to different axes)
            const vectorField nf(patch.nf());
            labelList& axes = patchFaceAxis_[patchi];
            labelList& offsets = patchFaceOffset_[patchi];
            axes.setSize(nf.size());
            offsets.setSize(nf.size());
            forAll(nf, facei)
            {
                const int a = dominantAxis(nf[facei]);
                if (mag(nf[facei][a]) < 1 - 1e-6)
                {
                    why << "face " << facei << " of processor patch "
                        << patch.name() << " is not normal to an axis";
                    reason_ = why.str();
                    return false;
                }
                axes[facei] = a;
                offsets[facei] = (nf[facei][a] > 0) ? 0 : -1;
                if (isA<processorCyclicFvPatch>(patch))
                {
                    periodic[a] = true;
                }
            }
        }
        else if (isA<cyclicFvPatch>(patch))
        {
            const cyclicFvPatch& cyc = refCast<const cyclicFvPatch>(patch);
            const labelUList& mine = cyc.faceCells();
            const labelUList& theirs = cyc.neighbPatch().faceCells();
            int axis = -1;
            forAll(mine, facei)
            {
                int faceAxis = -1, steps = 0;
                for (int a = 0; a < 3; ++a)
                {
                    const long d = std::abs(ijk_[theirs[facei]][a] - ijk_[mine[facei]][a]);
                    if (d != 0)
                    {
                        ++steps;
                        faceAxis = (d == n_[a] - 1) ? a : -2;
                    }
                }
                if (steps == 0)
                {
                    // one cell along the axis, its own neighbour: the face's
                    // normal tells the axis
                    faceAxis = dominantAxis(patch.nf()()[facei]);
                    steps = (n_[faceAxis] == 1) ? 1 : 0;
                }
                if (steps != 1 || faceAxis < 0 || (axis >= 0 && faceAxis != axis))
                {
                    why << "cyclic patch " << patch.name() << " does not join"
                        << " opposite faces of the box";
                    reason_ = why.str();
                    return false;
                }
                axis = faceAxis;
            }
            patchFaceAxis_[patchi] = labelList(mine.size(), axis);
            patchFaceOffset_[patchi] = labelList(mine.size(), 0);
            periodic[axis] = true;
        }
        else if (patch.coupled())
        {
            why << "patch " << patch.name() << " is a coupled patch of type "
                << patch.type() << " (only cyclic pairs are periodic axes)";
            reason_ = why.str();
            return false;
        }
        else
        {
            for (const point& c : patch.Cf())
            {
                for (int a = 0; a < 3; ++a)
                {
                    if
                    (
                        mag(c[a] - bounds.min()[a]) < 1e-6*delta
                     || mag(c[a] - bounds.max()[a]) < 1e-6*delta
                    )
                    {
                        walled[a] = true;
                    }
                }
            }
        }
    }
    return true;
}


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::boxLattice::boxLattice(const fvMesh& mesh)
:
    reason_(),
    n_{{0, 0, 0}},
    wallAxis_(-1),
    decomposed_(Pstream::parRun())
{
    recognise(mesh);
}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

const Foam::boxLattice* Foam::boxLattice::find(const lduMesh& mesh)
{
    // one lattice per mesh for the whole run (the meshes of a run do not move)
    static std::map<const lduMesh*, std::unique_ptr<boxLattice>> lattices;
    auto it = lattices.find(&mesh);
    if (it == lattices.end())
    {
        const fvMesh* fv = dynamic_cast<const fvMesh*>(&mesh);
        if (!fv)
        {
            return nullptr;
        }
        it = lattices.emplace(&mesh, std::unique_ptr<boxLattice>(new boxLattice(*fv))).first;
    }
    return it->second.get();
}


Foam::string Foam::boxLattice::description() const
{
    OStringStream s;
    s << n_[0] << " x " << n_[1] << " x " << n_[2] << " cells, ";
    if (wallAxis_ < 0)
    {
        s << "periodic";
    }
    else
    {
        s << "walls across " << axisName(wallAxis_);
    }
    if (decomposed_)
    {
        s << ", decomposed over " << Pstream::nProcs() << " processors";
    }
    return s.str();
}


// ************************************************************************* //
