"""The ``bladecase`` command line (a thin layer over the Python API)."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path
from typing import Sequence

import numpy as np


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line: ``bladecase …: error: reason``."""

    def error(self, message: str) -> None:  # noqa: D401 - argparse API
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def _floats(text: str) -> float | list[float]:
    """A positive number or a comma-separated list of them."""
    try:
        values = [float(x) for x in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number or comma-separated numbers, got {text!r}") from None
    return values[0] if len(values) == 1 else values


def _periods(text: str) -> np.ndarray:
    """``START:STOP:COUNT`` → ``linspace(START, STOP, COUNT)``."""
    parts = text.split(":")
    if len(parts) != 3:
        raise argparse.ArgumentTypeError(f"expected START:STOP:COUNT, got {text!r}")
    try:
        start, stop, count = float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected START:STOP:COUNT with COUNT an integer, got {text!r}") from None
    if not (np.isfinite(start) and np.isfinite(stop)) or start <= 0 or stop < start:
        raise argparse.ArgumentTypeError(f"need 0 < START <= STOP, got START={start:g}, STOP={stop:g}")
    if count < 1:
        raise argparse.ArgumentTypeError(f"COUNT must be >= 1, got {count}")
    return np.linspace(start, stop, count)


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {value}")
    return value


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="bladecase",
        description=(
            "Nonsmooth modal analysis of blade–casing contact: periodic orbits with impacts of a "
            "linear structure against a unilateral obstacle, their admissibility, and their "
            "frequency–energy backbones."
        ),
        epilog="Run 'bladecase COMMAND --help' for the options of a command.",
    )
    from . import __version__

    parser.add_argument("--version", action="version", version=f"bladecase {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    bb = sub.add_parser(
        "backbone",
        help="orbits with k impacts per period over a period scan, and their admissible intervals",
        description=(
            "Compute the periodic orbits with IPP impacts per period at every period of a scan, "
            "certify their admissibility (wᵀx <= d over the whole period, impulses >= 0), refine "
            "the admissible intervals of T by bisection, and print a table (T, 1/T, energy, "
            "impulses, admissible) followed by the intervals."
        ),
    )
    src = bb.add_argument_group("system (one of)")
    src.add_argument("--chain", type=_positive_int, metavar="N",
                     help="spring–mass chain of N masses, wall at one end, obstacle after the last mass")
    src.add_argument("--matrices", type=Path, metavar="FILE.npz",
                     help="user system: an .npz with arrays M, K (n×n), w (n,) or an integer contact dof, gap")
    bb.add_argument("--k", type=_floats, default=1.0, metavar="K",
                    help="chain spring stiffness(es): a number or N comma-separated numbers (default 1)")
    bb.add_argument("--m", type=_floats, default=1.0, metavar="M",
                    help="chain mass(es): a number or N comma-separated numbers (default 1)")
    bb.add_argument("--gap", type=float, metavar="D",
                    help="clearance d > 0 (required with --chain; overrides the file's gap with --matrices)")
    bb.add_argument("--periods", type=_periods, required=True, metavar="START:STOP:COUNT",
                    help="scan COUNT periods evenly from START to STOP (inclusive)")
    bb.add_argument("--ipp", type=_positive_int, default=1, metavar="K",
                    help="impacts per period (default 1).  K >= 2: the K-ipp families (nonsmooth modes) "
                         "are searched at the COUNT scan periods and followed by continuation over "
                         "[START, STOP]; a table per family is printed")
    bb.add_argument("--json", type=Path, metavar="FILE", help="write the scan and intervals as JSON")
    bb.add_argument("--plot", type=Path, metavar="FILE.png", help="write the frequency–energy plot")
    bb.add_argument("--table", type=Path, metavar="FILE", help="also write the printed table to FILE")
    bb.add_argument("--quiet", action="store_true", help="print only the admissible intervals")
    bb.add_argument("--no-progress", action="store_true", help="no progress bar")
    bb.set_defaults(func=_cmd_backbone)
    return parser


def _load_system(args):
    from .model import LinearSystem, chain

    if (args.chain is None) == (args.matrices is None):
        raise ValueError("give exactly one of --chain N or --matrices FILE.npz")
    if args.chain is not None:
        if args.gap is None:
            raise ValueError("--gap D is required with --chain")
        return chain(args.chain, k=args.k, m=args.m, gap=args.gap)
    try:
        data = np.load(args.matrices, allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise ValueError(f"cannot read {args.matrices}: {exc}") from None
    missing = [key for key in ("M", "K", "w") if key not in data]
    if missing:
        raise ValueError(f"{args.matrices} lacks array(s) {', '.join(missing)} (needs M, K, w and gap)")
    gap = args.gap if args.gap is not None else (float(data["gap"]) if "gap" in data else None)
    if gap is None:
        raise ValueError(f"{args.matrices} has no 'gap' and --gap was not given")
    w = data["w"]
    w = int(w) if w.ndim == 0 else w
    return LinearSystem(data["M"], data["K"], w, gap)


def _cmd_backbone(args) -> int:
    from .io import save_figure, write_json, write_text
    from .scan import backbone

    system = _load_system(args)
    progress = not args.no_progress and sys.stderr.isatty()
    if args.ipp == 1:
        result = backbone(system, args.periods, ipp=1, progress=progress)
        curves = [result]
        table = result.table()
        summary = table.split("\n\n", 1)[-1]
        data = result.to_dict()
    else:
        from .continuation import nonsmooth_mode

        P = args.periods
        if P.size < 2 or P[0] == P[-1]:
            raise ValueError("--ipp K >= 2 needs a period range: START < STOP and COUNT >= 2")
        curves = nonsmooth_mode(system, args.ipp, (P[0], P[-1]), scan=P.size, progress=progress)
        if curves:
            summary = "\n".join(f.table() for f in curves)
        else:
            summary = f"no {args.ipp}-ipp family found in T in [{P[0]:g}, {P[-1]:g}]"
        table = summary if args.quiet else "\n\n".join(_family_table(f) for f in curves) + "\n\n" + summary
        data = {
            "ipp": args.ipp,
            "system": {"n": system.n, "gap": system.gap},
            "T_range": [float(P[0]), float(P[-1])],
            "families": [f.to_dict() for f in curves],
        }
    print(summary if args.quiet else table)
    if args.table:
        write_text(args.table, table + "\n")
    if args.json:
        write_json(args.json, data)
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        from .plot import frequency_energy

        if not curves:
            raise ValueError("nothing to plot: no family found")
        fig = frequency_energy(curves)
        save_figure(fig, args.plot, dpi=150)
        plt.close(fig)
    for label, path in (("table", args.table), ("json", args.json), ("plot", args.plot)):
        if path:
            print(f"wrote {label}: {path}", file=sys.stderr)
    return 0


def _family_table(family) -> str:
    """Per-orbit table of one k-ipp family (in continuation order)."""
    lines = [family.table().split("\n", 1)[0],
             f"{'T':>14} {'1/T':>12} {'energy':>12} {'impact times':>36} {'impulses':>30} admissible"]
    for o in family.orbits:
        times = " ".join(f"{t:.6g}" for t in o.impact_times)
        imp = " ".join(f"{x:.5g}" for x in o.impulses)
        lines.append(f"{o.T:14.8g} {1 / o.T:12.6g} {o.energy:12.6g} {times:>36} {imp:>30} "
                     f"{'yes' if o.admissible else 'no'}")
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``bladecase`` command; returns the exit code (0 on
    success, 2 on bad arguments or input, with a one-line reason on stderr)."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a bad argument (message already printed)
        return int(exc.code or 0) if not isinstance(exc.code, str) else 2
    if args.command is None:
        parser.print_help()
        return 2
    try:
        return args.func(args)
    except ValueError as exc:
        print(f"bladecase {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into e.g. `head`
        sys.stdout = open(os.devnull, "w")
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
