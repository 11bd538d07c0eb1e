"""The command-line options the case scripts share (argparse helpers): the run options of every coupled
case, and the boxes and cell offsets of the cases that scan positions of a sphere in a mesh cell."""
from __future__ import annotations

import os

def boxes_and_offsets(parser, args, default_boxes, cell_offsets):
    """The box and cell-offset options two cases share (--size, --boxes [LX LY LZ ...], --offset ...,
    --positions N): returns (boxes, offsets, positions represented); a bad value is a parser error naming it.
    cell_offsets(N) gives a case's own offsets for N positions (ValueError if N is not allowed)."""
    if args.boxes is None:
        boxes = [tuple(args.size)]
    elif not args.boxes:
        boxes = list(default_boxes)
    else:
        if len(args.boxes) % 3 or len(args.boxes) < 6:
            parser.error("--boxes takes LX LY LZ per box, for two boxes or more (got %d numbers)" % len(args.boxes))
        boxes = [tuple(args.boxes[k:k + 3]) for k in range(0, len(args.boxes), 3)]
    if args.offset:
        for offset in args.offset:
            if not all(0.0 <= o < 1.0 for o in offset):
                parser.error("--offset %s: each offset must be in [0, 1) cells" % " ".join("%g" % o for o in offset))
        return boxes, [tuple(o) for o in args.offset], len(args.offset)
    try:
        offsets, represented = cell_offsets(args.positions)
    except ValueError as e:
        parser.error(str(e))
    return boxes, offsets, represented



def add_run_options(parser, case_dir, tol_lambda, cutoff=False, model=False):
    """The options every coupled case's script shares: --tol-lambda, --acceleration, --np-fluid,
    --workdir, --out, --keep; with cutoff, --cutoff and --model (pair_style fdm/subgrid's cut-off and
    sub-grid model; model=True gives --model alone)."""
    if cutoff:
        parser.add_argument("--cutoff", type=float, default=None,
                            help="pair_style fdm/subgrid cutoff (mesh cells; default: the pair style's)")
    if cutoff or model:
        parser.add_argument("--model", choices=("calibrated", "cutoff"), default="calibrated",
                            help="pair_style fdm/subgrid model: the calibration of what the solver resolves "
                                 "(the default; a1/Delta 3-5, a2/a1 1 and 1.4) or the cut-off model (docs/dem.md)")
    parser.add_argument("--tol-lambda", type=float, default=tol_lambda, help="fdmFoam's innerIterations tolLambda")
    parser.add_argument("--acceleration", choices=("anderson", "none"), default="anderson",
                        help="fdmFoam's inner-iteration acceleration (none: the plain iteration of paper 4.3)")
    parser.add_argument("--np-fluid", type=int, default=1, help="MPI ranks of fdmFoam")
    parser.add_argument("--workdir", default=os.path.join(case_dir, "runs"), help="where the runs are written")
    parser.add_argument("--out", default=os.path.join(case_dir, "results.json"))
    parser.add_argument("--keep", action="store_true", help="keep the meshes and the fields of the runs")


def add_size_options(parser) -> None:
    """The size-distribution options of the suspension cases (couette, poiseuille): --radii with
    --volume-fractions, or --distribution lognormal MEDIAN SIGMA N; size_distribution() reads them."""
    parser.add_argument("--radii", type=float, nargs="+", default=None, metavar="A",
                        help="the radii of the species in units of a1 (default 1 1.4, the paper's), each a LIGGGHTS "
                             "atom type (1 the smallest); the mesh is --a-over-delta cells per a1, and the smallest "
                             "radius must get at least 2 cells")
    parser.add_argument("--volume-fractions", type=float, nargs="+", default=None, metavar="F",
                        help="with --radii: each species' share of the particle volume (phi_k/phi_bulk), summing to "
                             "1 (default: equal volumes)")
    parser.add_argument("--distribution", nargs=4, default=None, metavar=("lognormal", "MEDIAN", "SIGMA", "N"),
                        help="instead of --radii: a log-normal number distribution of radii (median MEDIAN a1, "
                             "SIGMA the standard deviation of ln a) in N species (fdmsubgrid.packing."
                             "SizeDistribution.lognormal)")


def size_distribution(parser, args):
    """The packing.SizeDistribution of add_size_options' options (the paper's by default); a bad value is a parser
    error naming it. Sets args.radii and args.volume_fractions to the distribution's, so that the results file's
    scene records what was packed."""
    from . import packing
    try:
        if args.distribution is not None:
            if args.radii is not None or args.volume_fractions is not None:
                parser.error("--distribution replaces --radii and --volume-fractions: give one or the other")
            kind, *values = args.distribution
            if kind != "lognormal":
                parser.error("--distribution %s: the named distribution is lognormal MEDIAN SIGMA N" % kind)
            try:
                median, sigma, n = float(values[0]), float(values[1]), float(values[2])
            except ValueError:
                parser.error("--distribution lognormal %s: MEDIAN, SIGMA and N must be numbers" % " ".join(values))
            sizes = packing.SizeDistribution.lognormal(median, sigma, n)
        elif args.radii is not None:
            sizes = packing.SizeDistribution.of(args.radii, args.volume_fractions)
        elif args.volume_fractions is not None:
            sizes = packing.SizeDistribution.of(packing.PAPER_SUSPENSION.radii, args.volume_fractions)
        else:
            sizes = packing.PAPER_SUSPENSION
    except packing.SizeDistributionError as e:
        parser.error(str(e))
    args.radii, args.volume_fractions = list(sizes.radii), list(sizes.volume_fractions)
    return sizes
