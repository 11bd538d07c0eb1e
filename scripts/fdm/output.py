"""Reading fdmFoam's per-step and per-particle records (postProcessing/fdm/*.dat)."""
import io
import os
import warnings

import numpy as np

STEP_COLUMNS = ("step time innerIterations residualLambda converged meanUx meanUy meanUz "
                "lambdaForceX lambdaForceY lambdaForceZ fluidSeconds particleSeconds exchangeSeconds maxCoreSlip "
                "velocityError").split()
PARTICLE_COLUMNS = "step tag x y z radius Ux Uy Uz Wx Wy Wz Fx Fy Fz Tx Ty Tz Vu".split()


def _read(path, columns):
    if not os.path.isfile(path):
        raise FileNotFoundError("%s not found: did fdmFoam run?" % path)
    with open(path) as f:
        text = f.read()
    if text and not text.endswith("\n"):
        # a record cut by a full disk or a killed run: fdmFoam ends every step's records with a
        # new line, so only the last, unfinished line is dropped
        warnings.warn("%s: the last line is incomplete (the run stopped while writing it): ignored" % path)
        text = text[:text.rfind("\n") + 1]
    data = np.loadtxt(io.StringIO(text), comments="#", ndmin=2)
    if data.size == 0:
        raise ValueError("%s has no records" % path)
    if columns is STEP_COLUMNS and data.shape[1] == len(columns) - 1:
        # records of fdmFoam before the velocity error was written
        data = np.hstack([data, np.full((data.shape[0], 1), np.nan)])
    if data.shape[1] != len(columns):
        raise ValueError("%s has %d columns, expected %d (%s)" % (path, data.shape[1], len(columns),
                                                                  " ".join(columns)))
    return {name: data[:, i] for i, name in enumerate(columns)}


def steps(fluid_case):
    return _read(os.path.join(fluid_case, "postProcessing", "fdm", "steps.dat"), STEP_COLUMNS)


def particles(fluid_case):
    return _read(os.path.join(fluid_case, "postProcessing", "fdm", "particles.dat"), PARTICLE_COLUMNS)


# ------------------------------------------------------------------------------------------------
# LIGGGHTS per-particle dumps (dump custom) of fix fdm/couple runs
# ------------------------------------------------------------------------------------------------

COUPLE_COLUMNS = 25
"""Width of fix fdm/couple's per-atom array with stresslets yes (docs/dem.md, Outputs)."""

SUSPENSION_DUMP_COLUMNS = ("id type radius x y z vx vy vz omegax omegay omegaz".split()
                           + ["f_couple[%d]" % k for k in range(1, COUPLE_COLUMNS + 1)])
"""The columns of the suspension cases' `dump custom` (cases/couette), in this order."""

# the columns of fix fdm/couple's per-atom array (1-based in LIGGGHTS, 0-based here)
_F_FDM, _T_FDM, _F_SG, _T_SG = slice(0, 3), slice(3, 6), slice(6, 9), slice(9, 12)
_S_H_TRACELESS, _S_H_TRACE, _S_C = slice(12, 18), 18, slice(19, 25)
_DIAGONAL = (0, 3, 5)  # xx, yy, zz in the order xx xy xz yy yz zz (fdm.profiles.COMPONENTS)


def dump_custom_command(dump_id, every, path, group="all", fix_id="couple"):
    """The LIGGGHTS commands that write SUSPENSION_DUMP_COLUMNS every `every` steps, sorted by id
    (after `fix <fix_id> all fdm/couple ... stresslets yes`)."""
    columns = " ".join(c.replace("couple", fix_id) for c in SUSPENSION_DUMP_COLUMNS)
    # full double precision: LIGGGHTS's default %g keeps 6 digits (1e-4 a1 on a position of 10 a1,
    # 2 % of h_r)
    digits = '"%d %d' + " %.17g" * (len(SUSPENSION_DUMP_COLUMNS) - 2) + '"'
    return ["dump            %s %s custom %d %s %s" % (dump_id, group, every, path, columns),
            "dump_modify     %s sort id format %s" % (dump_id, digits)]


def read_dump(path):
    """Every complete frame of a LIGGGHTS text `dump custom` file: a list of (step, columns) with
    columns a dict name -> (N,) array, in file order. A frame cut short (a killed run) is dropped;
    a file that does not start with a frame raises ValueError."""
    if not os.path.isfile(path):
        raise FileNotFoundError("%s not found: did fdmDEM run?" % path)
    with open(path) as f:
        lines = f.read().splitlines()
    frames, k = [], 0
    while k < len(lines):
        if lines[k].strip() != "ITEM: TIMESTEP":
            raise ValueError("%s: line %d is %r where a frame should start (ITEM: TIMESTEP)" % (path, k + 1, lines[k]))
        try:
            step = int(lines[k + 1])
            n = int(lines[k + 3])
            header = lines[k + 8].split()
        except (IndexError, ValueError):
            break  # a frame cut short
        if header[:2] != ["ITEM:", "ATOMS"]:
            raise ValueError("%s: no 'ITEM: ATOMS' line in the frame of step %d" % (path, step))
        names = header[2:]
        rows = lines[k + 9:k + 9 + n]
        if len(rows) < n:
            break
        words = [r.split() for r in rows]
        if any(len(w) != len(names) for w in words):
            if k + 9 + n >= len(lines):
                break  # the last frame, cut short in a row
            raise ValueError("%s: a row of the frame of step %d does not have the %d columns %s"
                             % (path, step, len(names), " ".join(names)))
        data = np.array(words, dtype=float)
        frames.append((step, {name: data[:, i] for i, name in enumerate(names)}))
        k += 9 + n
    return frames


def suspension_snapshots(path, dt, strain_rate=1.0, skip_first=True):
    """The frames of a suspension dump (dump_custom_command) as fdm.profiles.Snapshot objects,
    time = strain = step dt strain_rate, particles in id order: positions, radii, types, U_p,
    Omega_p, the hydrodynamic stresslet S^H = S^h + s^h delta/3 (Eq. 52; S^h the traceless fluid +
    sub-grid part of columns 13-18, s^h the trace of the force dipole, column 19) and the contact
    stresslet S^c (columns 20-25), both in the order xx xy xz yy yz zz (profiles.COMPONENTS).
    skip_first: drop a frame of step 0 (fix fdm/couple's outputs are zero before the first step).

    Also returns per frame the hydrodynamic forces F^FDM + F^SG (N, 3) in Snapshot-parallel
    arrays: (snapshots, forces)."""
    from .profiles import Snapshot
    frames = read_dump(path)
    snapshots, forces = [], []
    for step, c in frames:
        if skip_first and step == 0:
            continue
        missing = [name for name in SUSPENSION_DUMP_COLUMNS if name not in c]
        if missing:
            raise ValueError("%s: the dump lacks the columns %s (write it with output.dump_custom_command)"
                             % (path, " ".join(missing)))
        order = np.argsort(c["id"], kind="stable")
        c = {name: v[order] for name, v in c.items()}
        couple = np.column_stack([c["f_couple[%d]" % k] for k in range(1, COUPLE_COLUMNS + 1)])
        s_h = couple[:, _S_H_TRACELESS].copy()
        s_h[:, _DIAGONAL] += couple[:, [_S_H_TRACE]] / 3.0
        snapshots.append(Snapshot(
            positions=np.column_stack([c["x"], c["y"], c["z"]]), radii=c["radius"],
            velocities=np.column_stack([c["vx"], c["vy"], c["vz"]]),
            omegas=np.column_stack([c["omegax"], c["omegay"], c["omegaz"]]),
            stresslet_h=s_h, stresslet_c=couple[:, _S_C], types=c["type"].astype(int),
            time=step * dt * strain_rate))
        forces.append(couple[:, _F_FDM] + couple[:, _F_SG])
    return snapshots, forces


# ------------------------------------------------------------------------------------------------
# Time breakdowns at the end of a coupled run's logs (log.fluid, log.dem)
# ------------------------------------------------------------------------------------------------

def fluid_time_breakdown(text):
    """fdmFoam's "time breakdown" at the end of log.fluid as a dict: steps, inner_iterations, wall,
    and the seconds of fluid_solve, particle_forcing, exchange_dem (exchange + DEM: the messages and
    the whole particle side while fdmFoam waits), output. None if absent."""
    import re
    m = re.search(r"fdmFoam time breakdown \((\d+) steps, (\d+) inner iterations, ([0-9.eE+-]+) s wall\):\s*"
                  r"fluid solve\s+([0-9.eE+-]+) s.*?particle forcing\s+([0-9.eE+-]+) s.*?"
                  r"exchange \+ DEM\s+([0-9.eE+-]+) s.*?output\s+([0-9.eE+-]+) s", text, re.S)
    if not m:
        return None
    g = m.groups()
    return dict(steps=int(g[0]), inner_iterations=int(g[1]), wall=float(g[2]), fluid_solve=float(g[3]),
                particle_forcing=float(g[4]), exchange_dem=float(g[5]), output=float(g[6]))


def dem_time_breakdown(text):
    """fdmDEM's side of a coupled run from log.dem: the last "fdm/couple timing of this run" line
    (particle_solve: the Eq. (31) assembly, solves and position update; exchange_fluid: waiting for
    and talking to the fluid; gather_scatter) and LIGGGHTS's loop-time lines (Pair -- contact forces --, Neigh, Comm, Outpt, Other: seconds; the
    sub-grid blocks are collected inside the particle solve).
    None if absent."""
    import re
    m = None
    for m in re.finditer(r"fdm/couple timing of this run \(\d+ runs?, (\d+) steps, ([0-9.eE+-]+) s\): particle "
                         r"solve ([0-9.eE+-]+) s .*?exchange incl\. fluid ([0-9.eE+-]+) s .*?gather/scatter "
                         r"([0-9.eE+-]+) s", text):
        pass
    if not m:
        return None
    g = m.groups()
    out = dict(steps=int(g[0]), wall=float(g[1]), particle_solve=float(g[2]), exchange_fluid=float(g[3]),
               gather_scatter=float(g[4]), sections={})
    # LIGGGHTS 3.8 writes "Pair  time (%) = 0.00028 (0.0002)" (seconds, percent of the loop)
    for name, seconds in re.findall(r"^(Pair|Neigh|Comm|Outpt|Modify|Other)\s+time \(%\) = ([0-9.eE+-]+)", text, re.M):
        out["sections"][name] = float(seconds)
    return out
