"""Writing and running coupled cases (OpenFOAM fluid/ + LIGGGHTS dem/), see docs/cases.md."""
import os
import shutil
import subprocess
import time
from typing import Iterable

import numpy as np

from .environment import program, run_environment

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


# The fvSolution lines of each linear-solver choice, (p, U): FFTBox solves the box meshes every case
# writes directly (fluid/boxSolvers) and hands any other mesh to its fallback
LINEAR_SOLVERS = {
    "FFTBox": ("""        solver          FFTBox;
        fallback        { solver GAMG; smoother GaussSeidel; }""",
               """        solver          FFTBox;
        fallback        { solver smoothSolver; smoother symGaussSeidel; }"""),
    "GAMG": ("""        solver          GAMG;
        smoother        GaussSeidel;""",
             """        solver          smoothSolver;
        smoother        symGaussSeidel;"""),
}
DEFAULT_LINEAR_SOLVER = "GAMG"


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
                     p_final_rel_tol=0.0, linear_solver=None):
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
    DEFAULT_LINEAR_SOLVER (docs/fluid.md, "Direct solver for box meshes")."""
    linear_solver = DEFAULT_LINEAR_SOLVER if linear_solver is None else linear_solver
    if linear_solver not in LINEAR_SOLVERS:
        raise ValueError("write_fluid_case: linear_solver %r is not one of %s" % (linear_solver, ", ".join(LINEAR_SOLVERS)))
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
    momentumPredictor yes;
    nCorrectors     %(ncorr)d;
    nNonOrthogonalCorrectors 0;
    pRefCell        0;
    pRefValue       0;
}
""" % dict(tol_p=tol_p, tol_u=tol_u, u_rel_tol=u_rel_tol, p_rel_tol=p_rel_tol, p_final_rel_tol=p_final_rel_tol,
           ncorr=n_correctors, p_solver=LINEAR_SOLVERS[linear_solver][0], u_solver=LINEAR_SOLVERS[linear_solver][1]))

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


def run(case_dir, np_fluid=1, np_dem=1, quiet=True, extra=()):
    """Run fdmRun on case_dir; returns the wall time in seconds. Raises RuntimeError with the
    end of fdmRun's report if the run fails."""
    cmd = [program("fdmRun"), "-f", str(np_fluid), "-d", str(np_dem)]
    if quiet:
        cmd.append("--quiet")
    cmd += list(extra) + [case_dir]
    t0 = time.time()
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="replace",
                          env=run_environment())
    wall = time.time() - t0
    if proc.returncode != 0:
        raise RuntimeError("fdmRun %s failed (exit %d):\n%s" % (case_dir, proc.returncode, proc.stdout[-4000:]))
    return wall


def subgrid_pair_style(walls=(), subgrid=True, model=None, cutoff=None, wall_cutoff=None) -> str:
    """The pair_style line of fdm/subgrid (docs/dem.md): the sub-grid model, its cut-offs in mesh cells
    (pairs, walls; None: the pair style's defaults), `lubrication no` without the correction, and the
    walls as (face, (ux, uy, uz)) pairs, e.g. (("ylo", (0, 0, 0)), ("yhi", (U, 0, 0)))."""
    words = ["fdm/subgrid"]
    if model is not None:
        words.append("model %s" % model)
    if cutoff is not None:
        words.append("cutoff %g" % cutoff)
    if wall_cutoff is not None:
        words.append("wall_cutoff %g" % wall_cutoff)
    if not subgrid:
        words.append("lubrication no")
    for face, velocity in walls:
        words.append("wall %s %s" % (face, " ".join("%r" % float(v) for v in velocity)))
    return " ".join(words)


def held_step_runs(configurations) -> list:
    """The LIGGGHTS lines that hold the particles at each configuration in turn for one coupled step
    (`fix fdm/couple ... move no`): configurations[k] lists each particle's centre (x, y, z) in tag
    order; the first is the data file's, so only the later ones are set. One `run 1` per configuration,
    each warm-started by the solver from the previous one."""
    runs = []
    for k, centres in enumerate(configurations):
        if k > 0:
            runs += ["set             atom %d x %r y %r z %r" % (i + 1, *map(float, c)) for i, c in enumerate(centres)]
        runs.append("run             1")
    return runs


def records_line(every: int) -> str:
    """The LIGGGHTS line that records every particle every `every` steps in particles.records (fix
    fdm/output, docs/dem.md)."""
    return "fix             output all fdm/output records %d particles.records" % every


# every step: the file read_held_steps and the one-step validation cases read
RECORD_EVERY_STEP = records_line(1)


def read_held_steps(run_dir: str, n: int, who: str):
    """The particle records (dem/particles.records, RECORD_EVERY_STEP) and fdmFoam's step records of
    a run of n held configurations (held_step_runs), checked to hold at least n steps; the last n blocks are
    the n steps (a block at step 0, if written, holds no solution). Returns (records, steps); a run that
    recorded fewer is a RuntimeError naming `who` and the folder."""
    from . import output
    records = output.read_particle_records(os.path.join(run_dir, "dem", "particles.records"), mmap=False)
    steps = output.steps(os.path.join(run_dir, "fluid"))
    if len(records) < n or len(steps["step"]) < n:
        raise RuntimeError("%s: %s recorded %d particle blocks and %d fluid steps for %d configurations"
                           % (who, run_dir, len(records), len(steps["step"]), n))
    return records, steps


def halton_points(n: int, dims: int) -> np.ndarray:
    """The first n points of the Halton sequence in [0, 1)^dims (bases 2, 3, 5, ...; unscrambled, the
    origin left out): positions spread evenly over a mesh cell for any count, the cases' --positions."""
    from scipy.stats import qmc
    return qmc.Halton(d=dims, scramble=False).random(n + 1)[1:]


def boxes_and_offsets(parser, args, default_boxes, cell_offsets):
    """The box and cell-offset options two cases share (--size, --boxes [LX LY LZ ...], --offset ...,
    --positions N): returns (boxes, offsets, positions represented); a bad value is a parser error naming it.
    cell_offsets(N) gives a case's own offsets for N positions (ValueError if N is not allowed)."""
    if args.boxes is None:
        boxes = [tuple(args.size)]
    elif not args.boxes:
        boxes = list(default_boxes)
    else:
        if len(args.boxes) % 3 or len(args.boxes) < 6:
            parser.error("--boxes takes LX LY LZ per box, for two boxes or more (got %d numbers)" % len(args.boxes))
        boxes = [tuple(args.boxes[k:k + 3]) for k in range(0, len(args.boxes), 3)]
    if args.offset:
        for offset in args.offset:
            if not all(0.0 <= o < 1.0 for o in offset):
                parser.error("--offset %s: each offset must be in [0, 1) cells" % " ".join("%g" % o for o in offset))
        return boxes, [tuple(o) for o in args.offset], len(args.offset)
    try:
        offsets, represented = cell_offsets(args.positions)
    except ValueError as e:
        parser.error(str(e))
    return boxes, offsets, represented


def uncalibrated(radii: Iterable[float], delta: float, walls: bool = False, model: str = "calibrated",
                 pairs: bool = True) -> list[str]:
    """What the shipped calibration table lacks for a scene of these radii at mesh size delta (with
    walls: also each radius against a wall), in pair_style fdm/subgrid's default model (calibrated):
    empty when the run can start, else one line per missing radius pair or wall, to refuse the scene
    before it is launched (the pair style refuses it anyway at its start; `fdmResistance coverage`
    makes the same test). radii: every particle's (a radius held by one particle has no pair with
    itself, as in the pair style); pairs=False: the spheres are never in one scene together (one per
    run), so only each radius against the walls counts; model cutoff needs nothing."""
    from collections import Counter
    from .theory import resistance
    if model != "calibrated":
        return []
    counts = Counter(float(r) for r in radii)
    sizes = sorted(counts)
    missing = []
    for i, a in enumerate(sizes):
        for b in sizes[i:]:
            r = resistance("coverage", "--a1", a, "--a2", b, "--delta", delta, *(["--wall"] if walls and b == a else []))
            if pairs and not r["pair"] and (b != a or counts[a] > 1):
                missing.append("no calibration for the pair of radii %g and %g at a1/Delta %g (a2/a1 %g)"
                               % (a, b, a / delta, b / a))
            if walls and b == a and not r["wall"]:
                missing.append("no wall calibration for radius %g at a/Delta %g" % (a, a / delta))
    if missing:
        missing.append("the table (%s) has %s; use --model cutoff for this scene" % (r["table"], r["coverage"]))
    return missing


def add_run_options(parser, case_dir, tol_lambda, cutoff=False, model=False):
    """The options every coupled case's script shares: --tol-lambda, --acceleration, --np-fluid,
    --workdir, --out, --keep; with cutoff, --cutoff and --model (pair_style fdm/subgrid's cut-off and
    sub-grid model; model=True gives --model alone)."""
    if cutoff:
        parser.add_argument("--cutoff", type=float, default=None,
                            help="pair_style fdm/subgrid cutoff (mesh cells; default: the pair style's)")
    if cutoff or model:
        parser.add_argument("--model", choices=("calibrated", "cutoff"), default="calibrated",
                            help="pair_style fdm/subgrid model: the calibration of what the solver resolves "
                                 "(the default; a1/Delta 3-5, a2/a1 1 and 1.4) or the cut-off model (docs/dem.md)")
    parser.add_argument("--tol-lambda", type=float, default=tol_lambda, help="fdmFoam's innerIterations tolLambda")
    parser.add_argument("--acceleration", choices=("anderson", "none"), default="anderson",
                        help="fdmFoam's inner-iteration acceleration (none: the plain iteration of paper 4.3)")
    parser.add_argument("--np-fluid", type=int, default=1, help="MPI ranks of fdmFoam")
    parser.add_argument("--workdir", default=os.path.join(case_dir, "runs"), help="where the runs are written")
    parser.add_argument("--out", default=os.path.join(case_dir, "results.json"))
    parser.add_argument("--keep", action="store_true", help="keep the meshes and the fields of the runs")


def run_and_read(run_dir, np_fluid=1, keep=False):
    """Run the coupled case in run_dir (fluid/ + dem/) and read fdmFoam's records; unless keep,
    then delete the mesh and the time directories (fields for ParaView), which the figures do not
    need and which are the bulk of the disk space. Returns (wall seconds, particles, steps) with
    the arrays of output.particles and output.steps."""
    from . import output
    fluid = os.path.join(run_dir, "fluid")
    wall = run(run_dir, np_fluid=np_fluid)
    particles, steps = output.particles(fluid), output.steps(fluid)
    if not keep:
        delete_fields(run_dir)
    return wall, particles, steps


def delete_fields(run_dir):
    """Delete the mesh and the time directories of run_dir/fluid (the fields for ParaView, the bulk
    of the disk space; the records and the checkpoints stay)."""
    fluid = os.path.join(run_dir, "fluid")
    shutil.rmtree(os.path.join(fluid, "constant", "polyMesh"), ignore_errors=True)
    for d in os.listdir(fluid):
        if d != "0" and d.replace(".", "").replace("e-", "").isdigit():
            shutil.rmtree(os.path.join(fluid, d), ignore_errors=True)


def write_dem_input(dem_dir, box, spheres, dt=1.0, density=1000.0, fix_options="move no",
                    before_run="", runs=("run 1",), name="in.dem", data_file="spheres.data", pair_style="none"):
    """LIGGGHTS input for fdmDEM: spheres [(x, y, z, radius), ...] or [(x, y, z, radius, type), ...]
    (type: the LIGGGHTS atom type, 1 if not given; e.g. 1 for a1 and 2 for a2 in a bidisperse
    suspension) from a data file, fix fdm/couple connected to ../fluid; pair_style e.g.
    "fdm/subgrid contact ..." (docs/dem.md), default none. Returns the input path."""
    os.makedirs(dem_dir, exist_ok=True)
    types = [int(s[4]) if len(s) > 4 else 1 for s in spheres]
    if any(t < 1 for t in types):
        raise ValueError("write_dem_input: atom types must be 1 or more, got %s" % sorted(set(types)))
    with open(os.path.join(dem_dir, data_file), "w") as f:
        f.write("spheres for fdmDEM\n\n%d atoms\n%d atom types\n\n" % (len(spheres), max(types, default=1)))
        for d, axis in enumerate("xyz"):
            f.write("%.17g %.17g %slo %shi\n" % (box.lo[d], box.hi[d], axis, axis))
        f.write("\nAtoms\n\n")
        for i, (sphere, kind) in enumerate(zip(spheres, types)):
            x, y, z, a = sphere[:4]
            # atom_style sphere: id type diameter density x y z
            f.write("%d %d %.17g %.17g %.17g %.17g %.17g\n" % (i + 1, kind, 2 * a, density, x, y, z))
    boundary = " ".join("p" if p else "f" for p in box.periodic())
    path = os.path.join(dem_dir, name)
    with open(path, "w") as f:
        f.write("""atom_style      sphere
atom_modify     map array sort 0 0.0
boundary        %(boundary)s
newton          off
communicate     single vel yes
units           si
read_data       %(data)s
pair_style      %(pair)s
%(coeff)sneighbor        %(skin).17g bin
neigh_modify    delay 0 every 1 check yes
timestep        %(dt).17g
%(before)s
fix             couple all fdm/couple portfile ../fluid/coupling.port %(fix)s
%(runs)s
""" % dict(boundary=boundary, data=data_file, pair=pair_style,
           coeff="" if pair_style == "none" else "pair_coeff      * *\n", skin=0.1 * min(s[3] for s in spheres) if spheres else 0.1,
           dt=dt, before=before_run, fix=fix_options, runs="\n".join(runs)))
    return path
