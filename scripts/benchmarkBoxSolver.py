#!/usr/bin/env python3
"""Scaling with N of the pressure solve: the direct solver for box meshes (FFTBox, fluid/boxSolvers)
against GAMG, in seconds per solve and per cell at 64^3, 96^3, 128^3 and 160^3 cells (issue 47).

A stock OpenFOAM solver (Debian's icoFoam, loading libfdmBoxSolvers.so) on a uniform n x n x n box
of side 1, two geometries:

  walls      cyclic in x and z, walls across y, the top wall moving at (1, 0, 0): a Couette-like
             start-up (FFTBox's box with one pair of walls);
  periodic   cyclic along all three axes.

Euler, Gauss linear convection and an orthogonal Laplacian, nu 0.01, dt 1e-3 (Courant number 0.16 at
160^3), PISO with two correctors and the pressure reference (pRefCell 0): the p equation is a singular
Laplacian, its rAU set by the momentum matrix (nearly uniform, the convection making it depart a
little from the separable box operator, so FFTBox's conjugate gradients take a few iterations). A
Couette start-up from rest alone is one-dimensional and divergence-free, so its p equation has no
source; both geometries start from the same three-dimensional velocity, not divergence-free, that
vanishes at y = 0 and 1 (with s = sin^2(pi y)):

    u0 = (sin(2 pi z) s, 0.5 sin(2 pi x) sin(2 pi z) s, sin(2 pi x) s)

so that the first p solve projects it and the later ones balance its convection.

Two fvSolution variants that differ only in p and pFinal: GAMG (smoother GaussSeidel) and FFTBox
(fallback GAMG), both tolerance 1e-7 relTol 0 (a solve to a tight absolute tolerance, as the
linear-solve baseline of docs/benchmarks.md); U is smoothSolver symGaussSeidel, tolerance 1e-8
relTol 0.01, in both (it is asymmetric: FFTBox does not apply).

Each case runs --steps time steps (--steps-160 at 160^3) with OpenFOAM's profiler on and a (binary)
write at every step, whose uniform/profiling holds the total time and the number of calls of
fvMatrix::solve.p so far (both correctors; setting up the solve and the lduMatrix solve). Two
figures per run: seconds per solve over every solve of the run, and over the solves of steps 2 on,
without the first step's one-off setup (GAMG's agglomeration; FFTBox's FFTW_MEASURE plans and its
first reading of the matrix), which is what a long run pays per solve. The log gives the
iterations and residuals of each p solve and FFTBox's own lines (a fallback, or no "solved
directly", stops the benchmark with the log named); the run's wall time (writes included) and
peak memory are measured around it. The two solvers' last p fields are compared
(max |p_GAMG - p_FFTBox| against max |p|; and each solver's repeats against each other). The
solvers run alternately (GAMG, FFTBox, GAMG, FFTBox, ... --repeats times, one size after the other)
so that the load of a shared machine hits both alike; the tables give medians over the repeats.

  nice python3 scripts/benchmarkBoxSolver.py [--sizes 64 96 128 160] [--geometries walls periodic]
                                             [--steps 5] [--steps-160 3] [--repeats 2]
                                             [--workdir DIR] [--keep] [--out PREFIX]

Writes docs/data/benchmarks_boxSolver.json and .png (seconds per p solve against cells, log-log, both
solvers, and their ratio) unless --out says otherwise, and prints a Markdown table.
"""
import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from typing import Dict, List, Optional

import numpy as np

from fdmsubgrid.foamcase import Box, foam_file, write_control_dict

HERE = os.path.dirname(os.path.abspath(__file__))
PROJECT = os.path.dirname(HERE)

SOLVERS = ("GAMG", "FFTBox")
GEOMETRIES = ("walls", "periodic")
NU = 0.01
DT = 1e-3
TOL_P = 1e-7
TOL_U = 1e-8
WALL_VELOCITY = (1.0, 0.0, 0.0)

P_SOLVER = {
    "GAMG": """        solver          GAMG;
        smoother        GaussSeidel;""",
    "FFTBox": """        solver          FFTBox;
        fallback        { solver GAMG; smoother GaussSeidel; }""",
}


def box_for(n: int, geometry: str) -> Box:
    """The unit box of n^3 cells: cyclic in x and z, walls across y with the top one moving (walls),
    or cyclic on all three axes (periodic)."""
    walls = ((0.0, 0.0, 0.0), WALL_VELOCITY)
    faces = ("cyclic", walls, "cyclic") if geometry == "walls" else ("cyclic", "cyclic", "cyclic")
    return Box((0, 0, 0), (1, 1, 1), 1.0 / n, faces=faces)


def initial_velocity(centres: np.ndarray) -> np.ndarray:
    """u0 of the docstring at the (m, 3) cell centres."""
    x, y, z = centres.T
    s = np.sin(np.pi * y) ** 2
    return np.column_stack([np.sin(2 * np.pi * z) * s, 0.5 * np.sin(2 * np.pi * x) * np.sin(2 * np.pi * z) * s,
                            np.sin(2 * np.pi * x) * s])


def write_internal_field(path: str, n: int) -> None:
    """The internalField entry of 0/U, u0 at the cell centres in blockMesh's order (x fastest, then
    y, then z), in a file of its own that the 0/U of both geometries and both solvers include."""
    c = (np.arange(n) + 0.5) / n
    z, y, x = np.meshgrid(c, c, c, indexing="ij")     # x fastest
    u = initial_velocity(np.column_stack([x.ravel(), y.ravel(), z.ravel()]))
    with open(path, "w") as f:
        f.write("internalField   nonuniform List<vector>\n%d\n(\n" % len(u))
        np.savetxt(f, u, fmt="(%.9g %.9g %.9g)")
        f.write(");\n")


def write_mesh(mesh_dir: str, box: Box) -> None:
    """blockMesh of the box in mesh_dir (its constant/polyMesh is shared by the solvers' cases)."""
    x1, y1, z1 = box.hi
    quads = {0: ("(0 4 7 3)", "(1 2 6 5)"), 1: ("(0 1 5 4)", "(3 7 6 2)"), 2: ("(0 3 2 1)", "(4 5 6 7)")}
    patches = []
    for d, name in enumerate("xyz"):
        lo, hi = quads[d]
        if box.faces[d] == "cyclic":
            patches.append("    %sLow { type cyclic; neighbourPatch %sHigh; faces (%s); }" % (name, name, lo))
            patches.append("    %sHigh { type cyclic; neighbourPatch %sLow; faces (%s); }" % (name, name, hi))
        else:
            patches.append("    %sLow { type wall; faces (%s); }" % (name, lo))
            patches.append("    %sHigh { type wall; faces (%s); }" % (name, hi))
    write_control_dict(mesh_dir, application="blockMesh", end_time=1, delta_t=1)
    foam_file(os.path.join(mesh_dir, "system/blockMeshDict"), "dictionary", """
convertToMeters 1;
vertices
(
    (0 0 0) (%(x1)g 0 0) (%(x1)g %(y1)g 0) (0 %(y1)g 0)
    (0 0 %(z1)g) (%(x1)g 0 %(z1)g) (%(x1)g %(y1)g %(z1)g) (0 %(y1)g %(z1)g)
);
blocks ( hex (0 1 2 3 4 5 6 7) (%(nx)d %(ny)d %(nz)d) simpleGrading (1 1 1) );
boundary
(
%(patches)s
);
""" % dict(x1=x1, y1=y1, z1=z1, nx=box.n[0], ny=box.n[1], nz=box.n[2], patches="\n".join(patches)))
    with open(os.path.join(mesh_dir, "log.blockMesh"), "w") as log:
        subprocess.run(["blockMesh", "-case", mesh_dir], stdout=log, stderr=subprocess.STDOUT, check=True)


def write_case(case_dir: str, box: Box, solver: str, steps: int, internal_field: str) -> None:
    """icoFoam's case in case_dir: its mesh a link to ../mesh, 0/U including internal_field."""
    # a write (binary) at every step: its uniform/profiling holds the profiler's sums so far
    write_control_dict(case_dir, application="icoFoam", write_interval=1, end_time=steps * DT, delta_t=DT)
    path = os.path.join(case_dir, "system/controlDict")
    text = open(path).read()
    text += """
libs            ("libfdmBoxSolvers.so");
profiling
{
    active      true;
    cpuInfo     false;
    memInfo     false;
    sysInfo     false;
}
"""
    open(path, "w").write(text)
    foam_file(os.path.join(case_dir, "system/fvSchemes"), "dictionary", """
ddtSchemes { default Euler; }
gradSchemes { default Gauss linear; }
divSchemes { default none; div(phi,U) Gauss linear; }
laplacianSchemes { default Gauss linear orthogonal; }
interpolationSchemes { default linear; }
snGradSchemes { default orthogonal; }
""")
    foam_file(os.path.join(case_dir, "system/fvSolution"), "dictionary", """
solvers
{
    p
    {
%(p)s
        tolerance       %(tol_p)g;
        relTol          0;
    }
    pFinal
    {
        $p;
    }
    U
    {
        solver          smoothSolver;
        smoother        symGaussSeidel;
        tolerance       %(tol_u)g;
        relTol          0.01;
    }
}
PISO
{
    nCorrectors     2;
    nNonOrthogonalCorrectors 0;
    pRefCell        0;
    pRefValue       0;
}
""" % dict(p=P_SOLVER[solver], tol_p=TOL_P, tol_u=TOL_U))
    foam_file(os.path.join(case_dir, "constant/transportProperties"), "dictionary",
              "\nnu              [0 2 -1 0 0 0 0] %g;\n" % NU)
    os.symlink(os.path.join("..", "..", "mesh", "constant", "polyMesh"),
               os.path.join(case_dir, "constant", "polyMesh"))
    u_bc, p_bc = [], []
    for d, name in enumerate("xyz"):
        for side, i in (("Low", 0), ("High", 1)):
            if box.faces[d] == "cyclic":
                u_bc.append("    %s%s { type cyclic; }" % (name, side))
                p_bc.append("    %s%s { type cyclic; }" % (name, side))
            else:
                u_bc.append("    %s%s { type fixedValue; value uniform (%g %g %g); }"
                            % ((name, side) + box.faces[d][i]))
                p_bc.append("    %s%s { type zeroGradient; }" % (name, side))
    # #include is relative to the folder of the file that includes
    foam_file(os.path.join(case_dir, "0/U"), "volVectorField", """
dimensions      [0 1 -1 0 0 0 0];
#include "%s"
boundaryField
{
%s
}
""" % (os.path.relpath(internal_field, os.path.join(case_dir, "0")), "\n".join(u_bc)))
    foam_file(os.path.join(case_dir, "0/p"), "volScalarField", """
dimensions      [0 2 -2 0 0 0 0];
internalField   uniform 0;
boundaryField
{
%s
}
""" % "\n".join(p_bc))


# ---- reading a run ------------------------------------------------------------------------------

SOLVE = re.compile(r"^(\w+):\s+Solving for (\w+), Initial residual = (\S+), Final residual = (\S+), "
                   r"No Iterations (\d+)")


def read_log(path: str) -> Dict:
    """Per p solve (both correctors) its solver, iterations, initial and final residuals; the U
    solves' iterations; the ExecutionTime of each step; FFTBox's own lines."""
    p, u, times, fftbox = [], [], [], []
    for line in open(path):
        m = SOLVE.match(line)
        if m:
            if m.group(2) == "p":
                p.append(dict(solver=m.group(1), iterations=int(m.group(5)), initial=float(m.group(3)),
                              final=float(m.group(4))))
            else:
                u.append(int(m.group(5)))
        elif line.startswith("ExecutionTime ="):
            times.append(float(line.split()[2]))
        elif line.startswith("FFTBox:"):
            fftbox.append(line.strip())
    return dict(p=p, u_iterations=u, execution_time=times, fftbox_lines=fftbox)


def read_profiling(path: str) -> Dict[str, Dict]:
    """uniform/profiling as {description: {calls, totalTime, childTime}}."""
    text = open(path).read()
    entries = {}
    for m in re.finditer(r"\{([^{}]*)\}", text):
        body = m.group(1)
        d = re.search(r'description\s+"([^"]*)"\s*;', body)
        if not d:
            continue
        entry = {}
        for key in ("calls", "totalTime", "childTime"):
            k = re.search(r"\b%s\s+([^;\s]+)\s*;" % key, body)
            if k:
                entry[key] = float(k.group(1))
        entries[d.group(1)] = entry
    return entries


def read_scalar_field(path: str) -> np.ndarray:
    """The internalField of a volScalarField written by OpenFOAM, binary (64-bit scalars) or ascii."""
    data = open(path, "rb").read()
    m = re.search(rb"internalField\s+nonuniform\s+List<scalar>\s*(\d+)\s*\(", data)
    if not m:
        raise ValueError("%s: no nonuniform internalField" % path)
    n = int(m.group(1))
    if re.search(rb"format\s+binary\s*;", data[:m.start()]):
        if not re.search(rb"scalar=64", data[:m.start()]):
            raise ValueError("%s: not 64-bit scalars" % path)
        values = np.frombuffer(data, dtype="<f8", count=n, offset=m.end())
        if data[m.end() + 8 * n:m.end() + 8 * n + 1] != b")":
            raise ValueError("%s: %d binary values not closed by ')'" % (path, n))
    else:
        values = np.array(data[m.end():data.index(b")", m.end())].split(), dtype=float)
    if len(values) != n:
        raise ValueError("%s: %d values, %d announced" % (path, len(values), n))
    return values.copy()


def peak_rss_kib_of(pid: int):
    """Wait for pid; its exit status and peak resident memory in KiB (wait4's rusage)."""
    _, status, usage = os.wait4(pid, 0)
    return os.waitstatus_to_exitcode(status), usage.ru_maxrss


def run_case(case_dir: str, steps: int, repeat: int) -> Dict:
    """icoFoam in case_dir (its earlier time folders removed); what the profiler, the log and the
    last p field say."""
    for entry in os.listdir(case_dir):
        if re.fullmatch(r"[0-9.e+-]+", entry) and entry != "0":
            shutil.rmtree(os.path.join(case_dir, entry))
    log_path = os.path.join(case_dir, "log.icoFoam.%d" % repeat)
    t0 = time.time()
    with open(log_path, "w") as log:
        proc = subprocess.Popen(["icoFoam", "-case", case_dir], stdout=log, stderr=subprocess.STDOUT)
        code, rss = peak_rss_kib_of(proc.pid)
        proc.returncode = code
    wall = time.time() - t0
    if code != 0:
        raise RuntimeError("icoFoam failed in %s (exit %d): see %s" % (case_dir, code, log_path))
    times = sorted((e for e in os.listdir(case_dir) if re.fullmatch(r"[0-9.e+-]+", e) and e != "0"), key=float)
    if len(times) != steps:
        raise RuntimeError("%s: %d time folders after %d steps" % (case_dir, len(times), steps))
    # the profiler's sums after each step
    profiles = [read_profiling(os.path.join(case_dir, t, "uniform", "profiling")) for t in times]
    if any("fvMatrix::solve.p" not in prof for prof in profiles):
        raise RuntimeError("%s: no fvMatrix::solve.p in the profiling (%s)" % (case_dir, ", ".join(profiles[-1])))
    p_total = [prof["fvMatrix::solve.p"]["totalTime"] for prof in profiles]
    p_calls = [int(prof["fvMatrix::solve.p"]["calls"]) for prof in profiles]
    u_total = [prof.get("fvMatrix::solve.U", {}).get("totalTime", float("nan")) for prof in profiles]
    log = read_log(log_path)
    p = read_scalar_field(os.path.join(case_dir, times[-1], "p"))
    for t in times[:-1]:
        shutil.rmtree(os.path.join(case_dir, t))
    return dict(repeat=repeat, wall_seconds=wall, peak_rss_MiB=rss / 1024.0, last_time=times[-1], steps=steps,
                p_solve_seconds=p_total[-1], p_solve_calls=p_calls[-1],
                p_solve_seconds_by_step=np.diff([0.0] + p_total).tolist(),
                p_solve_calls_by_step=np.diff([0] + p_calls).tolist(),
                # steps 2.. (the first holds the solver's setup: GAMG's agglomeration, FFTBox's FFTW plans)
                seconds_per_solve_later=(p_total[-1] - p_total[0]) / (p_calls[-1] - p_calls[0]) if steps > 1 else None,
                u_solve_seconds_by_step=np.diff([0.0] + u_total).tolist(),
                main_seconds=profiles[-1].get("application::main", {}).get("totalTime"),
                p_solvers=sorted({s["solver"] for s in log["p"]}),
                p_iterations=[s["iterations"] for s in log["p"]],
                p_initial_residuals=[s["initial"] for s in log["p"]],
                p_final_residuals=[s["final"] for s in log["p"]],
                u_iterations=log["u_iterations"], execution_time=log["execution_time"],
                fftbox_lines=log["fftbox_lines"],
                log=os.path.relpath(log_path, os.path.dirname(os.path.dirname(case_dir))),
                p_field=p)


def load() -> List[float]:
    return [round(x, 2) for x in os.getloadavg()]


def check_fftbox(run: Dict, solver: str) -> Optional[str]:
    """Why the run is not what it claims (a fallback, a solver other than the one asked for)."""
    if solver == "FFTBox":
        bad = [l for l in run["fftbox_lines"] if "fallback" in l]
        if bad or run["p_solvers"] != ["FFTBox"]:
            return "FFTBox did not solve p itself: %s; solvers in the log %s" % (" | ".join(bad), run["p_solvers"])
        if not any("solved directly" in l for l in run["fftbox_lines"]):
            return "no 'FFTBox: p solved directly' line in the log"
    elif run["p_solvers"] != ["GAMG"]:
        return "solvers in the log %s" % run["p_solvers"]
    return None


# ---- the benchmark ------------------------------------------------------------------------------

def run_size(workdir: str, n: int, geometry: str, steps: int, repeats: int, internal_field: str) -> Dict:
    box = box_for(n, geometry)
    root = os.path.join(workdir, "n%d_%s" % (n, geometry))
    shutil.rmtree(root, ignore_errors=True)
    t0 = time.time()
    write_mesh(os.path.join(root, "mesh"), box)
    mesh_seconds = time.time() - t0
    for solver in SOLVERS:
        write_case(os.path.join(root, solver), box, solver, steps, internal_field)
    runs = {s: [] for s in SOLVERS}
    for repeat in range(repeats):
        for solver in SOLVERS:
            r = run_case(os.path.join(root, solver), steps, repeat)
            problem = check_fftbox(r, solver)
            print("  %4d^3 %-8s %-6s repeat %d: p %2d solves %.3f s/solve (steps 2.. %.3f, first step %.2f s), "
                  "iterations %s, final residual max %.1e, wall %.1f s, peak %.0f MiB, load %s" % (
                      n, geometry, solver, repeat, r["p_solve_calls"], r["p_solve_seconds"] / r["p_solve_calls"],
                      r["seconds_per_solve_later"] or float("nan"), r["p_solve_seconds_by_step"][0],
                      " ".join(map(str, r["p_iterations"])), max(r["p_final_residuals"]), r["wall_seconds"],
                      r["peak_rss_MiB"], load()), flush=True)
            for line in r["fftbox_lines"] if repeat == 0 else []:
                print("      " + line, flush=True)
            if problem:
                raise RuntimeError("%d^3 %s %s: %s (log %s)" % (n, geometry, solver, problem, r["log"]))
            runs[solver].append(r)
    # the p fields: GAMG against FFTBox, run against run
    p = {s: [r.pop("p_field") for r in runs[s]] for s in SOLVERS}
    scale = float(np.abs(p["GAMG"][0]).max())
    diff = max(float(np.abs(a - b).max()) for a in p["GAMG"] for b in p["FFTBox"])
    same = {s: max(float(np.abs(a - p[s][0]).max()) for a in p[s]) for s in SOLVERS}
    row = dict(n=n, geometry=geometry, cells=n ** 3, steps=steps, repeats=repeats, blockMesh_seconds=mesh_seconds,
               p_max=scale, p_difference_max=diff, p_difference_relative=diff / scale if scale else None,
               p_repeat_difference_max=same, solvers={})
    for s in SOLVERS:
        per_solve = [r["p_solve_seconds"] / r["p_solve_calls"] for r in runs[s]]
        later = [r["seconds_per_solve_later"] for r in runs[s]]
        row["solvers"][s] = dict(
            # every solve of the run, the first step's setup included
            seconds_per_solve=statistics.median(per_solve), seconds_per_solve_runs=per_solve,
            seconds_per_solve_per_cell=statistics.median(per_solve) / n ** 3,
            # the solves of steps 2.. (what a long run pays per solve)
            seconds_per_solve_later=statistics.median(later) if steps > 1 else None, seconds_per_solve_later_runs=later,
            seconds_per_solve_later_per_cell=statistics.median(later) / n ** 3 if steps > 1 else None,
            first_step_p_seconds=statistics.median(r["p_solve_seconds_by_step"][0] for r in runs[s]),
            solves=runs[s][0]["p_solve_calls"], iterations=runs[s][0]["p_iterations"],
            iterations_mean=float(np.mean(runs[s][0]["p_iterations"])),
            final_residual_max=max(max(r["p_final_residuals"]) for r in runs[s]),
            wall_seconds=statistics.median(r["wall_seconds"] for r in runs[s]),
            peak_rss_MiB=max(r["peak_rss_MiB"] for r in runs[s]),
            u_solve_seconds_per_step=statistics.median(np.median(r["u_solve_seconds_by_step"]) for r in runs[s]),
            fftbox_lines=runs[s][0]["fftbox_lines"], runs=runs[s])
    g, f = row["solvers"]["GAMG"], row["solvers"]["FFTBox"]
    row["ratio_gamg_over_fftbox"] = g["seconds_per_solve"] / f["seconds_per_solve"]
    row["ratio_gamg_over_fftbox_later"] = (g["seconds_per_solve_later"] / f["seconds_per_solve_later"]
                                           if steps > 1 else None)
    print("  %4d^3 %-8s GAMG %.3f s/solve (steps 2.. %.3f), FFTBox %.3f (%.3f): ratio %.1f (%.1f); max |dp| %.2e "
          "(max |p| %.2e)" % (n, geometry, g["seconds_per_solve"], g["seconds_per_solve_later"] or float("nan"),
                              f["seconds_per_solve"], f["seconds_per_solve_later"] or float("nan"),
                              row["ratio_gamg_over_fftbox"], row["ratio_gamg_over_fftbox_later"] or float("nan"),
                              diff, scale), flush=True)
    return row


def plot(rows: List[Dict], png: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker
    fig, (ax, axr) = plt.subplots(2, 1, figsize=(5.5, 6), sharex=True, gridspec_kw=dict(height_ratios=(2, 1)))
    styles = {"walls": "-", "periodic": "--"}
    colours = {"GAMG": "C0", "FFTBox": "C3"}
    for geometry in GEOMETRIES:
        mine = sorted((r for r in rows if r["geometry"] == geometry), key=lambda r: r["cells"])
        if not mine:
            continue
        cells = [r["cells"] for r in mine]
        for s in SOLVERS:
            ax.loglog(cells, [r["solvers"][s]["seconds_per_solve"] for r in mine], styles[geometry], marker="o",
                      color=colours[s], label="%s, %s" % (s, geometry))
            later = [r["solvers"][s]["seconds_per_solve_later"] for r in mine]
            if None not in later:
                ax.loglog(cells, later, styles[geometry], marker="o", mfc="none", color=colours[s], alpha=0.5,
                          label="%s, %s, steps 2.." % (s, geometry))
        axr.semilogx(cells, [r["ratio_gamg_over_fftbox"] for r in mine], styles[geometry], marker="o", color="k",
                     label=geometry)
        later = [r["ratio_gamg_over_fftbox_later"] for r in mine]
        if None not in later:
            axr.semilogx(cells, later, styles[geometry], marker="o", mfc="none", color="grey",
                         label="%s, steps 2.." % geometry)
    c = np.array(sorted({r["cells"] for r in rows}), dtype=float)
    if len(c):
        ref = min(r["solvers"]["FFTBox"]["seconds_per_solve"] for r in rows if r["cells"] == c[0])
        ax.loglog(c, ref * c / c[0], ":", color="grey", label="proportional to cells")
    ax.set_ylabel("seconds per p solve")
    ax.set_title("p solve to 1e-7, icoFoam on an n$^3$ box\n(filled: every solve; open: steps 2 on)", fontsize=9)
    ax.legend(fontsize=6, ncol=2)
    axr.set_ylabel("GAMG / FFTBox")
    axr.set_xlabel("cells (n$^3$)")
    # ticks at the sizes measured
    axr.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    axr.set_xticks(list(c))
    axr.set_xticklabels(["%d$^3$" % round(x ** (1 / 3)) for x in c])
    axr.set_ylim(bottom=0)
    axr.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(png, dpi=120)
    plt.close(fig)


def markdown(rows: List[Dict]) -> str:
    lines = ["| geometry | n | cells | GAMG s/solve | FFTBox s/solve | GAMG / FFTBox "
             "| steps 2..: GAMG, FFTBox s/solve, ratio | GAMG ns/cell | FFTBox ns/cell | iterations GAMG "
             "| iterations FFTBox | max abs dp / max abs p |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        g, f = r["solvers"]["GAMG"], r["solvers"]["FFTBox"]
        later = ("%.3f, %.3f, %.1f" % (g["seconds_per_solve_later"], f["seconds_per_solve_later"],
                                       r["ratio_gamg_over_fftbox_later"]) if r["steps"] > 1 else "")
        lines.append("| %s | %d | %d | %.3f | %.3f | %.1f | %s | %.0f | %.0f | %s | %s | %.1e / %.1e |" % (
            r["geometry"], r["n"], r["cells"], g["seconds_per_solve"], f["seconds_per_solve"],
            r["ratio_gamg_over_fftbox"], later, 1e9 * g["seconds_per_solve_per_cell"],
            1e9 * f["seconds_per_solve_per_cell"],
            " ".join(map(str, g["iterations"])), " ".join(map(str, f["iterations"])), r["p_difference_max"],
            r["p_max"]))
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--sizes", type=int, nargs="+", default=[64, 96, 128, 160])
    p.add_argument("--geometries", nargs="+", choices=GEOMETRIES, default=list(GEOMETRIES))
    p.add_argument("--steps", type=int, default=5, help="time steps per run")
    p.add_argument("--steps-160", type=int, default=3, help="time steps per run at 160^3 and above")
    p.add_argument("--repeats", type=int, default=2, help="runs of each solver, alternating")
    p.add_argument("--workdir", default=None, help="where the cases are run (default: a temporary folder, removed)")
    p.add_argument("--keep", action="store_true", help="keep the cases of the default temporary folder")
    p.add_argument("--out", default=os.path.join(PROJECT, "docs", "data", "benchmarks_boxSolver"),
                   help="PREFIX of PREFIX.json and PREFIX.png")
    args = p.parse_args(argv)
    workdir = args.workdir or tempfile.mkdtemp(prefix="fdmBoxSolver.")
    os.makedirs(workdir, exist_ok=True)
    machine = dict(nproc=os.cpu_count(), load_start=load(), started=time.strftime("%Y-%m-%d %H:%M:%S"))
    print("cases in %s; nproc %d, load %s" % (workdir, machine["nproc"], machine["load_start"]), flush=True)
    rows = []
    t0 = time.time()
    try:
        for n in args.sizes:
            internal_field = os.path.join(workdir, "U0_n%d" % n)
            write_internal_field(internal_field, n)
            for geometry in args.geometries:
                steps = args.steps_160 if n >= 160 else args.steps
                rows.append(run_size(workdir, n, geometry, steps, args.repeats, internal_field))
                machine.update(load_end=load(), seconds=time.time() - t0)
                write(args, rows, machine)
            os.remove(internal_field)
    finally:
        if args.workdir is None and not args.keep:
            shutil.rmtree(workdir, ignore_errors=True)
    print(markdown(rows))
    print("wrote %s.json and %s.png" % (args.out, args.out))
    return 0


def write(args, rows: List[Dict], machine: Dict) -> None:
    """The JSON (and the PNG) so far: written after each size, so that a run stopped at 128^3 keeps
    what it measured."""
    result = dict(
        description="seconds per p solve of icoFoam on an n^3 unit box, GAMG against FFTBox "
                    "(scripts/benchmarkBoxSolver.py, issue 47)",
        command=("python3 scripts/benchmarkBoxSolver.py --sizes %s --geometries %s --steps %d --steps-160 %d "
                 "--repeats %d") % (
            " ".join(map(str, args.sizes)), " ".join(args.geometries), args.steps, args.steps_160, args.repeats),
        setup=dict(nu=NU, dt=DT, p_tolerance=TOL_P, p_relTol=0, U_tolerance=TOL_U, U_relTol=0.01, nCorrectors=2,
                   U_solver="smoothSolver symGaussSeidel", p_solvers=P_SOLVER, wall_velocity=WALL_VELOCITY,
                   geometries=dict(walls="cyclic x and z, walls across y (top moving)", periodic="cyclic x, y, z"),
                   initial_velocity="(sin(2 pi z) s, 0.5 sin(2 pi x) sin(2 pi z) s, sin(2 pi x) s), s = sin^2(pi y)",
                   seconds_per_solve="fvMatrix::solve.p of uniform/profiling: totalTime / calls (p and pFinal), "
                                     "every solve of the run",
                   seconds_per_solve_later="the same over the solves of steps 2.. (the profiling written at every "
                                           "step): without the first step's setup (GAMG's agglomeration, FFTBox's "
                                           "FFTW_MEASURE plans and first reading of the matrix)"),
        machine=dict(machine, uptime_load_average="1, 5, 15 min at start (load_start) and end (load_end)"),
        rows=rows)
    with open(args.out + ".json", "w") as f:
        json.dump(result, f, indent=1)
    plot(rows, args.out + ".png")


if __name__ == "__main__":
    sys.exit(main())
