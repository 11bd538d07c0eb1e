#include "boxLattice.H"
#include "volMesh.H"
#include "cyclicFvPatch.H"
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
}


// * * * * * * * * * * * * Private Member Functions  * * * * * * * * * * * * //

void Foam::boxLattice::recognise(const fvMesh& mesh)
{
    OStringStream why;

    if (Pstream::parRun())
    {
        why << "the mesh is decomposed over " << Pstream::nProcs()
            << " processors and FFTBox solves a whole box on one processor";
        reason_ = why.str();
        return;
    }

    const scalarField& V = mesh.V();
    if (V.empty())
    {
        reason_ = "the mesh has no cells";
        return;
    }
    const scalar delta = Foam::cbrt(gMax(V));
    forAll(V, celli)
    {
        if (mag(V[celli] - pow3(delta)) > 1e-6*pow3(delta))
        {
            why << "cell " << celli << " has volume " << V[celli]
                << ", not that of a cube of side " << delta
                << " (the mesh is not a uniform Cartesian one)";
            reason_ = why.str();
            return;
        }
    }

    const boundBox bounds(mesh.points(), false);
    for (int a = 0; a < 3; ++a)
    {
        const scalar cells = bounds.span()[a]/delta;
        n_[a] = long(std::round(cells));
        if (mag(cells - n_[a]) > 1e-6*cells || n_[a] < 1)
        {
            why << "the extent along " << axisName(a) << " is "
                << cells << " cells, not a whole number";
            reason_ = why.str();
            return;
        }
    }
    if (long(V.size()) != n_[0]*n_[1]*n_[2])
    {
        why << V.size() << " cells do not fill a box of " << n_[0] << " x "
            << n_[1] << " x " << n_[2];
        reason_ = why.str();
        return;
    }

    // every lattice site holds one cell
    const vectorField& C = mesh.cellCentres();
    ijk_.setSize(C.size());
    List<bool> filled(C.size(), false);
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
            return;
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
            return;
        }
        faceAxis_[facei] = static_cast<unsigned char>(axis);
    }

    // patches: cyclic pairs make an axis periodic, uncoupled patches on the
    // box's faces are walls
    std::array<bool, 3> periodic{{false, false, false}}, walled{{false, false, false}};
    patchAxis_.setSize(mesh.boundary().size(), -1);
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
            return;
        }
        if (isA<cyclicFvPatch>(patch))
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
                    const vector nf = cmptMag(patch.nf()()[facei]);
                    faceAxis = (nf.x() >= nf.y() && nf.x() >= nf.z()) ? 0 : (nf.y() >= nf.z() ? 1 : 2);
                    steps = (n_[faceAxis] == 1) ? 1 : 0;
                }
                if (steps != 1 || faceAxis < 0 || (axis >= 0 && faceAxis != axis))
                {
                    why << "cyclic patch " << patch.name() << " does not join"
                        << " opposite faces of the box";
                    reason_ = why.str();
                    return;
                }
                axis = faceAxis;
            }
            patchAxis_[patchi] = axis;
            periodic[axis] = true;
        }
        else if (patch.coupled())
        {
            why << "patch " << patch.name() << " is a coupled patch of type "
                << patch.type() << " (only cyclic pairs are periodic axes)";
            reason_ = why.str();
            return;
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
}


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::boxLattice::boxLattice(const fvMesh& mesh)
:
    reason_(),
    n_{{0, 0, 0}},
    wallAxis_(-1)
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
    return s.str();
}


// ************************************************************************* //
