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
