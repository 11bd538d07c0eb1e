"""The fluid side of a coupled case: fdmFoam's OpenFOAM case folder (system/, constant/, 0/) for a box
meshed with cubic cells (Box), written from string templates (docs/cases.md).

    box = Box((0, 0, 0), (Lx, Ly, Lz), delta, faces=("cyclic", ((0, 0, 0), (U, 0, 0)), "cyclic"))
    write_fluid_case("run/fluid", box, nu=1.0, tol_lambda=1e-4)
"""
from __future__ import annotations

import math
import os

import numpy as np

HEADER = """FoamFile
{{
    version     2.0;
    format      ascii;
    class       {cls};
    object      {obj};
}}
"""


def foam_file(path, cls, body):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(HEADER.format(cls=cls, obj=os.path.basename(path)))
        f.write(body)


def foam_vector(v):
    return "(%.17g %.17g %.17g)" % tuple(v)


class Box:
    """A box meshed with cubic cells of side delta. faces[axis] is 'cyclic' or a wall velocity pair
    ((ux, uy, uz) at the low face, (ux, uy, uz) at the high face); 'slip' for slip walls."""

    def __init__(self, lo, hi, delta, faces=("cyclic", "cyclic", "cyclic")):
        self.lo, self.hi, self.delta, self.faces = tuple(lo), tuple(hi), float(delta), faces
        self.n = []
        for d in range(3):
            n = (self.hi[d] - self.lo[d]) / self.delta
            if abs(n - round(n)) > 1e-9 * n:
                raise ValueError("box extent %g in %s is not a whole number of cells of %g"
                                 % (self.hi[d] - self.lo[d], "xyz"[d], self.delta))
            self.n.append(int(round(n)))

    @property
    def volume(self):
        return (self.hi[0] - self.lo[0]) * (self.hi[1] - self.lo[1]) * (self.hi[2] - self.lo[2])

    def periodic(self):
        return [f == "cyclic" for f in self.faces]


def whole_cell_box(L: float, a_over_delta: float, depth: float = 1.0) -> float:
    """The smallest box size >= L (in the mesh's unit, a1) whose extents L and depth L are whole, even numbers of
    cells of a1/a_over_delta (cubic cells; at a1/Delta 5.6 the 8 a1 box would be 44.8 cells: 8.2143 a1, 46 cells).
    Even, because the calibration scenes put the gap's centre at L/2 plus its offset in the cell: the box
    correction compares the same position in the mesh in both boxes only if L/2 falls on a cell face in both
    (an odd box puts it on a cell centre; the pair tangential at a1/Delta 5.6 in boxes of 45 and 68 cells had
    the two boxes 4-9 % apart in sliding, where at a1/Delta 5, 40 and 60 cells, they agree within 0.5 %)."""
    first = math.ceil(L * a_over_delta - 1e-9)
    for cells in range(first, first + 400):
        if cells % 2 == 0 and abs(depth * cells - round(depth * cells)) < 1e-9:
            return cells / a_over_delta
    raise ValueError("no box of about %g a1 at a1/Delta %g has whole numbers of cells along L and %g L"
                     % (L, a_over_delta, depth))


# The fvSolution lines of each linear-solver choice, (p, U). FFTBox solves the box meshes every case
# writes directly (fluid/boxSolvers) and hands any other mesh to its fallback. "FFTBox" (the default)
# solves p so and leaves U's loose momentum predictor (relTol 0.3 in the suspension scenes) to a sweep or
# two of symGaussSeidel, which cost less than an exact solve and take no more inner iterations (Table 8
# scene phi 0.37: 94 against 98, 52 against about 140 ms of momentum solve per inner iteration;
# docs/benchmarks.md, "Direct solver for box meshes"); "FFTBox-all" solves U with FFTBox too.
_FFTBOX = """        solver          FFTBox;
        fallback        { solver GAMG; smoother GaussSeidel; }"""
_FFTBOX_U = """        solver          FFTBox;
        fallback        { solver smoothSolver; smoother symGaussSeidel; }"""
_GAMG = """        solver          GAMG;
        smoother        GaussSeidel;"""
_SYMMETRIC_GAUSS_SEIDEL = """        solver          smoothSolver;
        smoother        symGaussSeidel;"""
LINEAR_SOLVERS = {
    "FFTBox": (_FFTBOX, _SYMMETRIC_GAUSS_SEIDEL),
    "FFTBox-all": (_FFTBOX, _FFTBOX_U),
    "GAMG": (_GAMG, _SYMMETRIC_GAUSS_SEIDEL),
}
# FDM_LINEAR_SOLVER=GAMG in the environment writes every case with the iterative solvers instead (for a
# side-by-side comparison; docs/fluid.md, "Direct solver for box meshes")
DEFAULT_LINEAR_SOLVER = os.environ.get("FDM_LINEAR_SOLVER", "FFTBox")
if DEFAULT_LINEAR_SOLVER not in LINEAR_SOLVERS:
    raise ValueError("FDM_LINEAR_SOLVER=%s in the environment is not one of %s"
                     % (DEFAULT_LINEAR_SOLVER, ", ".join(LINEAR_SOLVERS)))
# PISO's momentum predictor with each choice. Without it an inner iteration costs three solves less and a
# suspension's step takes as many inner iterations (Table 8 scenes phi 0.37 and 0.47: 95 and 94 against 98
# and 98), but a step stopped at the same tolLambda is further from the answer: the mirror images of
# cases/pairPoiseuille then differ by more than their 2e-4 U_c (docs/benchmarks.md, "Direct solver for
# box meshes"). momentum_predictor=False in write_fluid_case turns it off.
MOMENTUM_PREDICTOR = {"FFTBox": True, "FFTBox-all": True, "GAMG": True}


def write_control_dict(case_dir, application="fdmFoam", write_interval=100000, end_time=None, delta_t=None):
    """system/controlDict. For fdmFoam (the default) time is driven by fdmDEM: the run starts from
    the latest time and endTime and deltaT are placeholders. For another solver (e.g. icoFoam in a
    benchmark) give end_time and delta_t: it starts from time 0."""
    driven = application == "fdmFoam"
    if not driven and (end_time is None or delta_t is None):
        raise ValueError("write_control_dict: %s needs end_time and delta_t" % application)
    foam_file(os.path.join(case_dir, "system/controlDict"), "dictionary", """
application     %(app)s;
startFrom       %(start)s;
startTime       0;
stopAt          endTime;
endTime         %(end)s
deltaT          %(dt)s
writeControl    timeStep;
writeInterval   %(interval)d;
purgeWrite      0;
writeFormat     binary;
writePrecision  12;
writeCompression off;
timeFormat      general;
timePrecision   8;
runTimeModifiable false;
""" % dict(app=application, start="latestTime" if driven else "startTime", interval=write_interval,
           end="1e30;       // time is driven by fdmDEM" if driven else "%.17g;" % end_time,
           dt="1;          // overridden by fdmDEM's time step" if driven else "%.17g;" % delta_t))


def write_fluid_case(case_dir, box, nu=1.0, rho=1.0, grad_p0=(0, 0, 0), indicator=(5.0, 0.3),
                     tol_lambda=1e-4, n_max=500, n_min=1, first_step=None, tol_u=1e-6, tol_p=5e-6,
                     pseudo_time_factor=1.0, pseudo_time_factor_outside=None, n_particles=-1, write_interval=100000,
                     n_correctors=2, extra_fdm="", acceleration="anderson", tol_velocity=0.0,
                     mean_flow_correction=True, mean_flow_damping=None, u_rel_tol=0.0, p_rel_tol=0.01,
                     p_final_rel_tol=0.0, linear_solver=None, momentum_predictor=None, u_sweeps=None):
    """OpenFOAM case for fdmFoam in case_dir (system/, constant/, 0/). u_rel_tol, p_rel_tol,
    p_final_rel_tol: the relTol of the momentum predictor, of the first pressure corrector and of
    the last (pFinal) in every inner iteration (0: solved to tol_u, tol_p each time; the suspension
    scenes use 0.3, 0.05, 0.05: docs/benchmarks.md "Linear solves inside the inner iteration").
    acceleration: the inner
    iteration's, "anderson" (default) or "none" (the plain iteration of paper 4.3); tol_velocity: the
    innerIterations tolVelocity (0 = not checked, the first step included); mean_flow_correction: the
    exact plane-averaged profile of a channel at every inner iteration (a no-op in other boxes);
    mean_flow_damping: its meanFlowDamping (None: fdmFoam's default, 10), docs/fluid.md.
    linear_solver: the solver of p and U, "FFTBox" (the direct solver for box meshes, GAMG and
    symGaussSeidel as its fallbacks) or "GAMG" (GAMG for p, symGaussSeidel for U); None:
    DEFAULT_LINEAR_SOLVER (docs/fluid.md, "Direct solver for box meshes"). momentum_predictor: PISO's
    momentumPredictor (None: MOMENTUM_PREDICTOR of the linear solver). u_sweeps: the momentum predictor as
    that many symGaussSeidel sweeps per solve with no residual computed (OpenFOAM's smoothSolver with
    nSweeps -u_sweeps; tol_u and u_rel_tol then unused); None: solved to u_rel_tol, tol_u. Not with
    "FFTBox-all", whose U solve is exact."""
    linear_solver = DEFAULT_LINEAR_SOLVER if linear_solver is None else linear_solver
    if linear_solver not in LINEAR_SOLVERS:
        raise ValueError("write_fluid_case: linear_solver %r is not one of %s" % (linear_solver, ", ".join(LINEAR_SOLVERS)))
    u_solver = LINEAR_SOLVERS[linear_solver][1]
    if u_sweeps is not None:
        if u_solver != _SYMMETRIC_GAUSS_SEIDEL or int(u_sweeps) != u_sweeps or u_sweeps < 1:
            raise ValueError("write_fluid_case: u_sweeps %r needs a whole number >= 1 and U solved by symGaussSeidel "
                             "(linear_solver %r solves it otherwise)" % (u_sweeps, linear_solver))
        # the residuals a smoothSolver computes before and after its sweeps cost as much as one sweep
        # (docs/benchmarks.md, "The momentum predictor as one sweep": the momentum solve halved)
        u_solver += ("\n        nSweeps         %d;         // fixed sweeps, no residual: tolerance and relTol unused"
                     % -int(u_sweeps))
    x0, y0, z0 = box.lo
    x1, y1, z1 = box.hi
    names = ("x", "y", "z")
    # block faces by axis: (low face, high face) as vertex quadruples of the hex 0..7
    quads = {0: ("(0 4 7 3)", "(1 2 6 5)"), 1: ("(0 1 5 4)", "(3 7 6 2)"), 2: ("(0 3 2 1)", "(4 5 6 7)")}
    patches = []
    u_bc, p_bc = [], []
    for d in range(3):
        lo_q, hi_q = quads[d]
        face = box.faces[d]
        if face == "cyclic":
            patches.append("    %sLow { type cyclic; neighbourPatch %sHigh; faces (%s); }" % (names[d], names[d], lo_q))
            patches.append("    %sHigh { type cyclic; neighbourPatch %sLow; faces (%s); }" % (names[d], names[d], hi_q))
            for side in ("Low", "High"):
                u_bc.append("    %s%s { type cyclic; }" % (names[d], side))
                p_bc.append("    %s%s { type cyclic; }" % (names[d], side))
        else:
            for side, q, i in (("Low", lo_q, 0), ("High", hi_q, 1)):
                patches.append("    %s%s { type wall; faces (%s); }" % (names[d], side, q))
                if face == "slip":
                    u_bc.append("    %s%s { type slip; }" % (names[d], side))
                else:
                    u_bc.append("    %s%s { type fixedValue; value uniform %s; }"
                                % (names[d], side, foam_vector(face[i])))
                p_bc.append("    %s%s { type fixedFluxPressure; value uniform 0; }" % (names[d], side))

    foam_file(os.path.join(case_dir, "system/blockMeshDict"), "dictionary", """
convertToMeters 1;
vertices
(
    (%(x0).17g %(y0).17g %(z0).17g) (%(x1).17g %(y0).17g %(z0).17g)
    (%(x1).17g %(y1).17g %(z0).17g) (%(x0).17g %(y1).17g %(z0).17g)
    (%(x0).17g %(y0).17g %(z1).17g) (%(x1).17g %(y0).17g %(z1).17g)
    (%(x1).17g %(y1).17g %(z1).17g) (%(x0).17g %(y1).17g %(z1).17g)
);
blocks ( hex (0 1 2 3 4 5 6 7) (%(nx)d %(ny)d %(nz)d) simpleGrading (1 1 1) );
boundary
(
%(patches)s
);
""" % dict(x0=x0, y0=y0, z0=z0, x1=x1, y1=y1, z1=z1, nx=box.n[0], ny=box.n[1], nz=box.n[2],
           patches="\n".join(patches)))

    write_control_dict(case_dir, write_interval=write_interval)
    # an empty <case>.foam: what ParaView opens to read an OpenFOAM case (its built-in reader)
    open(os.path.join(case_dir, os.path.basename(os.path.normpath(case_dir)) + ".foam"), "w").close()

    foam_file(os.path.join(case_dir, "system/fvSchemes"), "dictionary", """
ddtSchemes { default none; }
gradSchemes { default Gauss linear; }
divSchemes { default none; }
laplacianSchemes { default Gauss linear orthogonal; }
interpolationSchemes { default linear; }
snGradSchemes { default orthogonal; }
""")

    foam_file(os.path.join(case_dir, "system/fvSolution"), "dictionary", """
solvers
{
    p
    {
%(p_solver)s
        tolerance       %(tol_p)g;     // tol_p of the paper (4.4.5)
        relTol          %(p_rel_tol)g;
    }
    pFinal
    {
        $p;
        relTol          %(p_final_rel_tol)g;
    }
    U
    {
%(u_solver)s
        tolerance       %(tol_u)g;     // tol_u of the paper (4.4.5)
        relTol          %(u_rel_tol)g;
    }
}
PISO
{
    momentumPredictor %(predictor)s;
    nCorrectors     %(ncorr)d;
    nNonOrthogonalCorrectors 0;
    pRefCell        0;
    pRefValue       0;
}
""" % dict(tol_p=tol_p, tol_u=tol_u, u_rel_tol=u_rel_tol, p_rel_tol=p_rel_tol, p_final_rel_tol=p_final_rel_tol,
           ncorr=n_correctors, p_solver=LINEAR_SOLVERS[linear_solver][0], u_solver=u_solver,
           predictor="yes" if (MOMENTUM_PREDICTOR[linear_solver] if momentum_predictor is None else momentum_predictor)
           else "no"))

    # no system/decomposeParDict: fdmRun -f N writes the split for N ranks (fdmsubgrid.decomposition)

    foam_file(os.path.join(case_dir, "constant/transportProperties"), "dictionary", """
nu              %.17g;   // kinematic viscosity eta/rho_f [m2/s]
rho             %.17g;   // fluid density rho_f [kg/m3]
""" % (nu, rho))

    first = ""
    if first_step:
        first = "\n    firstStep { tolLambda %g; nMax %d; }" % (first_step[0], first_step[1])
    foam_file(os.path.join(case_dir, "constant/fdmProperties"), "dictionary", """
indicator { b %(b).17g; c %(c).17g; }     // Eqs. (34)-(37)
gradP0          %(grad)s;   // imposed mean pressure gradient [Pa/m] (Eq. 42)
pseudoTimeFactor %(ptf).17g;          // pseudo-time step / alpha_lambda inside the particles
pseudoTimeFactorOutside %(ptfo).17g;   // ... outside them (0 = steady Stokes)
nParticles      %(np)d;
innerIterations
{
    tolLambda   %(tol).17g;
    tolVelocity %(tolv).17g;
    nMin        %(nmin)d;
    nMax        %(nmax)d;%(first)s
    acceleration %(accel)s;
    meanFlowCorrection %(meanflow)s;%(damping)s
}
coupling
{
    transport   socket;
    host        "127.0.0.1";
    port        0;
    portFile    "coupling.port";
    connectTimeout 60;
    receiveTimeout 600;
}
%(extra)s
""" % dict(b=indicator[0], c=indicator[1], grad=foam_vector(grad_p0), ptf=pseudo_time_factor,
           ptfo=pseudo_time_factor if pseudo_time_factor_outside is None else pseudo_time_factor_outside,
           np=n_particles, tol=tol_lambda, nmin=n_min, nmax=n_max, first=first, extra=extra_fdm,
           accel=acceleration, tolv=tol_velocity,
           meanflow="yes" if mean_flow_correction else "no",
           damping="" if mean_flow_damping is None else "\n    meanFlowDamping %.17g;" % mean_flow_damping))

    foam_file(os.path.join(case_dir, "0/U"), "volVectorField", """
dimensions      [0 1 -1 0 0 0 0];
internalField   uniform (0 0 0);
boundaryField
{
%s
}
""" % "\n".join(u_bc))
    foam_file(os.path.join(case_dir, "0/p"), "volScalarField", """
dimensions      [0 2 -2 0 0 0 0];
internalField   uniform 0;
boundaryField
{
%s
}
""" % "\n".join(p_bc))


def write_initial_velocity(case_dir, box, velocity):
    """0/U of the fluid case in case_dir with a nonuniform internal field: velocity(centres) -> (n, 3)
    at the (n, 3) cell centres, in blockMesh's cell order (x fastest, then y, then z); the boundary
    conditions write_fluid_case wrote are kept."""
    nx, ny, nz = box.n
    d = box.delta
    i, j, k = np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij")
    order = (i + nx * (j + ny * k)).reshape(-1)
    centres = np.empty((nx * ny * nz, 3))
    centres[order] = np.column_stack([box.lo[0] + (i.reshape(-1) + 0.5) * d, box.lo[1] + (j.reshape(-1) + 0.5) * d,
                                      box.lo[2] + (k.reshape(-1) + 0.5) * d])
    u = np.asarray(velocity(centres), dtype=float)
    if u.shape != centres.shape or not np.all(np.isfinite(u)):
        raise ValueError("write_initial_velocity: velocity() must give finite (%d, 3) values" % len(centres))
    path = os.path.join(case_dir, "0", "U")
    with open(path) as f:
        text = f.read()
    field = "internalField   nonuniform List<vector>\n%d\n(\n%s\n);" % (
        len(u), "\n".join("(%.17g %.17g %.17g)" % tuple(v) for v in u))
    if "internalField   uniform (0 0 0);" not in text:
        raise ValueError("write_initial_velocity: %s is not the 0/U of write_fluid_case" % path)
    with open(path, "w") as f:
        f.write(text.replace("internalField   uniform (0 0 0);", field))
