#!/usr/bin/env python3
"""Choosing the contact parameters of pair_style fdm/subgrid (k_n, k_t, mu_s, h_r) and the time step:
DEM-only scenes run with fdmDEM and fix fdm/couple transport none (docs/contact.md); the scenes and
their runners are fdmsubgrid.contactscenes, this script runs the sweeps and reports them.

Units SI at the 1 m scale: sphere radius a = 1 m, viscosity eta = 1 Pa s, mesh size Delta = 0.2 m
(a/Delta = 5), h_r = 0.01 m, loads of 10 N, k_n = k_t = 2000 N/m (F/k_n = h_r/2). Every scene is a
LIGGGHTS input in this folder (in.normal, in.wall, in.sliding) that runs by hand as well:
`fdmDEM -in in.normal -var kn 4000`. This script runs the sweeps:

  normal    two spheres pressed together (in.normal) and a sphere pressed on a wall (in.wall) for
            several k_n: steady gap against h_r - F/k_n, equal and opposite contact forces, the time
            to reach the steady gap against the same overdamped equation integrated here with the
            resistance functions of fdmResistance (zeta(gap), the pair's normal resistance)
  sliding   a sphere squeezed between two walls (Fn per contact) and pulled along them (Ft per
            contact, in.sliding): sticks below mu_s Fn with the spring displacement Ft/k_t, slides
            above with the tangential force mu_s Fn; the threshold by bisection; a sphere pulled on
            one wall rolls (in.wall, Ft): the stuck contact carries 4/7 Ft without lubrication
  stability the explicit contact with the implicit (overdamped) velocity solve: per step the gap error
            is multiplied by 1 - r (position update euler) or by the largest root of
            l^2 - (1 - 3r/2) l - r/2 = 0 (ab2, the fix's default), r = dt k_n / zeta at the steady gap;
            the limit dt (bisection) against the estimate 2 zeta/k (euler) or zeta/k (ab2), for the
            normal spring (k_n) of the pair with and without lubrication and of the wall, and for the
            tangential spring (k_t; 2 k_t for a sphere between two walls), whose history follows the
            displacement of the step and so has the same limit

  contactTuning.py            the small sweeps (about a minute on 2 cores)
  contactTuning.py --full     wider sweeps (k_n, h_r, loads through overlap, both integrators, dt grids)
  contactTuning.py --help     every option
Writes results.json and results_contactTuning.png here; run folders go to runs/.
"""
import argparse
import os
import time
from typing import List

import numpy as np

from fdmsubgrid import contactstability as cs
# the scenes and their runners (the names the tests use too)
from fdmsubgrid.contactscenes import (BASE, LOAD, StabilityConfig, implicit_convergence,  # noqa: F401
                                      implicit_equilibrium, implicit_stability, implicit_study, normal_run,
                                      normal_sweep, probe_cutoffs, rolling_runs, run_scene, sliding_run,
                                      sliding_sweep, stability_study, use_inputs)
from fdmsubgrid.results import Row, relative, write_results

HERE = os.path.dirname(os.path.abspath(__file__))
# the scenes' LIGGGHTS inputs are this folder's in.normal, in.wall, in.sliding
use_inputs(HERE)

# ---------------------------------------------------------------------------------------------
# the figure
# ---------------------------------------------------------------------------------------------

def plot(results, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(2, 2, figsize=(12, 9))

    a = ax[0, 0]
    for i, r in enumerate(x for x in results["normal"]["runs"] if x["ok"] and x["lubrication"] and x["hr"] == BASE["hr"]):
        colour = "C%d" % (i % 10)
        h = r["history"]
        a.plot(h["t"], np.array(h["gap"]) / r["hr"], color=colour, ls="-" if r["geometry"] == "pair" else "--",
               label="%s, k_n = %.0f N/m" % (r["geometry"], r["kn"]))
        a.axhline(r["gap_theory"] / r["hr"], color=colour, lw=0.5)
    a.axhline(1.0, color="k", lw=0.8)
    a.set_xscale("log")
    a.set_ylim(-0.2, 3)
    a.set_xlabel("t [s]")
    a.set_ylabel("gap / h_r")
    a.set_title("(a) gap under F = %g N (lines: h_r - F/k_n)" % LOAD)
    a.legend(fontsize=7)

    a = ax[0, 1]
    s = results["sliding"]
    runs = [r for r in s["runs"] if r["ok"]]
    q = np.array([r["ratio"] for r in runs])
    a.plot(q, [r["ft_over_muFn"] for r in runs], "o", label="tangential contact force / (mu_s F_n)")
    a.plot(q, [r["displacement"] / (r["mu"] * r["Fn"] / r["kt"]) for r in runs], "s", mfc="none",
           label="sphere displacement / (mu_s F_n / k_t) (end of run)")
    qq = np.linspace(0, max(q.max(), 1.5), 100)
    a.plot(qq, np.minimum(qq, 1.0), "k-", lw=0.8, label="min(F_t, mu_s F_n) / (mu_s F_n)")
    a.set_ylim(0, 2)
    a.set_xlabel("F_t / (mu_s F_n)")
    a.set_ylabel("ratio")
    a2 = a.twinx()
    a2.plot(q, [r["U_end"] for r in runs], "^", color="C3", label="sliding speed [m/s]")
    a2.set_ylabel("U at the end [m/s]", color="C3")
    title = "(b) sphere between two walls, pulled"
    if s["threshold"]:
        title += ": slides above %.4f mu_s F_n" % s["threshold"]["ratio"]
    a.set_title(title)
    a.legend(fontsize=7, loc="upper left")

    a = ax[1, 0]
    grid = results["stability"]["grid"]
    for integrator, marker in (("ab2", "o"), ("euler", "s")):
        pts = [g for g in grid if g["integrator"] == integrator and g.get("config") is None and g["ok"]
               and g["factor_measured"] is not None]
        a.plot([g["r"] for g in pts], [g["factor_measured"] for g in pts], marker, mfc="none",
               label="measured, %s" % integrator)
        rr = np.linspace(0.01, max(g["r"] for g in grid) * 1.05, 300)
        a.plot(rr, [cs.explicit_growth_factor(x, integrator) for x in rr], "-", lw=0.8, label="theory, %s" % integrator)
    a.axhline(1.0, color="k", lw=0.8)
    a.set_xlabel("r = dt k_n / zeta (zeta at the steady gap)")
    a.set_ylabel("|growth factor of the gap error per step|")
    a.set_ylim(0, 3)
    a.set_title("(c) pair with lubrication, perturbed steady contact")
    a.legend(fontsize=7)

    a = ax[1, 1]
    limits = results["stability"]["limits"]
    labels = ["%s\n%s" % (l["name"].replace(", ", ",\n", 1), l["integrator"]) for l in limits]
    x = np.arange(len(limits))
    a.bar(x - 0.2, [l["dt_measured"] for l in limits], 0.4, label="measured (bisection)")
    a.bar(x + 0.2, [l["dt_estimate"] for l in limits], 0.4, label="estimate 2 zeta/k (euler), zeta/k (ab2)")
    a.set_yscale("log")
    a.set_xticks(x)
    a.set_xticklabels(labels, fontsize=6, rotation=90)
    a.set_ylabel("largest stable dt [s]")
    a.set_title("(c) stability limit of the time step")
    a.legend(fontsize=7)
    fig.suptitle("contactTuning: a = 1 m, eta = 1 Pa s, Delta = 0.2 m, h_r = %g m, mu_s = %g, F = %g N"
                 % (BASE["hr"], BASE["mu"], LOAD))
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ---------------------------------------------------------------------------------------------

def summarise(results):
    """The named figures of results.json."""
    n = [r for r in results["normal"]["runs"] if r["ok"]]
    s = results["sliding"]
    sl = [r for r in s["runs"] if r["ok"]]
    lim = {("%s, %s" % (l["name"], l["integrator"])): l for l in results["stability"]["limits"]}
    default = lim.get("pair, lubrication, ab2")
    euler = lim.get("pair, lubrication, euler")
    rolling = [r for r in results["rolling"] if r["ok"] and not r["lubrication"]]
    stuck_euler = [r for r in sl + s["extra"] if r["ok"] and r.get("stuck") and r["integrator"] == "euler"]
    stuck_ab2 = [r for r in sl + s["extra"] if r["ok"] and r.get("stuck") and r["integrator"] == "ab2"]
    return dict(
        normal_gap_error=max(abs(r["gap_error"]) for r in n),
        normal_force_error=max(abs(r["normal_force_error"]) for r in n),
        normal_force_balance=max(r["force_balance"] for r in n if r["force_balance"] is not None),
        normal_history_vs_prediction=max(r.get("history_vs_prediction", 0.0) for r in n),
        sliding_threshold_ratio=s["threshold"]["ratio"] if s["threshold"] else None,
        sliding_force_ratio=max((abs(r["ft_over_muFn"] - 1) for r in sl if not r["stuck"]), default=None),
        sliding_speed_error=max((abs(r["sliding_speed_error"]) for r in sl if not r["stuck"]), default=None),
        stick_force_error=max((abs(r["ft_over_Ft"] - 1) for r in sl if r["stuck"]), default=None),
        stick_displacement_ratio_euler=[r["displacement_over_spring"] for r in stuck_euler],
        stick_displacement_ratio_ab2=[r["displacement_over_spring"] for r in stuck_ab2],
        rolling_force_ratio=rolling[0]["ft_over_Ft"] if rolling else None,
        stability_limit_dt=default["dt_measured"] if default else None,
        stability_limit_dt_estimate=default["dt_estimate"] if default else None,
        stability_limit_ratio=default["measured_over_estimate"] if default else None,
        stability_limit_dt_euler=euler["dt_measured"] if euler else None,
        stability_limit_dt_estimate_euler=euler["dt_estimate"] if euler else None,
        stability_limits={k: dict(dt_measured=v["dt_measured"], dt_estimate=v["dt_estimate"],
                                  ratio=v["measured_over_estimate"], zeta=v["zeta"], r_measured=v["r_measured"])
                          for k, v in lim.items()},
    )


def print_report(results):
    f = results["figures"]
    print("(a) normal contact under F = %g N (gap error relative to F/k_n):" % LOAD)
    print("  %-5s %-4s %9s %7s %10s %10s %9s %9s %9s %9s %9s" % ("geom", "lub", "k_n", "h_r", "gap theory", "gap end",
                                                                  "error", "tau [s]", "t_contact", "t_settle",
                                                                  "predicted"))
    for r in results["normal"]["runs"]:
        if not r["ok"]:
            print("  %s k_n %g: run failed" % (r["geometry"], r["kn"]))
            continue
        print("  %-5s %-4s %9.1f %7.4f %10.4g %10.4g %9.1e %9.3g %9.3g %9s %9s" % (
            r["geometry"], "yes" if r["lubrication"] else "no", r["kn"], r["hr"], r["gap_theory"], r["gap_end"],
            r["gap_error"], r["tau_steady"], r["t_contact"] or float("nan"),
            "%.3g" % r["t_settle"] if r["t_settle"] is not None else "-",
            "%.3g" % r["t_settle_predicted"] if r.get("t_settle_predicted") is not None else "-"))
    print("  largest |F1 + F2|/F = %.2e; gap history against the prediction: %.2e F/k_n"
          % (f["normal_force_balance"], f["normal_history_vs_prediction"]))
    print("(b) sphere between two walls, F_n = %g N per contact, mu_s = %g:" % (LOAD, BASE["mu"]))
    for r in results["sliding"]["runs"] + results["sliding"]["extra"]:
        if not r["ok"]:
            print("  Ft/(mu Fn) %g: run failed" % r["ratio"])
            continue
        if r["stuck"]:
            print("  Ft/(mu Fn) %-5g %-5s lub %-3s stuck:   ft/Ft %.9f, displacement / (Ft/k_t) %.6f" % (
                r["ratio"], r["integrator"], "yes" if r["lubrication"] else "no", r["ft_over_Ft"],
                r["displacement_over_spring"]))
        else:
            print("  Ft/(mu Fn) %-5g %-5s lub %-3s sliding: ft/(mu Fn) %.9f, U %.5g m/s (theory %.5g)" % (
                r["ratio"], r["integrator"], "yes" if r["lubrication"] else "no", r["ft_over_muFn"], r["U_end"],
                r["sliding_speed_theory"]))
    if results["sliding"]["threshold"]:
        t = results["sliding"]["threshold"]
        print("  threshold: Ft/(mu_s Fn) = %.5f (bracket %.5f .. %.5f)" % (t["ratio"], t["bracket"][0], t["bracket"][1]))
    for r in results["rolling"]:
        if r["ok"]:
            print("  one wall, pulled at the centre (rolls), lubrication %s: ft/Ft = %.6f (4/7 = %.6f without "
                  "lubrication), slip/U %.1e" % ("yes" if r["lubrication"] else "no", r["ft_over_Ft"], cs.ROLLING_CONTACT_FRACTION,
                                                 r["slip_over_U"]))
    print("(c) stability limit of dt (bisection to %g %%):" % (100 * results["stability"]["bisection_tolerance"]))
    print("  %-42s %-5s %10s %12s %12s %8s %8s" % ("scene", "integ", "zeta", "dt measured", "dt estimate", "ratio",
                                                   "r meas."))
    for l in results["stability"]["limits"]:
        print("  %-42s %-5s %10.4g %12.5g %12.5g %8.4f %8.4f" % (l["name"], l["integrator"], l["zeta"],
                                                                 l["dt_measured"], l["dt_estimate"],
                                                                 l["measured_over_estimate"], l["r_measured"]))
    print("  pair with lubrication, dt grid (r = dt k_n / zeta):")
    for g in results["stability"]["grid"]:
        if g.get("config"):
            continue
        print("    %-5s r %5.2f: growth factor %s (theory %.3f), %s, gap %.4g .. %.4g" % (
            g["integrator"], g["r"], "%.3f" % g["factor_measured"] if g.get("factor_measured") is not None else "-",
            g["factor_theory"], g["label"], g.get("min_gap", float("nan")), g.get("max_gap", float("nan"))))


def validation_rows(results: dict) -> List[Row]:
    """The named figures (summarise) as rows of fdmsubgrid.results: the stability limits of the time step
    against their estimates (docs/contact.md), and the largest relative errors of the sweeps against the
    contact model's own prediction. None without the three parts (--only)."""
    figures = results.get("figures")
    if not figures:
        return []
    rows = []
    for name, limit in figures["stability_limits"].items():
        if limit["dt_measured"] is not None:
            rows.append(Row("stability limit Δt", name, limit["dt_measured"], limit["dt_estimate"],
                            error=relative(limit["dt_measured"], limit["dt_estimate"])))
    for key, quantity in (("normal_gap_error", "normal load: gap error / (F/k_n) (largest)"),
                          ("normal_force_balance", "normal load: |F1 + F2|/F (largest)"),
                          ("sliding_force_ratio", "sliding: |F_t/(μ F_n) − 1| (largest)"),
                          ("sliding_speed_error", "sliding: speed against the prediction (largest)"),
                          ("stick_force_error", "sticking: |F_t/F − 1| (largest)")):
        if figures.get(key) is not None:
            rows.append(Row(quantity, "integrator %s" % results["integrator"], figures[key]))
    return rows


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--full", action="store_true", help="wider sweeps")
    p.add_argument("--integrator", choices=("ab2", "euler"), default="ab2",
                   help="position update of fix fdm/couple for the normal and sliding sweeps (the stability "
                        "study runs both)")
    p.add_argument("--jobs", type=int, default=2, help="fdmDEM runs at once")
    p.add_argument("--only", nargs="+", choices=("normal", "sliding", "stability", "implicit"), default=None,
                   help="parts to run (default: normal sliding stability; implicit: the implicit springs, "
                        "docs/contact.md 3c, written to results_implicit.json unless --out)")
    p.add_argument("--workdir", default=os.path.join(HERE, "runs"))
    p.add_argument("--out", default=None)
    args = p.parse_args(argv)
    parts = args.only or ["normal", "sliding", "stability"]
    if args.out is None:
        args.out = os.path.join(HERE, "results_implicit.json" if parts == ["implicit"] else "results.json")

    os.makedirs(args.workdir, exist_ok=True)
    t0 = time.time()
    cutoff, wall_cutoff = probe_cutoffs(args.workdir)
    res = cs.ContactResistances(BASE["a"], BASE["eta"], BASE["delta"], cutoff, wall_cutoff)
    results = dict(case="contactTuning", full=args.full, units="SI, a = 1 m, eta = 1 Pa s",
                   parameters=dict(BASE, load=LOAD, cutoff_cells=cutoff, wall_cutoff_cells=wall_cutoff),
                   integrator=args.integrator)
    if "normal" in parts:
        t = time.time()
        results["normal"] = dict(runs=normal_sweep(res, args.workdir, args.full, args.jobs, args.integrator))
        results["normal"]["seconds"] = time.time() - t
    if "sliding" in parts:
        t = time.time()
        results["sliding"] = sliding_sweep(res, args.workdir, args.full, args.jobs, args.integrator)
        results["rolling"] = rolling_runs(res, args.workdir, args.jobs, args.integrator)
        results["sliding"]["seconds"] = time.time() - t
    if "stability" in parts:
        t = time.time()
        results["stability"] = stability_study(res, args.workdir, args.full, args.jobs)
        results["stability"]["seconds"] = time.time() - t
    if "implicit" in parts:
        results["implicit"] = implicit_study(res, args.workdir, args.jobs)
    if len(parts) == 3 and "implicit" not in parts:
        results["figures"] = summarise(results)
    write_results(args.out, __file__, argv, args, validation_rows, results, t0)
    if len(parts) == 3 and "implicit" not in parts:
        print_report(results)
        plot(results, os.path.join(os.path.dirname(os.path.abspath(args.out)), "results_contactTuning.png"))
    print("wrote %s (%.0f s)" % (args.out, results["wall_seconds"]))
    return results


if __name__ == "__main__":
    main()
