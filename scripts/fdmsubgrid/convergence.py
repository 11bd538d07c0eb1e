"""The mesh and box convergence study of a case: its base scene, the same with a finer mesh, the same in
a larger box, and the changes of each measured quantity from the base to each of the other two
(cases/poiseuilleSphere and cases/pairPoiseuille, --convergence)."""
from __future__ import annotations

from typing import Mapping, Sequence

STUDIES = ("base", "mesh", "box")


def variants(a_over_delta: Sequence[float], boxes: Sequence) -> list[tuple[str, float, object]]:
    """The three scenes (study, a1/Delta, box): the base (the coarser mesh, the smaller box), the finer mesh
    in the smaller box, the coarser mesh in the larger box."""
    return [("base", a_over_delta[0], boxes[0]), ("mesh", a_over_delta[1], boxes[0]), ("box", a_over_delta[0], boxes[1])]


def change_entry(where: Mapping, base: Mapping, other: Mapping, base_values: Mapping, other_values: Mapping,
                 quantities: Sequence[str]) -> dict:
    """One change from the base to another scene: `where` first (the configuration and the study's name,
    in the caller's order), the meshes and boxes of the two scenes (their a_over_delta and box), then per
    quantity its value in each (Q_from, Q_to) and the change Q_to - Q_from."""
    entry = dict(where)
    entry.update(from_a_over_delta=base["a_over_delta"], to_a_over_delta=other["a_over_delta"], from_box=base["box"],
                 to_box=other["box"])
    for q in quantities:
        entry[q + "_from"], entry[q + "_to"] = base_values[q], other_values[q]
        entry[q + "_change"] = other_values[q] - base_values[q]
    return entry
