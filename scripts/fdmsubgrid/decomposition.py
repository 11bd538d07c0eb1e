"""The mesh decomposition of a parallel fluid run (fdmRun -f N): the split (n_x, n_y, n_z) of the
uniform Cartesian mesh into N sub-domains with the least processor-boundary area, written to
system/decomposeParDict (docs/fluid.md, "Parallel runs").

    python3 -m fdmsubgrid.decomposition FLUID_CASE N     (what fdmRun calls; exit 2 with a message if
                                                   the mesh cannot take N ranks)

The rule for a case's own system/decomposeParDict: a dict that fdmRun wrote carries MARK and is
rewritten for every run; any other dict is the case's own and is used as it is when its
numberOfSubdomains is N, refused (never overwritten) otherwise.
"""
import gzip
import itertools
import os
import re
import sys

import numpy as np

MARK = "// written by fdmRun"
# Debian's OpenFOAM v1912 has dummy scotch/metis/kahip libraries: decomposePar stops on them
UNAVAILABLE_METHODS = ("scotch", "ptscotch", "metis", "kahip")


class DecompositionError(Exception):
    """A decomposition fdmRun cannot make: the message is for the user."""


# ---- reading constant/polyMesh -----------------------------------------------------------------

def _read_foam_file(path):
    """(header dict, body bytes) of an OpenFOAM file, plain or .gz."""
    for candidate in (path, path + ".gz"):
        if os.path.isfile(candidate):
            opener = gzip.open if candidate.endswith(".gz") else open
            with opener(candidate, "rb") as f:
                data = f.read()
            break
    else:
        raise DecompositionError("%s not found: is the fluid case meshed (blockMesh)?" % path)
    start = data.find(b"FoamFile")
    open_brace = data.find(b"{", start)
    close_brace = data.find(b"}", open_brace)
    header = {}
    for entry in data[open_brace + 1:close_brace].decode("latin-1").split(";"):
        words = entry.split(None, 1)
        if len(words) == 2:
            header[words[0]] = words[1].strip().strip('"')
    return header, data[close_brace + 1:]


def _skip_comments(body, pos):
    while True:
        while pos < len(body) and body[pos:pos + 1].isspace():
            pos += 1
        if body.startswith(b"//", pos):
            pos = body.find(b"\n", pos)
        elif body.startswith(b"/*", pos):
            pos = body.find(b"*/", pos) + 2
        else:
            return pos


def _read_list(header, body, pos, width, dtype):
    """The list starting at body[pos] (after comments): ascii or binary, `width` numbers per
    element (1 for labels, 3 for vectors). Returns (array of shape (n, width), end position)."""
    pos = _skip_comments(body, pos)
    match = re.compile(rb"(\d+)\s*\(").match(body, pos)
    if match is None:
        # a uniform list, n{value}: not written for meshes
        raise DecompositionError("unexpected list format in the mesh (at byte %d)" % pos)
    n = int(match.group(1))
    pos = match.end()
    if header.get("format", "ascii") == "binary":
        end = pos + n * width * np.dtype(dtype).itemsize
        values = np.frombuffer(body[pos:end], dtype=np.dtype(dtype).newbyteorder("<"))
        close = body.find(b")", end)
    else:
        # ascii: labels end at the first ')', vectors (x y z) at the (n+1)-th
        close = pos - 1
        for _ in range(1 if width == 1 else n + 1):
            close = body.find(b")", close + 1)
        text = body[pos:close].replace(b"(", b" ").replace(b")", b" ")
        values = np.array(text.split(), dtype=dtype)
    return values.reshape(n, width), close + 1


def _label_dtype(header):
    return np.int64 if "label=64" in header.get("arch", "") else np.int32


def _ascii_faces(body):
    """faceList in ascii: n( k(a b c ...) ... ) -> (offsets, labels)."""
    pos = _skip_comments(body, 0)
    match = re.compile(rb"(\d+)\s*\(").match(body, pos)
    faces = re.findall(rb"\d+\s*\(([\d\s]*)\)", body[match.end():])
    sizes, labels = [0], []
    for face in faces[:int(match.group(1))]:
        vertices = face.split()
        labels.extend(int(v) for v in vertices)
        sizes.append(len(vertices))
    return np.cumsum(sizes), np.array(labels)


def read_boundary(poly_mesh):
    """[(name, type, nFaces, startFace)] from polyMesh/boundary."""
    _, body = _read_foam_file(os.path.join(poly_mesh, "boundary"))
    text = re.sub(r"//.*", "", body.decode("latin-1"))
    patches = []
    for name, entries in re.findall(r"(\w+)\s*\{([^}]*)\}", text):
        fields = dict(re.findall(r"(\w+)\s+([^;]+);", entries))
        patches.append((name, fields.get("type", ""), int(fields.get("nFaces", 0)),
                        int(fields.get("startFace", 0))))
    return patches


def mesh_layout(fluid_case):
    """(cells, periodic) of the uniform Cartesian mesh of fluid_case: the cell counts in x, y, z
    and, per direction, whether it has a cyclic patch pair (the faces a split there adds)."""
    poly_mesh = os.path.join(fluid_case, "constant", "polyMesh")
    header, body = _read_foam_file(os.path.join(poly_mesh, "points"))
    points, _ = _read_list(header, body, 0, 3, np.float64)
    span = points.max(axis=0) - points.min(axis=0)
    cells = []
    for d in range(3):
        coordinates = np.sort(points[:, d])
        # distinct planes of points, to a tolerance far below any cell size
        cells.append(int(np.count_nonzero(np.diff(coordinates) > 1e-9 * span[d])))
    if (cells[0] + 1) * (cells[1] + 1) * (cells[2] + 1) != len(points):
        raise DecompositionError(
            "the mesh in %s is not a Cartesian box (%d points on %d x %d x %d planes): fdmFoam "
            "needs a uniform Cartesian mesh (docs/fluid.md)" % (poly_mesh, len(points), cells[0] + 1,
                                                             cells[1] + 1, cells[2] + 1))

    periodic = [False, False, False]
    cyclics = [p for p in read_boundary(poly_mesh) if p[1] == "cyclic" and p[2] > 0]
    if cyclics:
        header, body = _read_foam_file(os.path.join(poly_mesh, "faces"))
        if header.get("class") == "faceCompactList":
            offsets, end = _read_list(header, body, 0, 1, _label_dtype(header))
            labels, _ = _read_list(header, body, end, 1, _label_dtype(header))
            offsets, labels = offsets.ravel(), labels.ravel()
        else:
            offsets, labels = _ascii_faces(body)
        for _, _, _, start in cyclics:
            corners = points[labels[offsets[start]:offsets[start + 1]]]
            # the direction in which the face's corners do not spread is its normal
            periodic[int(np.argmin(np.ptp(corners, axis=0)))] = True
    return tuple(cells), tuple(periodic)


# ---- choosing the split ------------------------------------------------------------------------

def boundary_faces(cells, periodic, split):
    """Processor-boundary faces of a split: n_d - 1 planes across direction d, n_d if d is
    periodic (the cyclic faces then join two processors too), each of the other two counts."""
    faces = 0
    for d in range(3):
        planes = split[d] if (periodic[d] and split[d] > 1) else split[d] - 1
        faces += planes * cells[(d + 1) % 3] * cells[(d + 2) % 3]
    return faces


def choose_split(cells, periodic, n_ranks):
    """(n_x, n_y, n_z) with n_x n_y n_z = n_ranks, each n_d at most the cells in d, with the fewest
    processor-boundary faces; among equals, the splits whose n_d divide the cell counts (flat
    interfaces; OpenFOAM's hierarchical method balances the cell counts either way), then the most
    cube-like sub-domains, then the one cut most in x. DecompositionError if the mesh cannot take
    n_ranks."""
    candidates = []
    for nx in range(1, n_ranks + 1):
        if n_ranks % nx:
            continue
        for ny in range(1, n_ranks // nx + 1):
            if (n_ranks // nx) % ny:
                continue
            split = (nx, ny, n_ranks // (nx * ny))
            if all(split[d] <= cells[d] for d in range(3)):
                uneven = sum(cells[d] % split[d] != 0 for d in range(3))
                extents = [cells[d] / split[d] for d in range(3)]
                candidates.append((boundary_faces(cells, periodic, split), uneven, max(extents) / min(extents),
                                   [-s for s in split], split))
    if not candidates:
        total = cells[0] * cells[1] * cells[2]
        why = ("more ranks than the %d cells" % total if n_ranks > total else
               "no split n_x n_y n_z = %d has n_x <= %d, n_y <= %d and n_z <= %d (at least one cell "
               "layer per rank in each direction)" % (n_ranks, cells[0], cells[1], cells[2]))
        raise DecompositionError("the %d x %d x %d mesh cannot be split into %d sub-domains: %s"
                                 % (cells[0], cells[1], cells[2], n_ranks, why))
    return min(candidates)[-1]


# ---- system/decomposeParDict -------------------------------------------------------------------

DICT_TEMPLATE = """/*--------------------------------*- C++ -*----------------------------------*/
%(mark)s for %(n)d ranks: the %(nx)d x %(ny)d x %(nz)d mesh%(periodic)s split
// (%(sx)d %(sy)d %(sz)d), the fewest processor faces (%(faces)d). It is rewritten by every
// parallel run; remove the first line to keep a decomposition of your own (docs/fluid.md).
FoamFile
{
    version     2.0;
    format      ascii;
    class       dictionary;
    object      decomposeParDict;
}
numberOfSubdomains %(n)d;
method          hierarchical;   // scotch/metis are stubs in Debian's OpenFOAM
hierarchicalCoeffs { n (%(sx)d %(sy)d %(sz)d); order xyz; }
"""


def _dict_entry(text, key):
    match = re.search(r"^\s*%s\s+([^;]+);" % key, re.sub(r"//.*", "", text), re.MULTILINE)
    return match.group(1).strip() if match else None


def prepare(fluid_case, n_ranks):
    """Write system/decomposeParDict for n_ranks (or keep the case's own) and return a line saying
    which decomposition the run uses. DecompositionError if the mesh or the case's own dict
    cannot give n_ranks sub-domains."""
    path = os.path.join(fluid_case, "system", "decomposeParDict")
    if os.path.isfile(path):
        with open(path) as f:
            text = f.read()
        if MARK not in text:
            method = _dict_entry(text, "method")
            subdomains = _dict_entry(text, "numberOfSubdomains")
            if subdomains != str(n_ranks):
                raise DecompositionError(
                    "%s is the case's own (numberOfSubdomains %s, method %s), not written by fdmRun: "
                    "set numberOfSubdomains %d in it, or delete it to let fdmRun choose the split "
                    "for %d ranks" % (path, subdomains, method, n_ranks, n_ranks))
            if method in UNAVAILABLE_METHODS:
                raise DecompositionError(
                    "%s asks for method %s, a dummy library in Debian's OpenFOAM: use simple or "
                    "hierarchical, or delete the file to let fdmRun choose" % (path, method))
            return "the case's own decomposition (%s, method %s)" % (path, method)

    cells, periodic = mesh_layout(fluid_case)
    split = choose_split(cells, periodic, n_ranks)
    names = "".join(axis for axis, p in zip("xyz", periodic) if p)
    with open(path, "w") as f:
        f.write(DICT_TEMPLATE % dict(mark=MARK, n=n_ranks, nx=cells[0], ny=cells[1], nz=cells[2],
                                     periodic=" (periodic in %s)" % names if names else "",
                                     sx=split[0], sy=split[1], sz=split[2],
                                     faces=boundary_faces(cells, periodic, split)))
    return "%d x %d x %d cells split (%d %d %d), hierarchical, %d processor faces" % (
        cells[0], cells[1], cells[2], split[0], split[1], split[2], boundary_faces(cells, periodic, split))


def main(argv):
    if len(argv) != 3 or not argv[2].isdigit():
        sys.stderr.write("usage: python3 -m fdmsubgrid.decomposition FLUID_CASE N\n")
        return 2
    try:
        print(prepare(argv[1], int(argv[2])))
    except DecompositionError as e:
        sys.stderr.write("%s\n" % e)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
