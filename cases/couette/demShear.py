#!/usr/bin/env python3
"""The Couette scene without the fluid (fix fdm/couple transport none): a dense bidisperse packing
between walls at -U and +U, each particle with its isolated Stokes drag plus the sub-grid
lubrication and the contact springs of Eq. (31). No model of a suspension (the walls drag the
packing through lubrication and contact only, so a jammed packing carries far larger loads than
with the fluid), but a testbed of the particle side that runs in seconds: the stability of the
springs and of the position update (docs/benchmarks.md, "Stability map").

  demShear.py                                    the variants of docs/benchmarks.md (about 1 min)
  demShear.py --variant soft:kt=485 stiff:kt=kn  named variants; keys: kt (N/m or 'kn'), kn, mu,
                                                 dt, fix (extra fix fdm/couple keywords, '+' for a space)

Prints, per variant, how the run ended, the largest particle speed, the deepest overlap (pairs and
walls) over the dumped frames, and the position update's counts; writes --out (JSON).
"""
from __future__ import annotations

import argparse
import json
import os
import sys

import numpy as np

from fdmsubgrid import demonly, packing

HERE = os.path.dirname(os.path.abspath(__file__))

KN_RULE_047 = 3.128e5     # the case's k_n at phi 0.47 (couette.py's recipe, printed by the coupled runs)
KT_SOFT_047 = 485.1       # the case's former rule k_t = 0.5 zeta_t/dt at dt = 0.02 (before docs/contact.md 2c)
DEFAULT_VARIANTS = [
    "rule:kt=485.1",
    "rule_contact_gaps_free:kt=485.1:fix=contact_gaps+free",
    "rule_no_gap_update:kt=485.1:fix=gap_update+none",
    "stiff_kt:kt=kn",
    "stiff_kt_euler:kt=kn:fix=integrator+euler",
    "stiff_kt_no_gap_update:kt=kn:fix=gap_update+none",
    "stiff_kt_mu5:kt=kn:mu=5",
    "stiff_kt_mu0:kt=kn:mu=0",
    "kt_x10:kt=4851",
    "kn_x10:kn=3.128e6:kt=485.1",
    "kn_x10_dt0.04:kn=3.128e6:kt=485.1:dt=0.04",
    "kn_x10_dt0.04_free:kn=3.128e6:kt=485.1:dt=0.04:fix=contact_gaps+free",
]


def parse_variant(text: str) -> tuple[str, dict]:
    """'name:key=value:...' into (name, settings) with the defaults of the case at phi 0.47, dt 0.02."""
    name, *items = text.split(":")
    settings = dict(kn=KN_RULE_047, kt=KT_SOFT_047, mu=0.5, dt=0.02, fix="")
    for item in items:
        key, _, value = item.partition("=")
        if key not in settings:
            raise SystemExit("demShear: variant %s: unknown key %r (kn, kt, mu, dt, fix)" % (name, key))
        settings[key] = value.replace("+", " ") if key == "fix" else value
    kn = float(settings["kn"])
    kt = kn if settings["kt"] == "kn" else float(settings["kt"])
    return name, dict(kn=kn, kt=kt, mu=float(settings["mu"]), dt=float(settings["dt"]), fix=settings["fix"])


def deepest_overlaps(run_dir: str, box: np.ndarray) -> tuple[float, float, int]:
    """(smallest pair gap, smallest wall gap, most overlapping pairs in a frame) over the dump."""
    pair, wall, count = np.inf, np.inf, 0
    for _, a in demonly.read_dump(os.path.join(run_dir, "positions.dump")):
        x, r = a[:, 3:6], a[:, 2]
        i, j, d = packing.neighbour_pairs(x, box, 3.0, walls=(1,))
        g = d - r[i] - r[j]
        if len(g):
            pair = min(pair, float(g.min()))
            count = max(count, int(np.sum(g < 0)))
        wall = min(wall, float(np.min(np.minimum(x[:, 1] - r, box[1] - x[:, 1] - r))))
    return pair, wall, count


def main(argv: list[str] | None = None) -> list[dict]:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--variant", nargs="+", default=DEFAULT_VARIANTS)
    p.add_argument("--phi", type=float, default=0.47)
    p.add_argument("--size", type=float, nargs=3, default=(10, 12, 8))
    p.add_argument("--steps", type=int, default=200)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--workdir", default=os.path.join(HERE, "runs", "demShear"))
    p.add_argument("--out", default=os.path.join(HERE, "runs", "demShear.json"))
    args = p.parse_args(argv)
    pack = packing.channel_packing(tuple(args.size), phi=args.phi, seed=args.seed, min_gap=0.01, wall_gap=0.01)
    box = np.array(pack.box, dtype=float)
    U = 0.5 * box[1]          # walls at -U, +U: nominal shear rate 1
    rows = []
    print("%-24s %-9s %6s %9s %10s %10s %8s  %s" % ("variant", "ends", "steps", "max speed", "min gap", "min wall",
                                                   "overlaps", "position update"))
    for text in args.variant:
        name, s = parse_variant(text)
        scene = demonly.Scene(pack, solver="ldlt" + (" " + s["fix"] if s["fix"] else ""), steps=args.steps,
                              dt=s["dt"], eta=1.0, delta=1.0 / 3.0, contact=(s["kn"], s["kt"], s["mu"], 5e-3),
                              walls={"ylo": (-U, 0, 0), "yhi": (U, 0, 0)}, dump_every=10)
        run_dir = os.path.join(args.workdir, name)
        r = demonly.run(scene, run_dir, timeout=1800)
        speed = r["max_speed"]
        pair, wall, count = deepest_overlaps(run_dir, box) if os.path.exists(os.path.join(run_dir, "positions.dump")) \
            else (np.nan, np.nan, 0)
        timing = r["timing"] or {}
        update = ""
        for line in r["log"].splitlines():
            # the timing line's counts (not the particle-step breakdown's "position update" row)
            if "position update" in line and line.startswith("fdm/couple timing"):
                update = line[line.index("position update"):].strip()
        row = dict(variant=name, **s, completed=r["completed"], steps=int(len(speed)),
                   max_speed=float(speed.max()) if len(speed) else None, min_pair_gap=pair, min_wall_gap=wall,
                   most_overlapping_pairs=count, position_update=update, solve_seconds=timing.get("particle_solve"))
        rows.append(row)
        print("%-24s %-9s %6d %9.3g %10.3g %10.3g %8d  %s" % (
            name, "completed" if r["completed"] else "STOPPED", row["steps"], row["max_speed"] or np.nan, pair, wall,
            count, update[:110]), flush=True)
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, "w") as f:
        json.dump(dict(phi=args.phi, size=list(args.size), steps=args.steps, seed=args.seed, n_particles=pack.n,
                       command="cases/couette/demShear.py " + " ".join(argv if argv is not None else sys.argv[1:]),
                       rows=rows), f, indent=1)
    return rows


if __name__ == "__main__":
    main()
