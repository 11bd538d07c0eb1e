#!/usr/bin/env python3
"""Stability and cost of the Eq. (31) particle solve with the sub-grid lubrication matrix R^SG
(fix fdm/couple + pair_style fdm/subgrid), for choosing its linear solver (issue 4: "Stability",
"Timing"). Every configuration is run with `solver cg tolerance 1e-10` (the fix's default),
`solver cg tolerance 1e-6` (the paper's tolerance, 4.4.5) and `solver ldlt`.

  stability   DEM only (fix fdm/couple transport none: isolated Stokes drag + R^SG + contact),
              1000 steps each, recording per step the solver iterations and the particle-solve
              seconds (f_couple[5], increments of f_couple[3]), the largest speed and spin, NaNs,
              the smallest surface gap (dumps):
                (a) a pair at xi = 1e-5 (a2/a1 = 1 and 1.4), held (move no) and pushed together
                    (normal load kn (h_r - gap) plus a tangential couple: it stays near xi = 1e-5
                    and turns);
                (b) a random packing (fdmsubgrid.packing) of 150 bidisperse spheres at phi = 0.5 between
                    two walls in shear (boundary p f p, walls at -U and +U, shear rate 1/s).
  timing      (c) 1000 bidisperse spheres (a1 = 1, a2 = 1.4, equal volumes) at phi = 0.45 in a
              periodic box on the matching mesh (Delta = a1/5, box rounded to whole cells), DEM
              only, driven by fix addforce (the two sizes pushed opposite ways, no net force):
              seconds per step (pair style collectBlocks + gather + assembly + one solve) for each
              solver, and for `cg tolerance 0.9` (the assembly alone: 0-1 CG iterations), as the
              median over steps 2.. of each run, then the median over --repeats runs; the packing
              as generated (overlap relaxation: ~1.4 pairs per sphere at gaps ~1.5e-4 a1) and
              after 100 hard-sphere Monte Carlo sweeps (few gaps below 1e-2 a1).
  coupled     the same 1000-sphere packing with the real fluid (fdmFoam + fdmDEM through fdmRun,
              one rank each): the mesh of the timing case, the paper's suspension settings
              (section 6: tol_p = 1e-3, tol_u = 1e-5, a fixed 10 inner iterations per step),
              --coupled-steps steps per solver; fluid seconds per inner iteration (steps.dat
              fluidSeconds / innerIterations) against the particle side per inner iteration
              (fdmDEM's per-step particle-solve seconds, summed over steps 2.. and divided by
              their inner iterations: the assembly once per step, the solve every iteration).
              The issue's target: particle side < 5 % of a fluid inner iteration.
  coupled-shear  (b) with the real fluid: the 150-sphere phi = 0.5 packing (box rounded to whole
              cells) between the walls in shear, --shear-steps steps of 10 inner iterations per
              solver: solver iterations per step as the contact network builds up, particle-solve
              seconds per inner iteration.
  scaling     DEM only, ldlt against cg 1e-6 as the system grows: 1000 spheres at phi = 0.45 and
              0.55, 2000 and 4000 at phi = 0.45 (relaxed packings), seconds per step (median over
              steps 2..6, then over --scaling-repeats runs).

  scripts/benchmarkSubgrid.py                      # everything (about 30 min on 2 cores)
  scripts/benchmarkSubgrid.py --skip-coupled       # DEM only (a few minutes)
  scripts/benchmarkSubgrid.py --only coupled --coupled-steps 3
  scripts/benchmarkSubgrid.py --only scaling coupled-shear    # re-run parts; the others are kept from the JSON
Writes docs/data/benchmarks_subgrid.json and docs/data/benchmarks_subgrid.md (the tables of docs/benchmarks.md);
run folders go to --workdir (default .cache/runs/benchmarkSubgrid).
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import time

import numpy as np

from fdmsubgrid import case, demonly, output, packing

HERE = os.path.dirname(os.path.abspath(__file__))
PROJECT = os.path.dirname(HERE)

SOLVERS = [("cg", 1e-10), ("cg", 1e-6), ("ldlt", None)]
ASSEMBLY = ("cg", 0.9)            # warm-started CG stops at once: what remains is the assembly
ETA, DELTA = 1.0, 0.2             # Pa s, m: a1 = 1 m, a1/Delta = 5
HR = 5e-3                         # roughness height h_r = 5e-3 a1 (paper section 6)
KN = KT = 1e4                     # N/m: F/kn ~ 1e-3 for the loads here (~10 N)
MU = 0.5
CONTACT = (KN, KT, MU, HR)


def label(solver, tol):
    return solver if tol is None else "%s %g" % (solver, tol)


def pair_packing(a1, a2, xi, L=12.0):
    gap = xi * (a1 + a2) / 2
    c = L / 2
    x = np.array([[c - a1 - gap / 2, c + 0.01, c + 0.02], [c + gap / 2 + a2, c + 0.01, c + 0.02]])
    return packing.Packing(x, [a1, a2], [1, 1 if a2 == a1 else 2], [L] * 3)


def summarize(r, scene, skip=1):
    """Numbers of one DEM-only run for the JSON and the tables."""
    it = demonly.statistics(r["iterations"], 0)  # the first, cold-started solve counts
    ts = demonly.statistics(r["solve_seconds"], skip)  # the first step pays the resistance set-up
    fail = None
    if not r["ok"]:
        lines = [l for l in r["log"].splitlines() if "ERROR" in l]
        fail = lines[-1] if lines else "exit %d" % r["returncode"]
    return dict(ok=r["ok"], completed=r["completed"], failure=fail,
                steps_done=int(r["step"][-1]) if len(r["step"]) else 0, steps=scene.steps,
                finite=r["finite"], iterations=it, solve_seconds=ts,
                max_speed=float(np.max(r["max_speed"])) if len(r["max_speed"]) else math.nan,
                max_spin=float(np.max(r["max_spin"])) if len(r["max_spin"]) else math.nan,
                min_gap=r.get("min_gap"), pair_blocks=int(r["pair_blocks"][-1]) if len(r["pair_blocks"]) else 0,
                wall_blocks=int(r["wall_blocks"][-1]) if len(r["wall_blocks"]) else 0,
                contacts=int(r["contacts"][-1]) if len(r["contacts"]) else 0, wall=r["wall"],
                first_step_seconds=float(r["solve_seconds"][0]) if len(r["solve_seconds"]) else math.nan,
                timing=r["timing"])


def stability(workdir, steps):
    results = []
    kn, hr = KN, HR
    for a2 in (1.0, 1.4):
        p = pair_packing(1.0, a2, 1e-5)
        gap0 = p.min_gap
        scenes = {
            # fixed at xi = 1e-5: 10 N along the line of centres, 5 N across, opposite on the two
            "held": dict(move=False, forces={"one": ([1], (10.0, 5.0, 0)), "two": ([2], (-10.0, -5.0, 0))}),
            # free: the normal load balances the contact spring at the initial gap, the couple turns the pair
            "pushed": dict(move=True, forces={"one": ([1], (kn * (hr - gap0), 5.0, 0)),
                                              "two": ([2], (-kn * (hr - gap0), -5.0, 0))}),
        }
        for name, kw in scenes.items():
            for solver, tol in SOLVERS:
                scene = demonly.Scene(p, solver, tol, steps=steps, dt=1e-3, eta=ETA, delta=DELTA, contact=CONTACT,
                                      dump_every=max(1, steps // 20), **kw)
                run_dir = os.path.join(workdir, "stability", "pair%g_%s_%s" % (a2, name, label(solver, tol).replace(" ", "")))
                r = demonly.run(scene, run_dir)
                s = summarize(r, scene)
                s.update(scene="(a) pair a2/a1 = %g at xi = 1e-5, %s" % (a2, name), solver=label(solver, tol),
                         n=2, speed_scale=10.0 / (6 * math.pi * ETA))
                results.append(s)
                report_stability(s)
    p = packing.random_packing(150, 0.5, bidisperse=True, seed=1, walls=(1,))
    U = 0.5 * p.box[1]  # shear rate 1/s
    for solver, tol in SOLVERS:
        scene = demonly.Scene(p, solver, tol, steps=steps, dt=1e-3, eta=ETA, delta=DELTA, contact=CONTACT,
                              walls={"ylo": (-U, 0, 0), "yhi": (U, 0, 0)}, dump_every=max(1, steps // 20))
        run_dir = os.path.join(workdir, "stability", "shear150_%s" % label(solver, tol).replace(" ", ""))
        r = demonly.run(scene, run_dir)
        s = summarize(r, scene)
        s.update(scene="(b) 150 bidisperse spheres, phi 0.5, walls in shear (U = +-%.3g)" % U,
                 solver=label(solver, tol), n=p.n, speed_scale=U, packing=p.summary())
        results.append(s)
        report_stability(s)
    return results


def report_stability(s):
    print("%-62s %-10s %s %4d/%d steps, finite %s, iterations median %.0f max %.0f, solve ms median %.3g max %.3g, "
          "max speed %.3g, min gap %.3g%s" % (
              s["scene"], s["solver"], "ok  " if s["ok"] else "FAIL", s["steps_done"], s["steps"], s["finite"],
              s["iterations"]["median"], s["iterations"]["max"], 1e3 * s["solve_seconds"]["median"],
              1e3 * s["solve_seconds"]["max"], s["max_speed"], s["min_gap"] if s["min_gap"] is not None else math.nan,
              "" if s["ok"] else "\n    " + str(s["failure"])), flush=True)


def timing_packings():
    p = packing.random_packing(1000, 0.45, bidisperse=True, seed=1, box_multiple=DELTA)
    q = packing.random_packing(1000, 0.45, bidisperse=True, seed=1, box_multiple=DELTA, shake_sweeps=100)
    return {"relaxed": p, "shaken": q}


def driving_forces(p, F=10.0):
    n1 = int(np.sum(p.types == 1))
    n2 = p.n - n1
    return {"small": ("type 1", (F, 0, 0)), "large": ("type 2", (-F * n1 / n2, 0, 0))}


def timing(workdir, steps, repeats, packings):
    results = []
    for name, p in packings.items():
        for solver, tol in [ASSEMBLY] + SOLVERS:
            runs = []
            for k in range(repeats):
                scene = demonly.Scene(p, solver, tol, steps=steps, dt=1e-3, eta=ETA, delta=DELTA, contact=CONTACT,
                                      forces=driving_forces(p))
                r = demonly.run(scene, os.path.join(workdir, "timing", "%s_%s_%d" % (
                    name, label(solver, tol).replace(" ", ""), k)))
                runs.append(summarize(r, scene, skip=1))
            medians = [r["solve_seconds"]["median"] for r in runs]
            s = dict(packing=name, summary=p.summary(), solver="assembly only (cg 0.9)" if (solver, tol) == ASSEMBLY
                     else label(solver, tol), repeats=repeats, steps=steps,
                     seconds_per_step=float(np.median(medians)), seconds_per_step_runs=medians,
                     seconds_first_step=float(np.median([r["first_step_seconds"] for r in runs])),
                     iterations_median=float(np.median([r["iterations"]["median"] for r in runs])),
                     iterations_max=float(np.max([r["iterations"]["max"] for r in runs])),
                     pair_blocks=runs[0]["pair_blocks"], contacts=runs[0]["contacts"],
                     ok=all(r["ok"] for r in runs))
            results.append(s)
            print("(c) 1000 spheres %-8s %-24s %.4g s/step (runs %s), iterations median %.0f max %.0f, %d pair "
                  "blocks, %d contacts" % (name, s["solver"], s["seconds_per_step"],
                                           " ".join("%.4g" % m for m in medians), s["iterations_median"],
                                           s["iterations_max"], s["pair_blocks"], s["contacts"]), flush=True)
    return results


def particle_work_shares(root):
    """The particle work as a percentage of the coupled run (all its steps), from the time breakdowns
    at the end of log.fluid and log.dem: fdmFoam's particle forcing (stencil integrals and
    corrections), fdmDEM's particle solve (sub-grid blocks and assembly, Eq. (31) solves, position
    update), its LIGGGHTS force computation (Pair: contact; Neigh), its gather/scatter, and the
    messages (fdmFoam's "exchange + DEM" less fdmDEM's work while fdmFoam waits); "particle work" is
    their sum, i.e. fdmFoam's particle forcing + exchange + DEM. None if a log has no breakdown."""
    try:
        with open(os.path.join(root, "log.fluid")) as f:
            fl = output.fluid_time_breakdown(f.read())
        with open(os.path.join(root, "log.dem")) as f:
            dm = output.dem_time_breakdown(f.read())
    except OSError:
        return None
    if not fl or not dm:
        return None
    pair = dm["sections"].get("Pair", 0.0) + dm["sections"].get("Neigh", 0.0)
    dem_work = dm["particle_solve"] + pair + dm["gather_scatter"]
    pct = 100.0 / fl["wall"]
    return {"fluid solve": fl["fluid_solve"] * pct, "particle forcing (fdmFoam)": fl["particle_forcing"] * pct,
            "assembly + Eq. 31 + position update": dm["particle_solve"] * pct,
            "contact + neighbour lists (Pair, Neigh)": pair * pct,
            "gather/scatter": dm["gather_scatter"] * pct,
            "messages": max(fl["exchange_dem"] - dem_work, 0.0) * pct,
            "particle work": (fl["particle_forcing"] + fl["exchange_dem"]) * pct,
            "run wall s": fl["wall"]}


def coupled(workdir, steps, p, np_fluid=1, solvers=SOLVERS, keep=False):
    results = []
    box = case.Box((0, 0, 0), tuple(p.box), DELTA)
    mesh = None
    for solver, tol in solvers:
        root = os.path.join(workdir, "coupled", label(solver, tol).replace(" ", ""))
        if os.path.isdir(root):
            shutil.rmtree(root)
        fluid = os.path.join(root, "fluid")
        # the paper's suspension runs (section 6): tol_p 1e-3, tol_u 1e-5, a fixed number of inner iterations
        case.write_fluid_case(fluid, box, nu=ETA, rho=1.0, tol_lambda=0, n_max=10, n_min=10, tol_u=1e-5, tol_p=1e-3,
                              n_particles=p.n)
        if mesh:  # one blockMesh for all the runs
            os.symlink(mesh, os.path.join(fluid, "constant", "polyMesh"))
        scene = demonly.Scene(p, solver, tol, steps=steps, dt=1e-3, eta=ETA, delta=DELTA, contact=CONTACT,
                              forces=driving_forces(p), fluid="portfile ../fluid/coupling.port")
        scene.write(os.path.join(root, "dem"))
        t0 = time.time()
        case.run(root, np_fluid=np_fluid)
        wall = time.time() - t0
        if not mesh:
            mesh = os.path.join(fluid, "constant", "polyMesh")
        st = output.steps(fluid)
        with open(os.path.join(root, "log.dem")) as f:
            text = f.read()
        r = demonly.analyse(scene, os.path.join(root, "dem"), text)
        inner = st["innerIterations"]
        fluid_per_iteration = st["fluidSeconds"] / inner
        n = min(len(inner), len(r["solve_seconds"]))
        particle = r["solve_seconds"][:n]
        later = slice(1, n) if n > 1 else slice(0, n)
        particle_per_iteration = float(np.sum(particle[later]) / np.sum(inner[:n][later]))
        s = dict(solver=label(solver, tol), steps=steps, np_fluid=np_fluid, cells=box.n[0] * box.n[1] * box.n[2],
                 wall=wall, inner_iterations=inner.tolist(), fluid_seconds=st["fluidSeconds"].tolist(),
                 forcing_seconds=st["particleSeconds"].tolist(), exchange_seconds=st["exchangeSeconds"].tolist(),
                 fluid_seconds_per_iteration=float(np.median(fluid_per_iteration)),
                 fluid_seconds_per_iteration_steps=fluid_per_iteration.tolist(),
                 particle_seconds_per_step=particle.tolist(), particle_seconds_per_iteration=particle_per_iteration,
                 solver_iterations_per_step=r["iterations"].tolist(), timing=r["timing"],
                 pair_blocks=int(r["pair_blocks"][-1]), contacts=int(r["contacts"][-1]))
        s["ratio"] = s["particle_seconds_per_iteration"] / s["fluid_seconds_per_iteration"]
        s["step_shares"] = particle_work_shares(root)
        results.append(s)
        if s["step_shares"]:
            print("coupled %-10s share of the run (%%): %s" % (s["solver"], ", ".join(
                "%s %.3g" % (k, v) for k, v in s["step_shares"].items())), flush=True)
        print("coupled %-10s fluid %.3g s/iteration (%d cells, %d rank), particle side %.3g s/iteration (%.2f %%); "
              "solver iterations per step %s; run-end line: %s" % (
                  s["solver"], s["fluid_seconds_per_iteration"], s["cells"], np_fluid, particle_per_iteration,
                  100 * s["ratio"], " ".join("%d" % i for i in s["solver_iterations_per_step"]),
                  "CG mean %.1f max %d" % (r["timing"]["iterations_mean"], r["timing"]["iterations_max"])
                  if r["timing"] else "-"), flush=True)
        if not keep:
            for entry in os.listdir(fluid):
                path = os.path.join(fluid, entry)
                try:
                    float(entry)
                except ValueError:
                    continue
                if entry != "0":
                    shutil.rmtree(path, ignore_errors=True)
    if mesh and not keep:
        shutil.rmtree(mesh, ignore_errors=True)
    return results


def coupled_shear(workdir, steps, solvers=SOLVERS):
    """(b) with the real fluid: 150 spheres at phi ~0.5 sheared between walls, 10 inner iterations per step."""
    results = []
    p = packing.random_packing(150, 0.5, bidisperse=True, seed=1, walls=(1,), box_multiple=DELTA)
    U = 0.5 * p.box[1]
    box = case.Box((0, 0, 0), tuple(p.box), DELTA, faces=("cyclic", ((-U, 0, 0), (U, 0, 0)), "cyclic"))
    for solver, tol in solvers:
        root = os.path.join(workdir, "coupled-shear", label(solver, tol).replace(" ", ""))
        if os.path.isdir(root):
            shutil.rmtree(root)
        case.write_fluid_case(os.path.join(root, "fluid"), box, nu=ETA, rho=1.0, tol_lambda=0, n_max=10, n_min=10,
                              tol_u=1e-5, tol_p=1e-3, n_particles=p.n)
        scene = demonly.Scene(p, solver, tol, steps=steps, dt=1e-3, eta=ETA, delta=DELTA, contact=CONTACT,
                              walls={"ylo": (-U, 0, 0), "yhi": (U, 0, 0)}, fluid="portfile ../fluid/coupling.port")
        scene.write(os.path.join(root, "dem"))
        failure = None
        try:
            case.run(root)
        except RuntimeError as e:
            # LIGGGHTS names its source file by absolute path: keep the data free of this machine's
            failure = str(e).strip().splitlines()[-1].replace(PROJECT + os.sep, "")
        with open(os.path.join(root, "log.dem")) as f:
            r = demonly.analyse(scene, os.path.join(root, "dem"), f.read())
        st = output.steps(os.path.join(root, "fluid"))
        n = min(len(st["innerIterations"]), len(r["solve_seconds"]))
        inner = st["innerIterations"][:n]
        s = dict(solver=label(solver, tol), steps=steps, steps_done=int(len(r["step"])), failure=failure,
                 packing=p.summary(), cells=box.n[0] * box.n[1] * box.n[2], finite=r["finite"],
                 max_speed=float(np.max(r["max_speed"])) if len(r["max_speed"]) else math.nan, wall_speed=U,
                 solver_iterations_per_step=r["iterations"].tolist(),
                 particle_seconds_per_iteration=float(np.sum(r["solve_seconds"][1:n]) / max(1, np.sum(inner[1:]))),
                 fluid_seconds_per_iteration=float(np.median(st["fluidSeconds"][:n] / inner)),
                 pair_blocks=int(r["pair_blocks"][-1]) if len(r["pair_blocks"]) else 0,
                 contacts=int(r["contacts"][-1]) if len(r["contacts"]) else 0)
        s["ratio"] = s["particle_seconds_per_iteration"] / s["fluid_seconds_per_iteration"]
        results.append(s)
        it = s["solver_iterations_per_step"]
        print("coupled-shear %-10s %d/%d steps%s, solver iterations per step first %s last %s max %s, particle %.3g "
              "s/iteration, fluid %.3g s/iteration (%.2f %%), max speed %.3g (walls %.3g)" % (
                  s["solver"], s["steps_done"], steps, "" if not failure else " FAILED: " + failure,
                  it[0] if it else "-", it[-1] if it else "-", max(it) if it else "-",
                  s["particle_seconds_per_iteration"], s["fluid_seconds_per_iteration"], 100 * s["ratio"],
                  s["max_speed"], U), flush=True)
    return results


SCALING = [(1000, 0.45), (1000, 0.55), (2000, 0.45), (4000, 0.45)]


def scaling(workdir, repeats, steps=6):
    results = []
    for n, phi in SCALING:
        p = packing.random_packing(n, phi, bidisperse=True, seed=1)
        for solver, tol in [("cg", 1e-6), ("ldlt", None)]:
            runs = []
            for k in range(repeats):
                scene = demonly.Scene(p, solver, tol, steps=steps, dt=1e-3, eta=ETA, delta=DELTA, contact=CONTACT,
                                      forces=driving_forces(p))
                r = demonly.run(scene, os.path.join(workdir, "scaling", "%d_%g_%s_%d" % (
                    n, phi, label(solver, tol).replace(" ", ""), k)))
                runs.append(summarize(r, scene))
            s = dict(n=n, phi=phi, solver=label(solver, tol), repeats=repeats, steps=steps,
                     seconds_per_step=float(np.median([r["solve_seconds"]["median"] for r in runs])),
                     iterations_median=float(np.median([r["iterations"]["median"] for r in runs])),
                     pair_blocks=runs[0]["pair_blocks"], ok=all(r["ok"] for r in runs))
            results.append(s)
            print("scaling %5d spheres phi %.2f %-8s %.4g s/step, iterations median %.0f, %d pair blocks" % (
                n, phi, s["solver"], s["seconds_per_step"], s["iterations_median"], s["pair_blocks"]), flush=True)
    return results


def markdown(results):
    out = []
    if results.get("stability"):
        out.append("Stability (DEM only, `transport none`, %d steps, dt = 1e-3 s; iterations: Eigen's CG count per step, "
                   "largest over the step's solves, all steps; solve ms: particle-solve seconds of a step, steps 2.. (the "
                   "first pays the resistance library's one-off set-up, ~0.2 s)):\n" % results["stability"][0]["steps"])
        out.append("| scene | solver | steps done | NaN | max speed [m/s] | min surface gap [a1] | iterations median / max "
                   "| solve ms median / max |")
        out.append("|---|---|---|---|---|---|---|---|")
        for s in results["stability"]:
            status = "%d/%d" % (s["steps_done"], s["steps"]) + ("" if s["ok"] else " **failed**")
            out.append("| %s | %s | %s | %s | %.3g | %s | %.0f / %.0f | %.3g / %.3g |" % (
                s["scene"], s["solver"], status, "no" if s["finite"] else "**yes**", s["max_speed"],
                "%.2g" % s["min_gap"] if s["min_gap"] is not None else "-", s["iterations"]["median"],
                s["iterations"]["max"], 1e3 * s["solve_seconds"]["median"], 1e3 * s["solve_seconds"]["max"]))
        fails = [s for s in results["stability"] if not s["ok"]]
        for s in fails:
            out.append("\n%s, %s: `%s`" % (s["scene"], s["solver"], s["failure"].strip()))
        out.append("")
    if results.get("timing"):
        t0 = results["timing"][0]
        out.append("Particle side per time step, 1000 spheres, DEM only (`transport none`; the pair style's "
                   "collectBlocks + gather + assembly + one solve; median over steps 2-%d of a run, then over %d runs):\n"
                   % (t0["steps"], t0["repeats"]))
        out.append("| packing | solver | s per step | iterations median / max | pair blocks | contacts |")
        out.append("|---|---|---|---|---|---|")
        for s in results["timing"]:
            out.append("| %s | %s | %.4f | %.0f / %.0f | %d | %d |" % (
                s["packing"], s["solver"], s["seconds_per_step"], s["iterations_median"], s["iterations_max"],
                s["pair_blocks"], s["contacts"]))
        out.append("")
    if results.get("coupled"):
        c0 = results["coupled"][0]
        out.append("Coupled, 1000 spheres (relaxed packing), %d cells (a1/Delta = 5), fdmFoam on %d rank, fdmDEM on 1, "
                   "%d steps of 10 inner iterations (fluid: median over the steps; particle side: steps 2-%d):\n"
                   % (c0["cells"], c0["np_fluid"], c0["steps"], c0["steps"]))
        out.append("| solver | fluid s per inner iteration | particle side s per inner iteration | ratio | solver "
                   "iterations per step (largest of its inner iterations) |")
        out.append("|---|---|---|---|---|")
        for s in results["coupled"]:
            out.append("| %s | %.3g | %.3g | %.2f %% | %s |" % (
                s["solver"], s["fluid_seconds_per_iteration"], s["particle_seconds_per_iteration"], 100 * s["ratio"],
                ", ".join("%d" % i for i in s["solver_iterations_per_step"])))
        out.append("")
    if results.get("coupled_shear"):
        c0 = results["coupled_shear"][0]
        out.append("Coupled, (b) with the fluid: 150 bidisperse spheres, phi %.3f, walls in shear, %d cells, %d steps "
                   "of 10 inner iterations:\n" % (float(c0["packing"].split("phi ")[1].split(",")[0]), c0["cells"], c0["steps"]))
        out.append("| solver | steps done | solver iterations per step: first, last, max | particle side s per inner "
                   "iteration | fluid s per inner iteration | ratio |")
        out.append("|---|---|---|---|---|---|")
        for s in results["coupled_shear"]:
            it = s["solver_iterations_per_step"] or [0]
            out.append("| %s | %d/%d%s | %d, %d, %d | %.3g | %.3g | %.2f %% |" % (
                s["solver"], s["steps_done"], s["steps"], "" if not s["failure"] else " **failed**", it[0], it[-1],
                max(it), s["particle_seconds_per_iteration"], s["fluid_seconds_per_iteration"], 100 * s["ratio"]))
        out.append("")
    if results.get("scaling"):
        s0 = results["scaling"][0]
        out.append("Scaling, DEM only (relaxed packings; s per step: median over steps 2-%d, then over %d runs):\n"
                   % (s0["steps"], s0["repeats"]))
        out.append("| spheres | phi | pair blocks | cg 1e-6 s per step (iterations) | ldlt s per step |")
        out.append("|---|---|---|---|---|")
        for n, phi in sorted({(s["n"], s["phi"]) for s in results["scaling"]}):
            row = {s["solver"]: s for s in results["scaling"] if (s["n"], s["phi"]) == (n, phi)}
            out.append("| %d | %.2f | %d | %.3g (%.0f) | %.3g |" % (
                n, phi, row["cg 1e-06"]["pair_blocks"], row["cg 1e-06"]["seconds_per_step"],
                row["cg 1e-06"]["iterations_median"], row["ldlt"]["seconds_per_step"]))
        out.append("")
    return "\n".join(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", choices=["stability", "timing", "coupled", "coupled-shear", "scaling"], nargs="+",
                    default=None)
    ap.add_argument("--skip-coupled", action="store_true")
    ap.add_argument("--steps", type=int, default=1000, help="steps of the stability runs")
    ap.add_argument("--timing-steps", type=int, default=30)
    ap.add_argument("--repeats", type=int, default=3, help="runs per timing configuration")
    ap.add_argument("--coupled-steps", type=int, default=4)
    ap.add_argument("--coupled-solvers", nargs="+", choices=["cg1e-10", "cg1e-6", "ldlt"], default=None,
                    help="the solvers of the coupled runs (default: all three)")
    ap.add_argument("--np-fluid", type=int, default=1)
    ap.add_argument("--shear-steps", type=int, default=30, help="steps of the coupled-shear runs")
    ap.add_argument("--scaling-repeats", type=int, default=2)
    ap.add_argument("--keep", action="store_true", help="keep the coupled runs' mesh and fields")
    ap.add_argument("--workdir", default=os.path.join(PROJECT, ".cache", "runs", "benchmarkSubgrid"))
    ap.add_argument("--out", default=os.path.join(PROJECT, "docs", "data", "benchmarks_subgrid"))
    args = ap.parse_args(argv)
    parts = args.only or (["stability", "timing", "scaling"] +
                          ([] if args.skip_coupled else ["coupled", "coupled-shear"]))
    os.makedirs(args.workdir, exist_ok=True)
    results = dict(machine=os.uname().nodename, cores=os.cpu_count(), date=time.strftime("%Y-%m-%d %H:%M"),
                   command=" ".join([os.path.relpath(sys.argv[0], PROJECT)] + (argv if argv is not None else sys.argv[1:])),
                   parameters=dict(eta=ETA, delta=DELTA, contact=CONTACT))
    if os.path.isfile(args.out + ".json"):  # keep the parts not re-run
        with open(args.out + ".json") as f:
            old = json.load(f)
        for k in ("stability", "timing", "coupled", "coupled-shear", "scaling"):
            key = k.replace("-", "_")
            if k not in parts and key in old:
                results[key] = old[key]
    t0 = time.time()
    if "stability" in parts:
        results["stability"] = stability(args.workdir, args.steps)
    packings = None
    if "timing" in parts:
        packings = timing_packings()
    elif "coupled" in parts:  # the coupled runs need the relaxed packing only
        packings = {"relaxed": packing.random_packing(1000, 0.45, bidisperse=True, seed=1, box_multiple=DELTA)}
    if "timing" in parts:
        results["timing"] = timing(args.workdir, args.timing_steps, args.repeats, packings)
    if "coupled" in parts:
        solvers = [st for st in SOLVERS if args.coupled_solvers is None
                   or label(*st).replace(" ", "") in args.coupled_solvers]
        results["coupled"] = coupled(args.workdir, args.coupled_steps, packings["relaxed"], args.np_fluid,
                                     solvers=solvers, keep=args.keep)
    if "coupled-shear" in parts:
        results["coupled_shear"] = coupled_shear(args.workdir, args.shear_steps)
    if "scaling" in parts:
        results["scaling"] = scaling(args.workdir, args.scaling_repeats)
    results["seconds"] = time.time() - t0
    with open(args.out + ".json", "w") as f:
        json.dump(results, f, indent=1)
    text = markdown(results)
    with open(args.out + ".md", "w") as f:
        f.write(text + "\n")
    print("\n" + text)
    print("wrote %s.json and %s.md (%.0f s)" % (args.out, args.out, results["seconds"]))


if __name__ == "__main__":
    main()
