"""Where in its mesh cell a held sphere (or pair) sits: the offsets from a mesh vertex, in cells, that a
case scans to average over the cell (the cases' --positions N).

The scenes of these cases are mirror-symmetric about a vertex plane in x and z (the flow with the
reversal of every velocity where needed, the uniform mesh about any vertex), so that a part of the cell
holds every offset once: the quarter [0, 1/2)^2 when both mirrors apply, the half [0, 1) x [0, 1/2) when
only z -> -z does. N positions over the cell are then an m x m lattice (m even) computed in that part,
or N Halton points there for any other count."""
from __future__ import annotations

import math

import numpy as np


def halton_points(n: int, dims: int) -> np.ndarray:
    """The first n points of the Halton sequence in [0, 1)^dims (bases 2, 3, 5, ...; unscrambled, the
    origin left out): positions spread evenly over a mesh cell for any count, the cases' --positions."""
    from scipy.stats import qmc
    return qmc.Halton(d=dims, scramble=False).random(n + 1)[1:]


def symmetric_cell_offsets(n_positions: int, who: str, mirror_x: bool = True,
                           x_fastest: bool = True) -> tuple[list[tuple[float, float]], int]:
    """Offsets (o_x, o_z) in cells standing for n_positions positions of the centre in the plane section
    (x, z) of one mesh cell (module docstring). mirror_x: the scene is also symmetric in x, the offsets
    lie in [0, 1/2)^2; else in [0, 1) x [0, 1/2). n_positions = m^2 with m even (4, 16: the paper's
    4 x 4): the lattice points (i + 1/2)/m in that part; 1: (1/4, 1/4); otherwise n_positions Halton
    points (bases 2, 3) scaled into it. x_fastest: the lattice listed with o_x varying fastest (else o_z),
    the order the held configurations are run in. Returns (offsets to compute, positions they stand for);
    a count below 1 is a ValueError naming `who`."""
    if n_positions < 1:
        raise ValueError("%s: --positions must be at least 1, got %d" % (who, n_positions))
    if n_positions == 1:
        return [(0.25, 0.25)], 1
    m = int(round(math.sqrt(n_positions)))
    if m * m == n_positions and m % 2 == 0:
        g = [(i + 0.5) / m for i in range(m)]
        gx, gz = (g[: m // 2] if mirror_x else g), g[: m // 2]
        if x_fastest:
            return [(x, z) for z in gz for x in gx], n_positions
        return [(x, z) for x in gx for z in gz], n_positions
    points = halton_points(n_positions, 2)
    if mirror_x:
        return [(0.5 * float(x), 0.5 * float(z)) for x, z in points], n_positions
    return [(float(x), 0.5 * float(z)) for x, z in points], n_positions
