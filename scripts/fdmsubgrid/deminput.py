"""The particle side of a coupled case: fdmDEM's LIGGGHTS input (the spheres' data file, the pair style
fdm/subgrid, fix fdm/couple connected to ../fluid, the held-configuration runs, the records), and whether
the sub-grid calibration covers a scene before it is launched, with the interpolated blocks a scene
needs where their measured error allows (scene_calibration; docs/dem.md)."""
from __future__ import annotations

import os
from typing import Iterable

def subgrid_pair_style(walls=(), subgrid=True, model=None, cutoff=None, wall_cutoff=None, calibration=None) -> str:
    """The pair_style line of fdm/subgrid (docs/dem.md): the sub-grid model, its cut-offs in mesh cells
    (pairs, walls; None: the pair style's defaults), `lubrication no` without the correction, and the
    walls as (face, (ux, uy, uz)) pairs, e.g. (("ylo", (0, 0, 0)), ("yhi", (U, 0, 0))). calibration: the
    calibration table's file relative to dem/ (SceneCalibration.table(); None: the shipped table)."""
    words = ["fdm/subgrid"]
    if model is not None:
        words.append("model %s" % model)
    if calibration is not None and subgrid:
        words.append("calibration %s" % calibration)
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


def balancing_force_line(box, grad_p0, n_particles: int = 1) -> str:
    """The LIGGGHTS line by which the particles carry V0 grad P0 in equal shares (fix addforce): in a box
    whose faces are periodic or slip nothing else holds the fluid, and the steady Stokes flow under the
    imposed gradient exists only with this balance (Eq. 43; move no fixes places, not velocities)."""
    volume = 1.0
    for lo, hi in zip(box.lo, box.hi):
        volume *= hi - lo
    return "fix             hold all addforce %s" % " ".join(repr(g * volume / n_particles) for g in grad_p0)


# the cut-off model's known error, what a scene outside the table gives up (docs/validation.md, "Squeeze
# calibration": closing velocities at a position the calibration did not use, a/Delta 3-5)
CUTOFF_MODEL_ERROR = "squeeze up to 16 % off for pairs, 24 % for walls: docs/validation.md"


def _calibration_command(a_over_delta: float, ratio: float | None) -> str:
    """The command that measures the calibration of one pair (a1/Delta, a2/a1) or, ratio None, one radius
    against a wall (docs/resistance.md, "Squeeze calibration"; the header of the shipped table)."""
    if ratio is None:
        return ("python3 -m fdmsubgrid.calibration --a-over-delta %.6g --no-pairs --tangential --out TABLE"
                % a_over_delta)
    return ("python3 -m fdmsubgrid.calibration --a-over-delta %.6g --ratios %.6g --no-wall --pair-tangential "
            "--out TABLE" % (a_over_delta, ratio))


def _coverage_summary(coverage: str) -> str:
    """`fdmResistance coverage`'s list of every tabulated block, summarised: the a/Delta and size ratios of the
    pair squeeze and the a/Delta of the wall squeeze (interpolated in between)."""
    import re
    parts = {p.split(" ", 1)[0]: p for p in coverage.split("; ")}
    pairs = re.findall(r"\(([\d.eE+-]+), ([\d.eE+-]+)\)", parts.get("pairs", ""))
    walls = re.findall(r"\(([\d.eE+-]+)\)", parts.get("walls", ""))
    def listed(values):
        return ", ".join(sorted(set(values), key=float)) or "none"
    # the a1/Delta of the same size ratios together: "3, 4, 5 x a2/a1 1, 1.4; 5.6 x 1"
    ratios = {}
    for a, r in pairs:
        ratios.setdefault(a, set()).add(r)
    groups = []
    for a in sorted(ratios, key=float):
        if groups and groups[-1][1] == ratios[a]:
            groups[-1][0].append(a)
        else:
            groups.append(([a], ratios[a]))
    grid = "; ".join("%s x %s" % (", ".join(ads), listed(rs)) for ads, rs in groups) or "none x none"
    return "pairs a1/Delta %s; walls a/Delta %s (interpolated between)" % (grid.replace(" x ", " x a2/a1 ", 1),
                                                                          listed(walls))


def uncalibrated(radii: Iterable[float], delta: float, walls: bool = False, model: str = "calibrated",
                 pairs: bool = True) -> list[str]:
    """What the shipped calibration table lacks for a scene of these radii at mesh size delta (with
    walls: also each radius against a wall), in pair_style fdm/subgrid's default model (calibrated):
    empty when the run can start, else one line per missing (a1/Delta, a2/a1) pair or wall a/Delta, each
    naming the command that would measure it, then a line with the table and what it covers and one with
    the alternative (--model cutoff, with its known error), to refuse the scene before it is launched
    (refusal() joins them; the pair style refuses it anyway at its start; `fdmResistance coverage` makes
    the same test). radii: every particle's (a radius held by one particle has no pair with itself, as in
    the pair style); pairs=False: the spheres are never in one scene together (one per run), so only each
    radius against the walls counts; model cutoff needs nothing."""
    from collections import Counter
    from .theory import resistance
    if model != "calibrated":
        return []
    counts = Counter(float(r) for r in radii)
    sizes = sorted(counts)
    missing, seen = [], set()
    r = {}
    for i, a in enumerate(sizes):
        for b in sizes[i:]:
            r = resistance("coverage", "--a1", a, "--a2", b, "--delta", delta, *(["--wall"] if walls and b == a else []))
            if pairs and not r["pair"] and (b != a or counts[a] > 1):
                key = ("pair", round(a / delta, 6), round(b / a, 6))
                if key not in seen:
                    seen.add(key)
                    missing.append("pair of radii %g and %g (a1/Delta %.4g, a2/a1 %.4g): %s"
                                   % (a, b, a / delta, b / a, _calibration_command(a / delta, b / a)))
            if walls and b == a and not r["wall"]:
                key = ("wall", round(a / delta, 6))
                if key not in seen:
                    seen.add(key)
                    missing.append("radius %g at a wall (a/Delta %.4g): %s"
                                   % (a, a / delta, _calibration_command(a / delta, None)))
    if missing:
        table = r["table"]
        root = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
        shown = os.path.relpath(table, root) if os.path.abspath(table).startswith(root + os.sep) else table
        missing.append("%s has %s" % (shown, _coverage_summary(r["coverage"])))
        missing.append("or --model cutoff (%s)" % CUTOFF_MODEL_ERROR)
    return missing


def refusal(who: str, missing: list[str]) -> str:
    """The message that refuses a scene uncalibrated() found lacking: one line per missing pair or wall
    (with its command) and the table's line, each on its own line."""
    lacking = sum(1 for line in missing if ": python3 -m fdmsubgrid.calibration" in line)
    return "%s: the sub-grid calibration (model calibrated) lacks %d of this scene's pairs and walls:\n%s" % (
        who, lacking, "\n".join("  " + line for line in missing))


class UncalibratedScene(ValueError):
    """A scene the sub-grid calibration does not cover, not even by an interpolation within its measured
    tolerance (scene_calibration): the message says so one line per refused pair or wall, each with the
    command that measures it."""


# the file name of a scene's own calibration table, in its dem/ folder (pair_style fdm/subgrid calibration FILE)
SCENE_TABLE = "subgrid_calibration.dat"


class SceneCalibration:
    """The sub-grid calibration table a scene runs with (scene_calibration): the shipped one (`text` None:
    nothing to write, the pair style reads its default) or the shipped one with the blocks of the scene's
    pairs and walls it lacks: measured on demand (`measured`: their subgridinterp.PairCoverage; `tables`, the
    tables measured on demand they come from) and interpolated (`interpolated`, each within
    subgridinterp.TOLERANCE as measured), written into each run folder's dem/ by `write`."""

    def __init__(self, who: str, text: str | None = None, interpolated: list | None = None,
                 measured: list | None = None, tables: list | None = None) -> None:
        self.who, self.text, self.interpolated = who, text, list(interpolated or [])
        self.measured, self.tables = list(measured or []), list(tables or [])

    def table(self) -> str | None:
        """The value of pair_style fdm/subgrid's `calibration` (relative to dem/), None for the shipped table."""
        return None if self.text is None else SCENE_TABLE

    def write(self, dem_dir: str) -> str | None:
        """Write the table into dem_dir (made if missing); returns its path, None for the shipped table."""
        if self.text is None:
            return None
        from .files import write_atomically
        os.makedirs(dem_dir, exist_ok=True)
        path = os.path.join(dem_dir, SCENE_TABLE)
        write_atomically(path, self.text)
        return path

    def line(self) -> str | None:
        """One line saying which pairs and walls are measured on demand (and where) and which are interpolated
        with their measured error bound, and that only their squeeze is (None for the shipped table)."""
        if self.text is None:
            return None
        from . import subgridinterp
        parts = []
        if self.measured:
            parts.append("the calibration measured on demand for %s (%s)" % (
                "; ".join(_entry_text(e) for e in self.measured), ", ".join(self.tables)))
        if self.interpolated:
            parts.append("the squeeze interpolated for %s (measured on held-back blocks, within %g %%; the tangential "
                         "functions there from the cut-off model: docs/resistance.md)" % (
                             "; ".join(_entry_text(e) for e in self.interpolated), 100 * subgridinterp.TOLERANCE))
        return "%s: the run reads dem/%s, the shipped table with %s" % (self.who, SCENE_TABLE, " and ".join(parts))


def _entry_text(entry) -> str:
    """An interpolated subgridinterp.PairCoverage in a few words, with its measured error bound."""
    error = "" if entry.error is None else ", error %.1f %%" % (100 * entry.error)
    if entry.kind == "wall":
        return "radius %g at a wall (a/Delta %g%s)" % (entry.pair[0], entry.a_over_delta, error)
    return "radii %g and %g (a1/Delta %g, a2/a1 %g%s)" % (entry.pair + (entry.a_over_delta, entry.ratio, error))


def scene_calibration(who: str, radii: Iterable[float], delta: float, walls: bool = False,
                      model: str = "calibrated", pairs: bool = True) -> SceneCalibration:
    """The one decision every scene writer makes before it writes a run: which sub-grid calibration table the
    scene runs with. The shipped table where it covers the scene (uncalibrated() finds nothing missing; model
    cutoff needs none); else, where every pair and wall it lacks is interpolated within subgridinterp.TOLERANCE
    as measured on held-back blocks (subgridinterp.coverage), the shipped table with those blocks added (the
    writer writes it with SceneCalibration.write into the run's dem/, points the pair style at it with
    `table()` and prints `line()`). Otherwise UncalibratedScene, its message one line per refused pair or wall
    (subgridinterp.refusal: why, the command that measures it and its cost), a line naming what would be
    interpolated, the table's line and the cut-off alternative. Arguments as uncalibrated()'s; who: the
    writer's name, first word of its lines."""
    radii = [float(r) for r in radii]
    missing = uncalibrated(radii, delta, walls=walls, model=model, pairs=pairs)
    if not missing:
        return SceneCalibration(who)
    from collections import Counter
    from . import subgridinterp
    counts = Counter(radii)
    sizes = sorted(counts)
    entries = [e for e in subgridinterp.coverage(sizes, sizes[0] / delta, walls=walls) if e.status != "calibrated"
               and (e.kind == "wall" or (pairs and (e.pair[0] != e.pair[1] or counts[e.pair[0]] > 1)))]
    refused = [e for e in entries if e.status == "refused"]
    interpolated = [e for e in entries if e.status == "interpolated"]
    measured = [e for e in entries if e.status == "measured"]
    if not entries:
        # the resistance library and the interpolation's reading of the table disagree: refuse as the library does
        raise UncalibratedScene(refusal(who, missing))
    if refused:
        lines = ["%s: the sub-grid calibration (model calibrated) lacks %d of this scene's pairs and walls beyond "
                 "what the interpolation reaches within %g %%:" % (who, len(refused), 100 * subgridinterp.TOLERANCE)]
        lines += ["  " + subgridinterp.refusal(e) for e in refused]
        if interpolated:
            lines.append("  interpolated within %g %%: %s" % (100 * subgridinterp.TOLERANCE, "; ".join(
                _entry_text(e) for e in interpolated)))
        lines += ["  " + line for line in missing[-2:]]
        raise UncalibratedScene("\n".join(lines))
    text, done = subgridinterp.interpolated_table([(e.kind, e.a_over_delta, e.ratio) for e in measured + interpolated])
    left = [d for d, e in zip(done, measured + interpolated) if d["status"] != e.status]
    if left:
        raise RuntimeError("scene_calibration: coverage() and interpolated_table() disagree on %s" % left)
    tables = sorted({t for d in done for t in d.get("tables", [])})
    return SceneCalibration(who, text, interpolated, measured, tables)


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
