"""Reading the outputs of coupled runs: fdmFoam's per-step and per-particle records
(postProcessing/fdm/*.dat), the binary particle records and ParaView files of fix fdm/output,
LIGGGHTS text dumps (older runs) and the time breakdowns of the logs."""
from __future__ import annotations

import io
import os
import warnings
from dataclasses import dataclass

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


def channel_profile(fluid_case):
    """fdmFoam's channelProfile.dat (a channel with the mean-flow correction on, docs/fluid.md): step
    (T,), time (T,), u (T, n, 3) the plane averages of U over the n cell planes from the low wall up,
    delta the cell width."""
    path = os.path.join(fluid_case, "postProcessing", "fdm", "channelProfile.dat")
    if not os.path.isfile(path):
        raise FileNotFoundError("%s not found: fdmFoam writes it in a channel with the mean-flow correction on "
                                "(innerIterations { meanFlowCorrection yes; }, the default)" % path)
    with open(path) as f:
        header = f.readline()
    try:
        n = int(header.split("over the ")[1].split()[0])
        delta = float(header.split("cell width ")[1].split()[0])
    except (IndexError, ValueError):
        raise ValueError("%s: the header does not give the planes and the cell width" % path) from None
    columns = ["step", "time"] + ["U%s%d" % (c, j) for j in range(n) for c in "xyz"]
    data = _read(path, columns)
    u = np.stack([data[name] for name in columns[2:]], axis=1).reshape(-1, n, 3)
    return dict(step=data["step"].astype(int), time=data["time"], u=u, delta=delta)


# ------------------------------------------------------------------------------------------------
# Wall loads: the force of the fluid (fdmFoam, postProcessing/fdm/walls.dat) and of the particles
# (fix fdm/couple ... walls FILE) on each wall, per step -- the momentum balance of a sheared
# suspension (fdmsubgrid.rheology.stress_balance, docs/profiles.md)
# ------------------------------------------------------------------------------------------------

_AXES = "xyz"


@dataclass(frozen=True)
class WallLoads:
    """Per step (T steps common to both records) and per wall (W walls, in the order of `faces`,
    e.g. ("ylo", "yhi")), the force on the wall [N] as (T, W, 3) arrays: `fluid_viscous`
    (-rho_f nu sum snGrad(U)|Sf| over the patch), `fluid_pressure` (rho_f sum p Sf, the solver's
    pressure level), `subgrid` (the particles' sub-grid lubrication, Eq. D.6) and `contact` (the
    particles' wall contacts); `areas` (W,) of the patches; `steps` (T,) DEM steps, `times` (T,)
    [s]. `particles` False if there was no particle record (subgrid and contact then zero)."""

    steps: np.ndarray
    times: np.ndarray
    faces: tuple
    areas: np.ndarray
    fluid_viscous: np.ndarray
    fluid_pressure: np.ndarray
    subgrid: np.ndarray
    contact: np.ndarray
    particles: bool

    @property
    def total(self) -> np.ndarray:
        """Force of the suspension on each wall without the pressure: viscous + sub-grid + contact
        (T, W, 3); the tangential components are the walls' shear loads."""
        return self.fluid_viscous + self.subgrid + self.contact

    def wall(self, face: str) -> int:
        if face not in self.faces:
            raise KeyError("no wall %r in the wall loads (walls: %s)" % (face, " ".join(self.faces)))
        return self.faces.index(face)


def _header_lines(path: str, count: int) -> list:
    lines = []
    with open(path) as f:
        for line in f:
            if not line.startswith("#"):
                break
            lines.append(line[1:].split())
            if len(lines) == count:
                break
    return lines


def _patch_face(patch: str) -> str:
    """fdmFoam's patch name of a box face (fdmsubgrid.foamcase: xLow, yHigh, ...) as LIGGGHTS's (xlo, yhi)."""
    if len(patch) > 1 and patch[0] in _AXES and patch[1:] in ("Low", "High"):
        return patch[0] + ("lo" if patch[1:] == "Low" else "hi")
    return patch


def read_wall_loads(run_dir: str, dem_file: str | None = "walls.dat") -> WallLoads:
    """The wall loads of a coupled run (run_dir with fluid/ and dem/): fdmFoam's
    fluid/postProcessing/fdm/walls.dat and, unless dem_file is None, the particle side
    dem/<dem_file> of `fix fdm/couple ... walls FILE`; joined on their common steps. The fluid
    patches are matched to the particle code's faces by name (fdmsubgrid.foamcase names the patch of the
    face ylo yLow). A last, incomplete line (a killed run) is dropped with a warning."""
    fluid_path = os.path.join(run_dir, "fluid", "postProcessing", "fdm", "walls.dat")
    if not os.path.isfile(fluid_path):
        raise FileNotFoundError("%s not found: did this fdmFoam (with wall records) run?" % fluid_path)
    head = _header_lines(fluid_path, 2)
    words = head[0][head[0].index("[m2]:") + 1:] if head and "[m2]:" in head[0] else []
    patches = [_patch_face(w) for w in words[0::2]]
    areas = np.array([float(w) for w in words[1::2]])
    if not patches:
        raise ValueError("%s: no patch areas in its header" % fluid_path)
    fluid = _read(fluid_path, ["step", "time"] + ["%s%d" % (p, k) for p in patches for k in range(6)])
    f_steps = fluid["step"].astype(np.int64)
    fl = np.stack([np.column_stack([fluid["%s%d" % (p, k)] for k in range(6)]) for p in patches], axis=1)
    if dem_file is None:
        faces = tuple(patches)
        zeros = np.zeros((len(f_steps), len(faces), 3))
        return WallLoads(f_steps, fluid["time"], faces, areas, fl[:, :, 0:3], fl[:, :, 3:6], zeros, zeros.copy(),
                         False)
    dem_path = os.path.join(run_dir, "dem", dem_file)
    if not os.path.isfile(dem_path):
        raise FileNotFoundError("%s not found: give fix fdm/couple 'walls %s' (docs/dem.md)" % (dem_path, dem_file))
    head = _header_lines(dem_path, 2)
    if len(head) < 2 or head[1][0] != "step":
        raise ValueError("%s is not a wall-loads file of fix fdm/couple (no '# step ...' header)" % dem_path)
    columns = head[1]
    dem_faces = []
    for c in columns[1:]:
        face = c.split(":")[0]
        if face not in dem_faces:
            dem_faces.append(face)
    dem = _read(dem_path, columns)
    d_steps = dem["step"].astype(np.int64)
    faces = tuple(f for f in patches if f in dem_faces)
    if not faces:
        raise ValueError("the fluid's wall patches (%s) and the particle code's walls (%s) have no face in common"
                         % (" ".join(patches), " ".join(dem_faces)))
    common, fi, di = np.intersect1d(f_steps, d_steps, return_indices=True)
    keep = [patches.index(f) for f in faces]

    def part(name: str) -> np.ndarray:
        return np.stack([np.column_stack([dem["%s:%s%s" % (f, name, c)][di] for c in "XYZ"]) for f in faces], axis=1)

    return WallLoads(common, fluid["time"][fi], faces, areas[keep], fl[fi][:, keep, 0:3], fl[fi][:, keep, 3:6],
                     part("subgrid"), part("contact"), True)


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
_DIAGONAL = (0, 3, 5)  # xx, yy, zz in the order xx xy xz yy yz zz (fdmsubgrid.profiles.COMPONENTS)


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
    """The frames of a suspension dump (dump_custom_command) as fdmsubgrid.profiles.Snapshot objects,
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
# Binary per-particle records of fix fdm/output (dem/particle_records.h, docs/dem.md)
# ------------------------------------------------------------------------------------------------

RECORDS_MAGIC = b"FDMPREC\n"


class ParticleRecords:
    """The complete blocks of a records file of `fix fdm/output ... records N FILE`.

    `records["x"]` is the (T, N, 3) array of field x (T record steps, N particles by tag, here
    index tag - 1), `records["radius"]` (T, N), and so on for every field of `records.fields`;
    `records.steps` and `records.times` are (T,). `records.blocks` is the structured array of the
    blocks (fields step, time, particles (N,), end), memory-mapped unless read with mmap=False.
    `records.header` is the file's JSON header (box_lo, box_hi, periodic, dt, every, ...).
    `dropped_bytes`: bytes after the last complete block (a run killed while writing it)."""

    def __init__(self, path: str, header: dict, blocks: np.ndarray, dropped_bytes: int) -> None:
        self.path, self.header, self.blocks, self.dropped_bytes = path, header, blocks, dropped_bytes

    @property
    def fields(self) -> tuple:
        return self.blocks.dtype["particles"].base.names

    @property
    def n_particles(self) -> int:
        return int(self.header["particles"])

    @property
    def steps(self) -> np.ndarray:
        return self.blocks["step"]

    @property
    def period(self) -> np.ndarray:
        """(3,) box lengths of the periodic directions, 0 where the box is not periodic (contacts.minimum_image)."""
        lo = np.asarray(self.header["box_lo"], dtype=float)
        hi = np.asarray(self.header["box_hi"], dtype=float)
        return np.where(np.asarray(self.header.get("periodic", [0, 0, 0]), dtype=bool), hi - lo, 0.0)

    @property
    def times(self) -> np.ndarray:
        return self.blocks["time"]

    def __len__(self) -> int:
        return len(self.blocks)

    def __getitem__(self, field: str) -> np.ndarray:
        if field in ("step", "time"):
            return self.blocks[field]
        if field not in self.fields:
            raise KeyError("%s has no field %r (fields: %s)" % (self.path, field, " ".join(self.fields)))
        return self.blocks["particles"][field]

    def __repr__(self) -> str:
        return "ParticleRecords(%s: %d blocks of %d particles, fields %s)" % (
            self.path, len(self), self.n_particles, " ".join(self.fields))


def records_dtype(header: dict) -> np.dtype:
    """The numpy dtype of one block of a records file, from its header."""
    particle = np.dtype([(f[0], f[1], tuple(f[2])) if len(f) > 2 else (f[0], f[1])
                         for f in header["particle_fields"]])
    if particle.itemsize != header["record_bytes"]:
        raise ValueError("records header: the particle fields make %d bytes, record_bytes says %d"
                         % (particle.itemsize, header["record_bytes"]))
    order = "<" if header.get("byte_order", "little") == "little" else ">"
    block = np.dtype([("step", order + "i8"), ("time", order + "f8"),
                      ("particles", particle, (int(header["particles"]),)), ("end", order + "i8")])
    if block.itemsize != header["block_bytes"]:
        raise ValueError("records header: a block of %d bytes, block_bytes says %d" % (block.itemsize,
                                                                                       header["block_bytes"]))
    return block


def read_records_header(path: str) -> dict:
    """The JSON header of a records file (raises ValueError if it is none)."""
    import json
    import struct
    if not os.path.isfile(path):
        raise FileNotFoundError("%s not found: did fdmDEM run with fix fdm/output ... records?" % path)
    with open(path, "rb") as f:
        head = f.read(12)
        if len(head) < 12 or head[:8] != RECORDS_MAGIC:
            raise ValueError("%s is not a particle records file of fix fdm/output (no FDMPREC header)" % path)
        length = struct.unpack("<I", head[8:12])[0]
        text = f.read(length)
    if len(text) < length:
        raise ValueError("%s: the records header is cut short" % path)
    header = json.loads(text.decode("ascii"))
    if header.get("format") != "fdm particle records" or header.get("header_bytes") != 12 + length:
        raise ValueError("%s: not a particle records header: %s" % (path, text[:200]))
    if header.get("version") != 1:
        raise ValueError("%s: records format version %s, this reader knows version 1" % (path, header.get("version")))
    return header


def read_particle_records(path: str, mmap: bool = True) -> ParticleRecords:
    """Every complete block of a binary records file of fix fdm/output (docs/profiles.md,
    "Particle records"), memory-mapped (mmap=True: nothing is read until used) or read into memory.
    A trailing partial block (a run killed while writing it) is dropped with a warning."""
    header = read_records_header(path)
    dtype = records_dtype(header)
    offset = int(header["header_bytes"])
    size = os.path.getsize(path)
    count = (size - offset) // dtype.itemsize
    if count == 0:
        blocks = np.zeros(0, dtype=dtype)
    elif mmap:
        blocks = np.memmap(path, dtype=dtype, mode="r", offset=offset, shape=(count,))
    else:
        blocks = np.fromfile(path, dtype=dtype, count=count, offset=offset)
    # a block is complete when its end marker is -1 - step (a file extended by a crash holds zeros)
    bad = np.flatnonzero(blocks["end"] != ~blocks["step"]) if count else np.zeros(0, dtype=int)
    if bad.size and bad[-1] != count - 1 or bad.size > 1:
        raise ValueError("%s: block %d of %d is damaged (its end marker does not match its step)"
                         % (path, bad[0] + 1, count))
    if bad.size:
        count = int(bad[0])
        blocks = blocks[:count]
    dropped = size - offset - count * dtype.itemsize
    if dropped:
        warnings.warn("%s: the last %d bytes are an incomplete block (the run stopped while writing it): ignored"
                      % (path, dropped))
    return ParticleRecords(path, header, blocks, dropped)


def record_snapshots(records, strain_rate: float = 1.0):
    """The blocks of a records file (a path or ParticleRecords) as fdmsubgrid.profiles.Snapshot objects,
    time = strain = record time x strain_rate, particles by tag: positions (wrapped into the box),
    radii, types, U_p, Omega_p, S^H = S_fluid + S_subgrid (the hydrodynamic stresslet, Eq. 52, not
    traceless) and S^c = S_contact (zero without stresslets). Also returns per block the
    hydrodynamic forces F_fluid + F_subgrid (N, 3): (snapshots, forces), as suspension_snapshots."""
    from .profiles import Snapshot
    r = read_particle_records(records) if isinstance(records, str) else records
    stresslets = "S_fluid" in r.fields
    snapshots, forces = [], []
    for k in range(len(r)):
        p = r.blocks[k]["particles"]
        snapshots.append(Snapshot(
            positions=p["x"], radii=p["radius"], velocities=p["U"], omegas=p["omega"],
            stresslet_h=p["S_fluid"] + p["S_subgrid"] if stresslets else None,
            stresslet_c=p["S_contact"] if stresslets else None, types=p["type"],
            time=float(r.blocks[k]["time"]) * strain_rate))
        forces.append(np.asarray(p["F_fluid"] + p["F_subgrid"], dtype=float))
    return snapshots, forces


# ------------------------------------------------------------------------------------------------
# ParaView files of fix fdm/output (vtk M DIR): the .pvd series and the particles' .vtp files
# ------------------------------------------------------------------------------------------------

def read_pvd(path: str) -> list:
    """The (time, file path) entries of a .pvd series, file paths resolved against its folder."""
    import xml.etree.ElementTree as ET
    root = ET.parse(path).getroot()
    folder = os.path.dirname(os.path.abspath(path))
    return [(float(d.get("timestep")), os.path.join(folder, d.get("file"))) for d in root.iter("DataSet")]


def read_vtp(path: str) -> dict:
    """The point arrays of a .vtp written by fix fdm/output (binary appended raw data, UInt64
    headers): a dict name -> (n,) or (n, components) array, with "Points" (n, 3)."""
    import re
    with open(path, "rb") as f:
        data = f.read()
    start = data.index(b"<AppendedData")
    raw = data.index(b"_", start) + 1
    xml = data[:start].decode("ascii")
    order = "<" if 'byte_order="LittleEndian"' in xml else ">"
    if 'header_type="UInt64"' not in xml:
        raise ValueError("%s: not a .vtp of fix fdm/output (header_type UInt64)" % path)
    n = int(re.search(r'NumberOfPoints="(\d+)"', xml).group(1))
    out = {}
    for m in re.finditer(r'<DataArray type="(Float64|Int64)" Name="([^"]+)"(?: NumberOfComponents="(\d+)")? '
                         r'format="appended" offset="(\d+)"/>', xml):
        kind, name, comps, offset = m.group(1), m.group(2), int(m.group(3) or 1), int(m.group(4))
        nbytes = int(np.frombuffer(data, dtype=order + "u8", count=1, offset=raw + offset)[0])
        values = np.frombuffer(data, dtype=order + ("f8" if kind == "Float64" else "i8"), count=nbytes // 8,
                               offset=raw + offset + 8)
        if name in ("connectivity", "offsets"):
            continue
        if values.size != n * comps:
            raise ValueError("%s: array %s has %d values for %d points" % (path, name, values.size, n))
        out[name] = values.reshape(n, comps) if comps > 1 else values
    return out


# ------------------------------------------------------------------------------------------------
# Time breakdowns at the end of a coupled run's logs (log.fluid, log.dem)
# ------------------------------------------------------------------------------------------------

def fluid_time_breakdown(text):
    """fdmFoam's "time breakdown" at the end of log.fluid as a dict: steps, inner_iterations, wall,
    and the seconds of fluid_solve, particle_forcing, exchange_dem (exchange + DEM: the messages and
    the whole particle side while fdmFoam waits), output, checkpoints (0 for a run without them). None if
    absent."""
    import re
    m = re.search(r"fdmFoam time breakdown \((\d+) steps, (\d+) inner iterations, ([0-9.eE+-]+) s wall\):\s*"
                  r"fluid solve\s+([0-9.eE+-]+) s.*?particle forcing\s+([0-9.eE+-]+) s.*?"
                  r"exchange \+ DEM\s+([0-9.eE+-]+) s.*?output\s+([0-9.eE+-]+) s", text, re.S)
    if not m:
        return None
    g = m.groups()
    checkpoints = re.match(r"\s*checkpoints\s+([0-9.eE+-]+) s", text[m.end():].split("\n", 1)[-1])
    return dict(steps=int(g[0]), inner_iterations=int(g[1]), wall=float(g[2]), fluid_solve=float(g[3]),
                particle_forcing=float(g[4]), exchange_dem=float(g[5]), output=float(g[6]),
                checkpoints=float(checkpoints.group(1)) if checkpoints else 0.0)


def fluid_inner_profile(text):
    """fdmFoam's "inner iterations by part" at the end of log.fluid (fluid/fdmFoam/runProfile) as a dict:
    inner_iterations, total seconds, and parts {name: seconds} (momentum assembly, pressure solve,
    Anderson mixing, ...). None if absent (a run of a build before it)."""
    import re
    m = re.search(r"fdmFoam inner iterations by part \((\d+) inner iterations, ([0-9.eE+-]+) s\):\n((?:    .*\n)+)",
                  text)
    if not m:
        return None
    parts = {}
    for line in m.group(3).splitlines():
        row = re.match(r"\s+(.+?)\s+([0-9.eE+-]+) s\s", line)
        if row:
            parts[row.group(1)] = float(row.group(2))
    return dict(inner_iterations=int(m.group(1)), total=float(m.group(2)), parts=parts)


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


# ------------------------------------------------------------------------------------------------
# The segments of a run and the machine's load while they ran (log.load, written by fdmRun)
# ------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Segment:
    """One fdmRun of a run (a start, a resume or a continuation of a compact snapshot): its kind, the particle
    steps it went from and to, its wall time from launch to its last sample (the end of a run that ended, within
    one sample interval of the kill of one that did not) and the 1-minute load averages sampled while it ran
    (mean and largest; nan where the machine has no /proc/loadavg)."""

    kind: str
    first_step: int
    last_step: int
    start: float
    end: float
    load_mean: float
    load_max: float
    samples: int
    from_eta: bool = False    # its wall time from fdmFoam's ETA (segments_from_fluid_log), not from log.load

    @property
    def wall_seconds(self) -> float:
        return self.end - self.start


def run_segments(case_dir: str) -> list[Segment]:
    """The segments of the run in case_dir from its log.load (fdmRun: a '# segment KIND from step N' line per
    fdmRun, then 'epoch load1 load5 load15 step' samples). A run of a build before log.load has none: ValueError
    naming the file."""
    path = os.path.join(case_dir, "log.load")
    if not os.path.isfile(path):
        raise ValueError("%s: no such file (fdmRun writes it since 2026-11-30; a run started before has its segments "
                         "only in log.fluid's '==== fdmRun' lines)" % path)
    segments: list[Segment] = []
    kind, first, rows = "", 0, []

    def close() -> None:
        if kind and rows:
            loads = np.array([r[1] for r in rows])
            finite = loads[np.isfinite(loads)]
            segments.append(Segment(kind=kind, first_step=first, last_step=int(max(r[2] for r in rows)),
                                    start=rows[0][0], end=rows[-1][0],
                                    load_mean=float(finite.mean()) if finite.size else float("nan"),
                                    load_max=float(finite.max()) if finite.size else float("nan"), samples=len(rows)))

    with open(path) as f:
        for number, line in enumerate(f, 1):
            words = line.split()
            if not words:
                continue
            if words[0] == "#":
                if len(words) != 6 or words[1] != "segment" or words[3:5] != ["from", "step"]:
                    raise ValueError("%s:%d: not a segment line: %r" % (path, number, line.strip()))
                close()
                kind, first, rows = words[2], int(words[5]), []
            else:
                if len(words) != 5 or not kind:
                    raise ValueError("%s:%d: not a sample 'epoch load1 load5 load15 step': %r" % (path, number, line.strip()))
                rows.append((float(words[0]), float(words[1]), int(words[4])))
    close()
    return segments


def segments_from_fluid_log(case_dir: str, planned_last_step: int) -> list[Segment]:
    """The segments of a run as its log.fluid holds them, for a run made (in part) before log.load: one per
    fdmRun ('==== fdmRun --resume from step N[, to step L ...]' lines; the first, a start, has none), its wall
    time from the last progress line's ETA, which fdmFoam computes as remaining x elapsed / steps done in the
    segment (elapsed = ETA x (step - first + 1) / (last - step), fdmFoam.C), so it leaves out the segment's
    start-up before fdmFoam's first step and what ran after its last progress line. planned_last_step: where the
    run was to end when a segment without 'to step L' ran (its input's 'run N upto'). No load is known (nan);
    start and end are seconds from the segment's own start; a segment that reached no progress line (refused)
    has none."""
    import re
    path = os.path.join(case_dir, "log.fluid")
    segments: list[Segment] = []
    current: dict | None = None

    def close() -> None:
        if current:
            segments.append(Segment(kind=current["kind"], first_step=current["first"],
                                    last_step=current["first"] if current["step"] is None else current["step"],
                                    start=0.0, end=current["elapsed"], load_mean=float("nan"),
                                    load_max=float("nan"), samples=0, from_eta=True))

    with open(path, errors="replace") as f:
        for line in f:
            if line.startswith("===="):
                m = re.match(r"==== fdmRun --(resume|from-snapshot) (?:\S+: )?(?:from )?step (\d+)(?:,? to (?:step )?(\d+))?",
                             line)
                if m:
                    close()
                    current = dict(kind="resume" if m.group(1) == "resume" else "snapshot", first=int(m.group(2)),
                                   last=int(m.group(3)) if m.group(3) else planned_last_step, first_fluid=None,
                                   step=None, elapsed=0.0)
                continue
            if line.startswith("Step "):
                m = re.match(r"Step (\d+) .*\| ETA ([0-9.eE+-]+) s", line)
                if not m:
                    continue
                if current is None:
                    current = dict(kind="start", first=0, last=planned_last_step, first_fluid=None, step=None,
                                   elapsed=0.0)
                step, eta = int(m.group(1)), float(m.group(2))
                if current["first_fluid"] is None:
                    current["first_fluid"] = step
                remaining = current["last"] - step
                if remaining > 0:
                    current["elapsed"] = eta * (step - current["first_fluid"] + 1) / remaining
                current["step"] = step
    close()
    return segments


def measured_segments(case_dir: str, planned_last_step: int | None = None) -> list[Segment]:
    """Every segment of a run: those log.load holds (run_segments) and, before them, those of a run made in
    part before log.load, from log.fluid's ETA (segments_from_fluid_log; planned_last_step needed then)."""
    if planned_last_step is None:
        return run_segments(case_dir)
    load = run_segments(case_dir) if os.path.isfile(os.path.join(case_dir, "log.load")) else []
    older = segments_from_fluid_log(case_dir, planned_last_step)
    if len(older) < len(load):
        raise ValueError("%s: log.load holds %d segments, log.fluid %d: not one run's logs" % (case_dir, len(load), len(older)))
    return older[:len(older) - len(load)] + load


def segments_table(segments: list[Segment]) -> str:
    """The segments as a table, with the total wall time and the mean load weighted by the segments' wall times."""
    import time
    lines = ["%-8s %-19s %9s %9s %10s %6s %6s" % ("segment", "started (UTC)", "from step", "to step", "wall / h",
                                                 "load", "max")]
    for s in segments:
        lines.append("%-8s %-19s %9d %9d %10.3f %6.2f %6.2f" % (
            s.kind + ("*" if s.from_eta else ""),
            "(from the ETA)" if s.from_eta else time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime(s.start)),
            s.first_step, s.last_step, s.wall_seconds / 3600, s.load_mean, s.load_max))
    wall = sum(s.wall_seconds for s in segments)
    # a killed segment's steps after its last checkpoint are run again by the next one: the run's steps
    # are from the first segment's start to the last one's end
    steps = segments[-1].last_step - segments[0].first_step if segments else 0
    weights = [(s.load_mean, s.wall_seconds) for s in segments if np.isfinite(s.load_mean) and s.wall_seconds > 0]
    load = sum(a * w for a, w in weights) / sum(w for _, w in weights) if weights else float("nan")
    lines.append("total: %d segments, %d particle steps, %.3f h of wall time at a mean load of %.2f"
                 % (len(segments), steps, wall / 3600, load))
    eta = [s for s in segments if s.from_eta]
    if eta:
        lines.append("(*: %d segments made before log.load, %.3f h of the total from fdmFoam's ETA, without their "
                     "start-up; the load is that of the others)" % (len(eta), sum(s.wall_seconds for s in eta) / 3600))
    return "\n".join(lines)


def keep_segments(segments: list[Segment], folder: str) -> str:
    """The segments of a run folder as JSON in folder/wall_<its first step>.json (one object per segment: its
    fields and wall_seconds; the total), replacing the file of the same run folder written before: a run folder
    lost with its logs keeps its measured wall time beside its compact snapshot (cases/poiseuille/ladderRun
    --save)."""
    import json
    from dataclasses import asdict
    if not segments:
        raise ValueError("no segments to keep")
    def plain(row: dict) -> dict:   # strict JSON: an unknown load is null
        return {k: (None if isinstance(v, float) and not np.isfinite(v) else v) for k, v in row.items()}

    data = dict(segments=[plain(dict(asdict(s), wall_seconds=s.wall_seconds)) for s in segments],
                wall_seconds=sum(s.wall_seconds for s in segments), first_step=segments[0].first_step,
                last_step=segments[-1].last_step)
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, "wall_%d.json" % segments[0].first_step)
    with open(path + ".tmp", "w") as f:
        json.dump(data, f, indent=1)
    os.replace(path + ".tmp", path)
    return path


USAGE = """usage: python3 -m fdmsubgrid.output segments CASE_DIR [PLANNED_LAST_STEP] [--keep FOLDER]
  the run's segments (fdmRun's log.load): when each ran, its steps, wall time and load; with PLANNED_LAST_STEP
  (where the run was to end) also the segments made before log.load, from log.fluid's ETA; --keep FOLDER: them
  also as FOLDER/wall_<first step>.json (keep_segments)"""


if __name__ == "__main__":
    import sys
    args = sys.argv[1:]
    keep = None
    if "--keep" in args:
        k = args.index("--keep")
        if k + 1 >= len(args):
            sys.exit(USAGE)
        keep = args[k + 1]
        del args[k:k + 2]
    if len(args) in (2, 3) and args[0] == "segments":
        try:
            found = measured_segments(args[1], int(args[2]) if len(args) == 3 else None)
        except ValueError as e:
            sys.exit("fdmsubgrid.output segments: %s" % e)
        print(segments_table(found))
        if keep:
            print("wrote %s" % keep_segments(found, keep))
    else:
        sys.exit(USAGE)
