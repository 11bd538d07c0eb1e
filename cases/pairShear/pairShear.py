#!/usr/bin/env python3
"""A pair of free spheres in simple shear flow between two moving walls (paper section 5.3, Fig. 14).

Walls y = 0 and y = H move at -U and +U along x (shear rate 2U/H = 1); x and z are periodic. The
spheres (a1 = 1, a2 = lambda a1) start in the plane z = Lz/2, symmetric about the box centre, so
that the relative position r = x2 - x1 starts at (r_x0, r_y0): r_x0 = -6 (-4.5 in a box shorter
than 15 a1) without contact, -3.48 with contact (the paper's Fig. 15). The shear brings sphere 2
over sphere 1. Without contact the relative trajectory is fore-aft symmetric (Stokes flow is
reversible): the final cross-stream offset equals the initial one. With contact (roughness h_r,
friction mu_s) it is not: the spheres touch for -1.39 <~ r_x/a1 <~ 0 in the paper (a2/a1 = 1.4,
r_y0 = 0.93, h_r = 5e-3 a1, mu_s = 0.5) and leave on a higher streamline.

  pairShear.py                 lambda = 1 without contact, r_y0 = 0.5 (CI size: a1/Delta = 3, 12 x 8 x 6)
  pairShear.py --contact       lambda = 1.4, h_r = 5e-3 a1, mu_s = 0.5 (kn = 2e4, kt = 200 N/m)
  pairShear.py --contact --size 20 12 10     the same with room: the paper's contact window
  pairShear.py --full          both, a1/Delta = 5, 20 x 12 x 8, several impact parameters
  pairShear.py --contact --fluid-every 3     the fluid solved every 3rd step only (fix fdm/couple fluid_every)
  pairShear.py --contact --dt 0.025 --fluid-every 4   half the particle step, the fluid every 0.1: the
                                             every-step window within 0.012 a1, 1.8x fewer solves per strain
  pairShear.py --help          every option
Writes results.json and results_pairShear.png here (docs/cases.md).
"""
import argparse
import json
import math
import os
import shutil
import time
from typing import List

import numpy as np

from fdmsubgrid import case, output, suspension
from fdmsubgrid.results import Row, relative, write_results

HERE = os.path.dirname(os.path.abspath(__file__))


# The paper's contact case (section 5.3, Figs. 14-15): a2/a1 = 1.4, r^0 = (-3.48, 0.93) a1
PAPER_CONTACT_RATIO, PAPER_CONTACT_R_X0, PAPER_CONTACT_R_Y0 = 1.4, -3.48, 0.93


def paper_contact(a1=1.0, kn=2e4, kt=200.0):
    """(kn, kt, mu_s, h_r) of the paper's contact case: h_r = 5e-3 a1, mu_s = 0.5. The springs are
    ours (docs/contact.md): the pair is pressed together by F_n = 20-28 N, so kn = 2e4 N/m keeps the
    contact in the roughness layer (F_n/(kn h_r) = 0.2-0.27, gap 3.6e-3 to 4e-3 a1) and the surfaces part as
    soon as the load turns (softer springs let lubrication hold the pair inside h_r long after
    r_x = 0). Both springs are within the ab2 limit (1) at dt = 0.05: dt kn/zeta_n = 0.62 and
    dt kt/zeta_t = 0.44, with zeta_n = 1617 and zeta_t = 22.6 N s/m the normal and slip resistances
    of the free pair at a gap of 4e-3 a1 (Stokes drag + sub-grid block at a1/Delta = 3, computed as
    in fdmsubgrid.contactstability.ContactResistances.pair_slip)."""
    return (kn, kt, 0.5, 5e-3 * a1)


def run_trajectory(workdir, ratio=1.0, r_y0=0.5, contact=None, a_over_delta=3.0, size=(12.0, 8.0, 6.0), dt=0.05,
                   tol_lambda=1e-3, n_max=50, cutoff=None, np_fluid=1, keep=False, max_steps=4000, lubrication=True,
                   gap_update="log", integrator="ab2", r_x0=None, acceleration="anderson",
                   mean_flow_correction=True, tol_velocity=0.0, model="calibrated", fluid_every=1,
                   held_drag="extrapolated"):
    """One coupled run from r_x = r_x0 (default -r_x_end) to +r_x_end (r_x_end = 6, the paper's, or
    less in a box shorter than 14 a1: the minimum image in the periodic x must stay unambiguous);
    returns the relative trajectory and the gaps. fluid_every K: the fluid is solved every K-th particle
    step (fix fdm/couple ... fluid_every, docs/dem.md), the steps between holding its force with held_drag
    (extrapolated or constant); the trajectory is read from the particle records of every step either way."""
    if fluid_every < 1:
        raise ValueError("pairShear: fluid_every must be at least 1, got %r" % fluid_every)
    a1, a2 = 1.0, ratio
    delta = a1 / a_over_delta
    Lx, H, Lz = size
    shear = 1.0
    U = shear * H / 2
    eta = 1.0
    name = "lambda%g_ry%g_ad%g_%s%s_dt%g_%s_%s" % (ratio, r_y0, a_over_delta, "contact" if contact else "smooth",
                                                "" if lubrication else "_nolub", dt, integrator, gap_update)
    if r_x0 is not None:
        name += "_rx%g" % r_x0
    if fluid_every > 1:
        name += "_fluidEvery%d%s" % (fluid_every, "" if held_drag == "extrapolated" else "_" + held_drag)
    run_dir = os.path.join(workdir, name)
    if os.path.isdir(run_dir):
        shutil.rmtree(run_dir)
    box = case.Box((0, 0, 0), (Lx, H, Lz), delta, faces=("cyclic", ((-U, 0, 0), (U, 0, 0)), "cyclic"))
    zc = Lz / 2 + 0.25 * delta
    r_x_end = min(6.0, Lx / 2 - 1.5)
    r_x_start = -r_x_end if r_x0 is None else r_x0
    if not -r_x_end <= r_x_start < 0:
        raise ValueError("pairShear: r_x0 = %g must lie in [-%g, 0) for a box of length %g" % (r_x_start, r_x_end, Lx))
    p1 = (Lx / 2 - r_x_start / 2, H / 2 - r_y0 / 2, zc)
    p2 = (Lx / 2 + r_x_start / 2, H / 2 + r_y0 / 2, zc)
    # the relative x-velocity is about shear * r_y: enough steps to go from r_x0 to r_x_end, with margin
    steps = min(max_steps, int(math.ceil((r_x_end - r_x_start) / (shear * max(r_y0, 0.3)) / dt * 1.6)))
    case.write_fluid_case(os.path.join(run_dir, "fluid"), box, nu=eta, rho=1.0, tol_lambda=tol_lambda, n_max=n_max,
                          first_step=(tol_lambda / 10 if tol_lambda > 0 else 0.0, 3000), n_particles=2,
                          tol_u=1e-5, tol_p=1e-4, acceleration=acceleration, tol_velocity=tol_velocity,
                          mean_flow_correction=mean_flow_correction)
    pair = "fdm/subgrid model %s%s wall ylo %r 0 0 wall yhi %r 0 0" % (
        model, "" if cutoff is None else " cutoff %g" % cutoff, -U, U)
    if not lubrication:
        pair += " lubrication no"
    if contact:
        kn, kt, mu, hr = contact
        pair += " contact %r %r %r %r" % (kn, kt, mu, hr)
    # runs of about 5 steps until sphere 2 has passed r_x_end (x2 - x1, minimum image in the periodic x;
    # 5 steps move r_x by much less than the 1.5 a1 left before the minimum image flips); a multiple of
    # fluid_every, since the fluid is also solved at the last step of every run
    chunk = fluid_every * int(math.ceil(5.0 / fluid_every))
    rx = "variable        rx equal x[2]-x[1]-%(L)r*round((x[2]-x[1])/%(L)r)" % dict(L=Lx)
    loop = ["thermo_style    custom step v_rx f_couple[1] f_couple[5] f_couple[6] f_couple[8]",
            "thermo          20",
            "variable        chunk loop %d" % int(math.ceil(steps / float(chunk))),
            "label           advance",
            "run             %d" % chunk,
            'if              "${rx} > %r" then "jump SELF finished"' % r_x_end,
            "next            chunk",
            "jump            SELF advance",
            "label           finished"]
    fix = "integrator %s gap_update %s" % (integrator, gap_update)
    if fluid_every > 1:
        fix += " fluid_every %d held_drag %s" % (fluid_every, held_drag)
    case.write_dem_input(os.path.join(run_dir, "dem"), box, [p1 + (a1,), p2 + (a2,)], dt=dt, pair_style=pair,
                         fix_options=fix, before_run=rx + "\n" + case.RECORD_EVERY_STEP, runs=loop,
                         name="in.pairShear")
    wall, _, steps_data = case.run_and_read(run_dir, np_fluid=np_fluid, keep=keep)
    records = output.read_particle_records(os.path.join(run_dir, "dem", "particles.records"), mmap=False)
    stepped = records.steps >= 1   # a block at step 0 holds the start, not a step
    rel = records["x"][stepped, 1, :] - records["x"][stepped, 0, :]
    rel[:, 0] -= Lx * np.round(rel[:, 0] / Lx)
    r = np.linalg.norm(rel, axis=1)
    xi = 2 * r / (a1 + a2) - 2
    gap = r - a1 - a2
    return dict(ratio=ratio, r_y0=r_y0, contact=contact, dt=dt, integrator=integrator, gap_update=gap_update, a_over_delta=a_over_delta, size=list(size),
                cells=box.n[0] * box.n[1] * box.n[2], steps=int(len(r)), wall_seconds=wall,
                fluid_every=fluid_every, held_drag=held_drag if fluid_every > 1 else None,
                fluid_steps=int(len(steps_data["innerIterations"])),
                inner_iterations_mean=float(steps_data["innerIterations"].mean()),
                # the cost per particle step: with fluid_every K the fluid's solves spread over K steps
                fluid_solves_per_step=float(steps_data["innerIterations"].sum() / max(len(rel), 1)),
                unconverged_steps=int((steps_data["converged"] == 0).sum()),
                r_x=rel[:, 0].tolist(), r_y=rel[:, 1].tolist(), r_z=rel[:, 2].tolist(), xi=xi.tolist(),
                gap_over_a1=(gap / a1).tolist())


def summarise(t, h_r=None):
    """The figures of one trajectory: initial and final offsets at |r_x| = the same distance,
    minimum gap, the contact window."""
    rx, ry, gap = np.array(t["r_x"]), np.array(t["r_y"]), np.array(t["gap_over_a1"])
    start = abs(rx[0])
    end = rx >= start
    s = dict(r_x_start=float(rx[0]), r_y_start=float(ry[0]), min_gap_over_a1=float(gap.min()),
             min_xi=float(min(t["xi"])), r_x_at_min_gap=float(rx[np.argmin(gap)]))
    if end.any():
        k = int(np.argmax(end))
        # interpolate r_y at r_x = +start
        f = (start - rx[k - 1]) / (rx[k] - rx[k - 1])
        ry_end = ry[k - 1] + f * (ry[k] - ry[k - 1])
        s.update(r_y_end=float(ry_end), fore_aft_asymmetry=float((ry_end - ry[0]) / ry[0]))
    if h_r:
        touching = gap < h_r
        if touching.any():
            idx = np.where(touching)[0]

            def crossing(i, j):
                # r_x where the gap passes h_r between samples i and j (log-linear: the gap changes
                # by a factor per step near contact)
                if min(i, j) < 0 or max(i, j) >= len(gap) or gap[i] <= 0 or gap[j] <= 0:
                    return float(rx[min(max(j, 0), len(gap) - 1)])
                f = np.log(h_r / gap[i]) / np.log(gap[j] / gap[i])
                return float(rx[i] + f * (rx[j] - rx[i]))

            s.update(contact_r_x_from=crossing(idx[0] - 1, idx[0]), contact_r_x_to=crossing(idx[-1], idx[-1] + 1),
                     contact_steps=int(len(idx)))
        else:
            s.update(contact_r_x_from=None, contact_r_x_to=None)
    return s


# The paper's contact case (section 5.3, Fig. 14): the spheres touch for -1.39 <~ r_x/a1 <~ 0
PAPER_CONTACT_WINDOW = (-1.39, 0.0)


def validation_rows(results: dict) -> List[Row]:
    """Per trajectory: the minimum gap; without contact the final offset against the initial one (Stokes
    flow is reversible); with contact the window of r_x where the spheres touch against the paper's."""
    rows = []
    for s, t in zip(results["summaries"], results["trajectories"]):
        config = "a2/a1 %g, r_y0 %g a1, %s" % (t.get("ratio", float("nan")), s["r_y_start"],
                                              "contact" if t.get("contact") else "no contact")
        rows.append(Row("minimum gap / a1", config, s["min_gap_over_a1"]))
        if "fore_aft_asymmetry" in s and not t.get("contact"):
            rows.append(Row("final offset r_y", config, s["r_y_end"], s["r_y_start"],
                            "fore-aft symmetric (Fig. 14, top)", relative(s["r_y_end"], s["r_y_start"])))
        if "contact_r_x_from" in s:
            for end, value, paper in (("from", s["contact_r_x_from"], PAPER_CONTACT_WINDOW[0]),
                                      ("to", s["contact_r_x_to"], PAPER_CONTACT_WINDOW[1])):
                touched = value is not None    # None: the spheres never came within h_r
                rows.append(Row("contact window r_x/a1, %s" % end, config, value, paper,
                                "≈ %g (Fig. 14, bottom)" % paper, value - paper if touched else None,
                                error_unit="a1"))
    return rows


def plot(results, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for i, t in enumerate(results["trajectories"]):
        label = "a2/a1 = %g, r_y0 = %g%s" % (t["ratio"], t["r_y0"], ", contact" if t["contact"] else "")
        axes[0].plot(t["r_x"], t["r_y"], "-", color="C%d" % i, label=label)
        axes[1].semilogy(t["r_x"], np.maximum(t["gap_over_a1"], 1e-7), "-", color="C%d" % i, label=label)
        if t["contact"]:
            axes[1].axhline(t["contact"][3], color="C%d" % i, ls=":", lw=1)  # h_r: below it the spheres touch
    axes[0].set_xlabel(r"$r_x/a_1$")
    axes[0].set_ylabel(r"$r_y/a_1$")
    axes[0].legend(fontsize=7)
    axes[1].set_xlabel(r"$r_x/a_1$")
    axes[1].set_ylabel(r"surface gap $/a_1$")
    fig.suptitle("Sphere pair in simple shear flow (paper Fig. 14)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--full", action="store_true")
    p.add_argument("--contact", action="store_true", help="the paper's contact case instead of the smooth one")
    p.add_argument("--r-y0", type=float, nargs="+", default=None, help="initial cross-stream offsets / a1")
    p.add_argument("--a-over-delta", type=float, default=3.0)
    p.add_argument("--size", type=float, nargs=3, default=[12.0, 8.0, 6.0], help="Lx H Lz in units of a1")
    p.add_argument("--dt", type=float, default=0.05, help="time step in units of 1/shear rate")
    case.add_run_options(p, HERE, tol_lambda=0.001, cutoff=True)
    p.add_argument("--kn", type=float, default=2e4, help="normal contact stiffness [N/m] of the --contact case")
    p.add_argument("--kt", type=float, default=200.0, help="tangential contact stiffness [N/m] of the --contact case")
    p.add_argument("--r-x0", type=float, default=None,
                   help="initial r_x / a1 (default: -3.48 with contact, the paper's Fig. 15; without, -6 or less in a short box)")
    p.add_argument("--integrator", choices=("ab2", "euler"), default="ab2", help="fix fdm/couple integrator")
    p.add_argument("--gap-update", choices=("log", "none"), default="log", help="fix fdm/couple gap_update")
    p.add_argument("--fluid-every", type=int, default=1, metavar="K",
                   help="solve the fluid every K-th particle step only (fix fdm/couple fluid_every, docs/dem.md)")
    p.add_argument("--held-drag", choices=suspension.HELD_DRAG, default=suspension.HELD_DRAG[0],
                   help="with --fluid-every: how the steps between fluid steps hold its force (fix fdm/couple held_drag)")
    args = p.parse_args(argv)
    if args.fluid_every < 1:
        p.error("--fluid-every must be at least 1, got %d" % args.fluid_every)

    a1 = 1.0
    contact = paper_contact(a1, args.kn, args.kt)
    contact_r_x0 = PAPER_CONTACT_R_X0 if args.r_x0 is None else args.r_x0
    jobs = []
    if args.full:
        args.a_over_delta, args.size = 5.0, [20.0, 12.0, 8.0]
        for ry in (args.r_y0 or [0.25, 0.5, 1.0]):
            jobs.append((1.0, ry, None))
        jobs.append((PAPER_CONTACT_RATIO, PAPER_CONTACT_R_Y0, contact))
    elif args.contact:
        jobs.append((PAPER_CONTACT_RATIO, (args.r_y0 or [PAPER_CONTACT_R_Y0])[0], contact))
    else:
        for ry in (args.r_y0 or [0.5]):
            jobs.append((1.0, ry, None))

    os.makedirs(args.workdir, exist_ok=True)
    t0 = time.time()
    results = dict(case="pairShear", trajectories=[], summaries=[])
    for ratio, ry, cont in jobs:
        t = run_trajectory(args.workdir, ratio, ry, cont, args.a_over_delta, tuple(args.size), args.dt,
                           tol_lambda=args.tol_lambda, cutoff=args.cutoff, np_fluid=args.np_fluid, keep=args.keep,
                           gap_update=args.gap_update, integrator=args.integrator,
                           r_x0=contact_r_x0 if cont else args.r_x0, acceleration=args.acceleration, model=args.model,
                           fluid_every=args.fluid_every, held_drag=args.held_drag)
        s = summarise(t, cont[3] / a1 if cont else None)
        s.update(ratio=ratio, r_y0=ry, contact=bool(cont), wall_seconds=t["wall_seconds"], steps=t["steps"],
                 inner_iterations_mean=t["inner_iterations_mean"], unconverged_steps=t["unconverged_steps"],
                 fluid_every=t["fluid_every"], held_drag=t["held_drag"],
                 fluid_solves_per_step=t["fluid_solves_per_step"], dt=args.dt, integrator=args.integrator, gap_update=args.gap_update)
        results["trajectories"].append(t)
        results["summaries"].append(s)
        print(json.dumps(s))
    write_results(args.out, __file__, argv, args, validation_rows, results, t0)
    plot(results, os.path.join(os.path.dirname(args.out), "results_pairShear.png"))
    print("wrote %s (%.0f s)" % (args.out, results["wall_seconds"]))
    return results


if __name__ == "__main__":
    main()
