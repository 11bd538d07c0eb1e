"""The mesh and box convergence studies of a case.

`variants` and `change_entry`: its base scene, the same with a finer mesh, the same in a larger box, and
the changes of each measured quantity from the base to each of the other two (cases/poiseuilleSphere
and cases/pairPoiseuille, --convergence). `resolution_series`: one configuration at several a/Delta,
each quantity's change from the next coarser resolution and its error against a reference
(cases/threeSpheres, several --a-over-delta)."""
from __future__ import annotations

from typing import Mapping, Optional, Sequence

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


def resolution_series(a_over_delta: Sequence[float], values: Sequence[Mapping[str, float]],
                      quantities: Sequence[str], reference: Optional[Mapping[str, float]] = None,
                      spread_suffix: str = "_std") -> list[dict]:
    """One configuration measured at several mesh resolutions (a/Delta, strictly ascending), its values
    per resolution in `values` (each a mapping with every quantity and, where measured, its spread under
    Q + spread_suffix). Returns one entry per resolution: a_over_delta, and per quantity Q its value, its
    spread (None if not given), `Q_change` = Q - Q at the next coarser resolution and `Q_rel_change` =
    that change over |Q| at the coarser one (None at the coarsest), and, with a reference, `Q_reference`
    and `Q_error` = (Q - reference)/|reference| (None without one). A resolution out of order, a missing
    quantity or a zero value a change is divided by is a ValueError naming it."""
    resolutions = [float(n) for n in a_over_delta]
    if len(resolutions) != len(values):
        raise ValueError("resolution_series: %d resolutions for %d sets of values" % (len(resolutions), len(values)))
    for coarse, fine in zip(resolutions, resolutions[1:]):
        if not fine > coarse:
            raise ValueError("resolution_series: a/Delta must be strictly ascending, got %g after %g" % (fine, coarse))
    out: list[dict] = []
    for k, (n, v) in enumerate(zip(resolutions, values)):
        entry: dict = dict(a_over_delta=n)
        for q in quantities:
            if q not in v:
                raise ValueError("resolution_series: %s missing at a/Delta %g" % (q, n))
            entry[q] = float(v[q])
            spread = v.get(q + spread_suffix)
            entry[q + spread_suffix] = None if spread is None else float(spread)
            if k == 0:
                entry[q + "_change"] = entry[q + "_rel_change"] = None
            else:
                coarser = float(values[k - 1][q])
                if coarser == 0:
                    raise ValueError("resolution_series: %s is 0 at a/Delta %g: no relative change"
                                     % (q, resolutions[k - 1]))
                entry[q + "_change"] = entry[q] - coarser
                entry[q + "_rel_change"] = (entry[q] - coarser) / abs(coarser)
            ref = None if reference is None else reference.get(q)
            entry[q + "_reference"] = None if ref is None else float(ref)
            entry[q + "_error"] = None if not ref else (entry[q] - float(ref)) / abs(float(ref))
        out.append(entry)
    return out
