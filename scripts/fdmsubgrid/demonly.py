"""fdmDEM scenes with pair_style fdm/subgrid, with or without the fluid: writing the LIGGGHTS input,
running fdmDEM, reading the per-step record of the Eq. (31) solve (scripts/benchmarkSubgrid.py,
tests/test_subgrid_stability.py).

    from fdmsubgrid import demonly, packing
    p = packing.random_packing(100, 0.5, walls=(1,))
    scene = demonly.Scene(p, solver="cg", tolerance=1e-10, steps=1000, dt=1e-3,
                          walls={"ylo": (-5, 0, 0), "yhi": (5, 0, 0)})
    r = demonly.run(scene, "runs/shear")          # fix fdm/couple transport none (no fluid)
    r["iterations"], r["solve_seconds"], r["max_speed"], r["timing"]   # per step / run-end line

Every step is recorded (thermo every step, fix fdm/couple's global vector): the linear-solver
iterations of Eq. (31) (f_couple[5]: Eigen's CG count, which is the number of matrix-vector
products less one when it converges; 1 for ldlt), the particle-solve seconds of the step (the
increment of f_couple[3]: the pair style's collectBlocks + gather + assembly of R^SG + the solve),
the sub-grid pair and wall blocks and contacts, the largest speed and spin. Positions go to a
dump every `dump_every` steps (surface gaps, overlaps)."""
from __future__ import annotations

import math
import os
import re
import shutil
import subprocess
import time

import numpy as np

from . import packing as packing_module
from .deminput import records_line
from .environment import program, run_environment

THERMO = ("step iterations solveTotal pairBlocks wallBlocks contacts maxSpeed maxSpin").split()
FACES = ("xlo", "xhi", "ylo", "yhi", "zlo", "zhi")


class Scene:
    """A LIGGGHTS scene for fdmDEM. packing: a fdmsubgrid.packing.Packing (its box and boundary are used);
    walls: {face: (ux, uy, uz)} moving walls declared to the pair style (faces on the packing's
    wall-bounded axes); forces: {group-name: (ids or 'type N', (fx, fy, fz))} applied with fix
    addforce; contact: (kn, kt, mu_s, h_r) or None; fluid: None for transport none (viscosity eta,
    mesh delta), else the fix's socket options (e.g. 'portfile ../fluid/coupling.port'); extra_fix: more
    fix fdm/couple keywords (e.g. 'background_shear 1 stresslets yes'); records_every: fix fdm/output
    records every so many steps into particles.records (0: none)."""

    def __init__(self, packing, solver="cg", tolerance=None, steps=100, dt=1e-3, eta=1.0, delta=0.2,
                 contact=(1e4, 1e4, 0.5, 5e-3), walls=None, forces=None, move=True, skin=None,
                 dump_every=0, fluid=None, extra_pair="", density=1000.0, extra_fix="", records_every=0):
        self.packing = packing
        self.solver, self.tolerance = solver, tolerance
        self.steps, self.dt, self.eta, self.delta = int(steps), float(dt), float(eta), float(delta)
        self.contact, self.walls, self.forces = contact, dict(walls or {}), dict(forces or {})
        self.move, self.dump_every, self.fluid, self.extra_pair = move, int(dump_every), fluid, extra_pair
        self.skin = 0.1 * float(np.min(packing.radii)) if skin is None else skin
        self.density = density
        self.extra_fix, self.records_every = extra_fix, int(records_every)

    def input_text(self, data_file):
        p = self.packing
        pair = "fdm/subgrid"
        if self.contact:
            pair += " contact %r %r %r %r" % tuple(float(c) for c in self.contact)
        for face, u in self.walls.items():
            if face not in FACES:
                raise ValueError("wall face %s is not one of %s" % (face, FACES))
            pair += " wall %s %r %r %r" % ((face,) + tuple(float(c) for c in u))
        if self.extra_pair:
            pair += " " + self.extra_pair
        lines = ["# written by fdmsubgrid.demonly (scripts/fdmsubgrid/demonly.py)",
                 "atom_style      sphere",
                 "atom_modify     map array sort 0 0.0",
                 "boundary        %s" % p.boundary,
                 "newton          off",
                 "communicate     single vel yes",
                 "units           si",
                 "read_data       %s" % data_file,
                 "pair_style      %s" % pair,
                 "pair_coeff      * *",
                 "neighbor        %r bin" % self.skin,
                 "neigh_modify    delay 0 every 1 check yes",
                 "timestep        %r" % self.dt]
        for k, (name, (who, force)) in enumerate(sorted(self.forces.items())):
            if isinstance(who, str):
                lines.append("group           %s %s" % (name, who))
            else:
                lines.append("group           %s id %s" % (name, " ".join(str(int(i)) for i in who)))
            lines.append("fix             push%d %s addforce %r %r %r" % ((k, name) + tuple(float(c) for c in force)))
        fix = "fix             couple all fdm/couple "
        if self.fluid is None:
            fix += "transport none viscosity %r mesh %r" % (self.eta, self.delta)
        else:
            fix += self.fluid
        fix += " solver %s" % self.solver
        if self.tolerance is not None:
            fix += " tolerance %r" % self.tolerance
        if not self.move:
            fix += " move no"
        if self.extra_fix:
            fix += " " + self.extra_fix
        lines.append(fix)
        if self.records_every:
            lines.append(records_line(self.records_every))
        lines += ["compute         spin all property/atom omegax omegay omegaz",
                  "variable        speed atom sqrt(vx*vx+vy*vy+vz*vz)",
                  "variable        spin atom sqrt(c_spin[1]*c_spin[1]+c_spin[2]*c_spin[2]+c_spin[3]*c_spin[3])",
                  "compute         vmax all reduce max v_speed v_spin",
                  "thermo_style    custom step f_couple[5] f_couple[3] f_couple[6] f_couple[7] f_couple[8] "
                  "c_vmax[1] c_vmax[2]",
                  "thermo_modify   format float %.12g",
                  "thermo          1"]
        if self.dump_every:
            lines.append("dump            positions all custom %d positions.dump id type radius x y z vx vy vz"
                         % self.dump_every)
            lines.append('dump_modify     positions sort id format "%d %d' + ' %.17g' * 7 + '"')
        lines.append("run             %d" % self.steps)
        return "\n".join(lines) + "\n"

    def write(self, run_dir, name="in.dem", data_file="packing.data"):
        os.makedirs(run_dir, exist_ok=True)
        packing_module.write_data(os.path.join(run_dir, data_file), self.packing, density=self.density)
        path = os.path.join(run_dir, name)
        with open(path, "w") as f:
            f.write(self.input_text(data_file))
        return path


def environment() -> dict:
    """os.environ plus what fdmDEM needs (environment.run_environment)."""
    return run_environment()


def fdmdem() -> str:
    """The fdmDEM binary (environment.program)."""
    return program("fdmDEM")


TIMING = re.compile(r"fdm/couple timing of this run \((\d+) runs?, (\d+) steps, ([0-9.eE+-]+) s\): particle solve "
                    r"([0-9.eE+-]+) s .*?gather/scatter ([0-9.eE+-]+) s.*?Eq\. 31: (\d+) solves, (\w+) iterations "
                    r"mean ([0-9.eE+-]+|nan) max (\d+)(?:, (\d+) factorisations, (\d+) low-rank downdates)?"
                    r"(?:, (\d+) back-substitutions \(Coulomb rounds, at most (\d+) in a solve\))?; "
                    r"last step (\d+) sub-grid pair blocks, (\d+) wall blocks, "
                    r"(\d+) contacts(?:; (\d+) contacts began to slide within their step)?")


def parse_timing(text):
    """The last 'fdm/couple timing of this run' line as a dict (None if absent)."""
    found = TIMING.findall(text)
    if not found:
        return None
    g = found[-1]

    def optional(v: str) -> int | None:  # a field older binaries did not write
        return int(v) if v else None

    return dict(steps=int(g[1]), wall=float(g[2]), particle_solve=float(g[3]), gather_scatter=float(g[4]),
                solves=int(g[5]), solver=g[6], iterations_mean=float(g[7]), iterations_max=int(g[8]),
                factorisations=optional(g[9]), downdates=optional(g[10]), back_substitutions=optional(g[11]),
                coulomb_rounds_max=optional(g[12]), pair_blocks=int(g[13]), wall_blocks=int(g[14]),
                contacts=int(g[15]), contact_slides=optional(g[16]))


POSITION_UPDATE = re.compile(r"fdm/couple timing of this run \((\d+) runs?, (\d+) steps, .*?position update "
                             r"\w+ with log gaps: .*?(\d+) limited, (\d+) steps with contradictory targets")
ATOMS = re.compile(r"^Loop time of .* steps with (\d+) atoms", re.M)
# A run whose log-gap targets were limited (a gap asked to change by more than a factor e in one step, docs/dem.md
# "Position update") more often than this per particle and step ran at a time step too large for its packing:
# the steps measured good at phi_bulk 0.37-0.54 had 0.0002-0.0027, the ones 12-30 % low 0.010-0.027, with and
# without the fluid (docs/benchmarks.md, "What limits the time step"). An intensive measure: the fraction of
# steps that fell back somewhere grows with the number of particles (100 % in the 956 spheres of the phi 0.47
# Table 8 scene at dt 0.02, 71 % in 98 of the same packing).
LIMITED_RATE_LIMIT = 0.005


def position_update_counts(text: str) -> dict | None:
    """The log-gap position update's counts summed over every 'fdm/couple timing of this run' line of a
    log (one per session of a resumed run): steps, fallback_steps (steps whose gap targets contradicted
    each other and moved straight with bounds, docs/dem.md 'Position update'), limited (log targets
    capped at a factor e per step), fallback_fraction, particles (LIGGGHTS's 'Loop time' line) and
    limited_per_particle_step. None if no line has them (gap_update none, or no run finished)."""
    found = POSITION_UPDATE.findall(text)
    if not found:
        return None
    steps = sum(int(g[1]) for g in found)
    fallback = sum(int(g[3]) for g in found)
    limited = sum(int(g[2]) for g in found)
    atoms = ATOMS.search(text)
    particles = int(atoms.group(1)) if atoms else None
    return dict(steps=steps, fallback_steps=fallback, limited=limited,
                fallback_fraction=fallback / steps if steps else 0.0, particles=particles,
                limited_per_particle_step=limited / (steps * particles) if steps and particles else None)


def time_step_too_large(counts: dict | None) -> str | None:
    """A warning when the log targets were limited more often than LIMITED_RATE_LIMIT per particle and step."""
    if not counts or counts.get("limited_per_particle_step") is None:
        return None
    rate = counts["limited_per_particle_step"]
    if rate <= LIMITED_RATE_LIMIT:
        return None
    return ("WARNING: the position update limited %.3g gap targets per particle and step (a gap asked to change "
            "by more than a factor e in one step; %d of %d steps fell back to the straight step): the time step "
            "is too large for this packing, and the particle stress is then low (12-30 %% at 0.010-0.027; "
            "docs/benchmarks.md, 'What limits the time step'): run again with a smaller dt (the fluid may keep "
            "its step: fix fdm/couple fluid_every, couette.py --fluid-every)"
            % (rate, counts["fallback_steps"], counts["steps"]))


def parse_thermo(text):
    """The per-step thermo rows (THERMO columns) as a dict of numpy arrays; non-finite values are
    kept (nan, inf)."""
    rows = []
    inside = False
    for line in text.splitlines():
        words = line.split()
        if words[:1] == ["Step"]:
            inside = True
            continue
        if not inside:
            continue
        if words[:2] == ["Loop", "time"]:
            inside = False
            continue
        if len(words) == len(THERMO):
            try:
                rows.append([float(w) for w in words])
            except ValueError:
                pass
    data = np.array(rows, dtype=float).reshape(-1, len(THERMO))
    return {name: data[:, k] for k, name in enumerate(THERMO)}


def read_dump(path):
    """Frames of a 'dump custom ... id type radius x y z vx vy vz' file: list of (step, array)."""
    frames = []
    with open(path) as f:
        lines = f.read().splitlines()
    k = 0
    while k < len(lines):
        if lines[k].startswith("ITEM: TIMESTEP"):
            step = int(lines[k + 1])
            n = int(lines[k + 3])
            k += 9  # TIMESTEP, step, NUMBER, n, BOX (3 lines + header), ATOMS header
            frames.append((step, np.array([[float(w) for w in lines[k + i].split()] for i in range(n)])))
            k += n
        else:
            k += 1
    return frames


def run(scene, run_dir, timeout=3600, np_dem=1, keep_log=True):
    """Runs the scene with fdmDEM (transport none) in run_dir. Returns a dict: ok, returncode, wall
    seconds, per-step arrays (step, iterations, solve_seconds, pair_blocks, wall_blocks, contacts,
    max_speed, max_spin), the run-end timing line (timing), finite (no nan/inf anywhere in the
    record), min_gap (smallest surface gap over the dumped frames, if dumped), the log's end."""
    if os.path.isdir(run_dir):
        shutil.rmtree(run_dir)
    scene.write(run_dir)
    cmd = [fdmdem(), "-in", "in.dem"]
    if np_dem > 1:
        cmd = ["mpirun", "-np", str(np_dem), "--bind-to", "none"] + cmd
    proc, wall = run_in(cmd, run_dir, "log.dem" if keep_log else None, timeout)
    return analyse(scene, run_dir, proc.stdout, proc.returncode, wall)


def run_in(cmd: list, run_dir: str, log: str | None = "log.dem",
           timeout: float = 3600) -> tuple[subprocess.CompletedProcess, float]:
    """Runs cmd (fdmDEM and its arguments) in run_dir with the project's environment, the command
    line written to run_dir/command and the screen output to run_dir/log (if given); returns the
    completed process (stdout text, stderr merged) and the wall seconds."""
    with open(os.path.join(run_dir, "command"), "w") as f:
        f.write(" ".join(cmd) + "\n")
    t0 = time.time()
    proc = subprocess.run(cmd, cwd=run_dir, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          errors="replace", timeout=timeout, env=environment())
    wall = time.time() - t0
    if log:
        with open(os.path.join(run_dir, log), "w") as f:
            f.write(proc.stdout)
    return proc, wall


def analyse(scene, run_dir, text, returncode=0, wall=None):
    thermo = parse_thermo(text)
    steps = thermo["step"]
    after = steps > 0  # step 0 is the setup row (no solve yet)
    solve_total = thermo["solveTotal"]
    solve_seconds = np.diff(np.concatenate(([0.0], solve_total[after]))) if np.any(after) else np.array([])
    out = dict(ok=returncode == 0, returncode=returncode, wall=wall, run_dir=run_dir,
               step=steps[after], iterations=thermo["iterations"][after], solve_seconds=solve_seconds,
               pair_blocks=thermo["pairBlocks"][after], wall_blocks=thermo["wallBlocks"][after],
               contacts=thermo["contacts"][after], max_speed=thermo["maxSpeed"][after],
               max_spin=thermo["maxSpin"][after], timing=parse_timing(text), log=text[-3000:])
    out["finite"] = bool(all(np.all(np.isfinite(thermo[c])) for c in THERMO)) and not re.search(
        r"\b-?(nan|inf)\b", text, re.IGNORECASE)
    out["completed"] = bool(len(out["step"]) and out["step"][-1] == scene.steps)
    dump = os.path.join(run_dir, "positions.dump")
    if scene.dump_every and os.path.isfile(dump):
        gaps = []
        p = scene.packing
        for step, a in read_dump(dump):
            order = np.argsort(a[:, 0])
            a = a[order]
            gaps.append((step, packing_module.minimum_gap(a[:, 3:6], a[:, 2], p.box, p.walls)))
        out["gap_history"] = gaps
        out["min_gap"] = min(g for _, g in gaps) if gaps else math.nan
    return out


def statistics(values, skip=1):
    """median, mean, max, 90th percentile of a per-step series, without its first `skip` steps (the
    first step of a run pays the resistance library's one-off set-up)."""
    v = np.asarray(values, dtype=float)[skip:]
    if v.size == 0:
        return dict(median=math.nan, mean=math.nan, max=math.nan, p90=math.nan, n=0)
    return dict(median=float(np.median(v)), mean=float(np.mean(v)), max=float(np.max(v)),
                p90=float(np.percentile(v, 90)), n=int(v.size))
