"""Argument types and input files of the command line (:mod:`bladecase.cli`): each refuses a bad value
with one line naming it and what is valid.

>>> _periods("1:12:3").tolist()
[1.0, 6.5, 12.0]
>>> _ipp("50")
Traceback (most recent call last):
    ...
argparse.ArgumentTypeError: impacts per period must be an integer with 1 <= K <= 8, got 50
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import numpy as np


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
    if count > MAX_PERIODS:
        raise argparse.ArgumentTypeError(f"COUNT must be <= {MAX_PERIODS} (each period is a solve), got {count}")
    return np.linspace(start, stop, count)


#: Largest COUNT of ``--periods START:STOP:COUNT`` (each scanned period is a solve).
MAX_PERIODS = 100_000
#: Largest ``--ipp`` (as the study's ``[search] ipp``: the k-ipp start search grows combinatorially with k).
MAX_IPP = 8


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {value}")
    return value


def _ipp(text: str) -> int:
    value = _positive_int(text)
    if value > MAX_IPP:
        raise argparse.ArgumentTypeError(f"impacts per period must be an integer with 1 <= K <= {MAX_IPP}, got {value}")
    return value


def load_system(args):
    """The system of ``backbone``/``modes``: ``--chain N`` or ``--matrices FILE.npz`` (fields checked)."""
    from .io import npz_scalar, read_npz
    from .nsm import LinearSystem, chain

    if (args.chain is None) == (args.matrices is None):
        raise ValueError("give exactly one of --chain N or --matrices FILE.npz")
    if args.chain is not None:
        from .nsm.system import MAX_CHAIN, dense_cost

        if args.chain > MAX_CHAIN:
            raise ValueError(f"--chain N must be <= {MAX_CHAIN}, got {args.chain}: {dense_cost(args.chain, 'N')}")
        if args.gap is None:
            raise ValueError("--gap D is required with --chain")
        return chain(args.chain, k=args.k, m=args.m, gap=args.gap)
    source = str(args.matrices)
    data = read_npz(args.matrices, "matrices file", names="M, K, w, gap")
    missing = [key for key in ("M", "K", "w") if key not in data]
    if missing:
        raise ValueError(f"{source} lacks array(s) {', '.join(missing)} (needs M, K, w and gap)")
    gap = args.gap if args.gap is not None else (npz_scalar(data, "gap", source) if "gap" in data else None)
    if gap is None:
        raise ValueError(f"{source} has no 'gap' and --gap was not given")
    w = data["w"]
    if w.dtype.kind not in "fiu":
        raise ValueError(f"{source}: field 'w' must hold numbers (a vector, or an integer contact dof), "
                         f"got dtype {w.dtype}")
    if w.ndim == 0:
        if not float(w).is_integer():
            raise ValueError(f"{source}: a single 'w' is the index of the contact dof and must be an integer, "
                             f"got {w.item()!r} (or give w as a vector of n numbers)")
        w = int(w)
    try:
        return LinearSystem(data["M"], data["K"], w, gap)
    except ValueError as exc:
        raise ValueError(f"{source}: {exc}") from None


def check_outputs(*paths) -> None:
    """Refuse up front (before any computation) output files that cannot be written."""
    from .io import check_output_file

    for path in paths:
        if path is not None:
            check_output_file(path)


def out_dir(text: str) -> Path:
    """``--out DIR``: a folder name (an empty one would mean the working folder)."""
    if not text.strip():
        raise argparse.ArgumentTypeError(f"expected a folder, got an empty name {text!r} (it would mean the working "
                                         "folder; give e.g. results/NAME)")
    return Path(text)


def not_onto_inputs(outputs: dict[str, Path | None], inputs: dict[str, Path | None]) -> None:
    """Refuse (before any work) an output file that is one of the command's inputs, or two outputs in one file."""
    seen: dict[str, str] = {}
    for label, path in inputs.items():
        if path is not None and os.path.lexists(path):
            seen[os.path.realpath(path)] = f"its input {label} {str(path)!r}"
    for label, path in outputs.items():
        if path is None:
            continue
        real = os.path.realpath(path)
        if real in seen:
            raise ValueError(f"{label} {str(path)!r} is {seen[real]}: it would be overwritten; write to another file")
        seen[real] = f"also given as {label}"
