"""The ``bladecase`` command line (a thin layer over the Python API)."""

from __future__ import annotations

import argparse
import logging
import os
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

from .cli_backbone import cmd_backbone as _cmd_backbone
from .cli_backbone import plot as _plot
from .cli_input import _floats, _ipp, _periods, _positive_int
from .cli_input import check_outputs as _check_outputs
from .cli_input import load_system as _load_system
from .cli_input import not_onto_inputs as _not_onto_inputs
from .cli_input import out_dir as _out_dir


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line: ``bladecase …: error: reason``."""

    def error(self, message: str) -> None:  # noqa: D401 - argparse API
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


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
    bb.add_argument("--ipp", type=_ipp, default=1, metavar="K",
                    help="impacts per period, 1 to 8 (default 1).  K >= 2: the K-ipp families (nonsmooth modes) "
                         "are searched at the COUNT scan periods and followed by continuation over "
                         "[START, STOP]; a table per family is printed")
    bb.add_argument("--json", type=Path, metavar="FILE", help="write the scan and intervals as JSON")
    bb.add_argument("--plot", type=Path, metavar="FILE.png", help="write the frequency–energy plot")
    bb.add_argument("--table", type=Path, metavar="FILE", help="also write the printed table to FILE")
    bb.add_argument("--quiet", action="store_true", help="print only the admissible intervals")
    bb.add_argument("--no-progress", action="store_true", help="no progress bar")
    bb.set_defaults(func=_cmd_backbone)
    _study_commands(sub)
    return parser


# ----------------------------------------------------------------------------- study commands

def _progress_options(p) -> None:
    p.add_argument("--quiet", action="store_true", help="log only warnings and errors")
    p.add_argument("--no-progress", action="store_true", help="no progress bars")


def _execution_options(p) -> None:
    p.add_argument("--executor", choices=("serial", "processes", "dask"),
                   help="where independent tasks run (overrides [execution] executor; see docs/distributed.md)")
    p.add_argument("--workers", type=_positive_int, metavar="N", help="local worker processes")
    p.add_argument("--scheduler", metavar="ADDR", help="an existing Dask scheduler, e.g. tcp://host:8786")


def _run_study(study, args, progress: bool):
    """``run`` with the executor of the command line, else of ``[execution]`` (closed afterwards)."""
    from .study import StudyError, run
    from .study.executor import make_executor

    x = study["execution"]
    if args.workers is not None and not args.scheduler:
        from .study.sections import worker_limit

        cap = worker_limit(study["limits"])
        if args.workers > cap:
            raise StudyError(f"--workers: {args.workers} local worker processes, at most {cap} ([limits] workers, "
                             f"or 8 per core of this machine's {os.cpu_count() or 1}): fewer workers, or raise "
                             "[limits] workers")
    kind = args.executor or (None if args.scheduler or args.workers else x["executor"])
    try:
        executor = make_executor(kind, args.workers or x["workers"], args.scheduler or x["scheduler"])
    except ValueError as exc:
        raise StudyError(f"--executor/--workers/--scheduler: {exc}") from None
    with executor:
        return run(study, out=args.out, progress=progress, executor=executor)


def _study_commands(sub) -> None:
    run = sub.add_parser(
        "run", help="run a study file end to end: mesh, FE model, reduction, nonsmooth modes, animations, VTK",
        description="Run the whole chain of a TOML study file (see docs/study.md) and write summary.json, "
                    "report.md, modes.json, the frequency–energy plot, GIF/MP4 animations and VTK time series "
                    "into the output directory.  Results are staged and moved into place only on success.")
    run.add_argument("study", type=Path, metavar="STUDY.toml")
    run.add_argument("--out", type=_out_dir, metavar="DIR", help="output directory (overrides [output] directory)")
    _progress_options(run)
    _execution_options(run)
    run.set_defaults(func=_cmd_run)

    demo = sub.add_parser(
        "demo", help="run the embedded demo study (a twisted, leaned 3-D Ti-6Al-4V blade, about 10 s)",
        description="Run the embedded demo study: a twisted, leaned NACA 2412 blade of a few thousand dofs, "
                    "Ti-6Al-4V, lumped mass, its tip face 0.1 mm from a compliant casing (1e6 N/m), the massless "
                    "contact model; the nonsmooth mode grown from the first linear mode, checked in a richer "
                    "reference model and animated.  --print-study shows its TOML as a template.")
    demo.add_argument("--out", type=_out_dir, metavar="DIR", help="output directory (default results/demo)")
    demo.add_argument("--print-study", action="store_true", help="print the demo study file and exit")
    _progress_options(demo)
    _execution_options(demo)
    demo.set_defaults(func=_cmd_demo)

    mesh = sub.add_parser("mesh", help="stage 1: mesh the study's blade (gmsh) or convert its mesh file",
                          description="Write the study's mesh: gmsh on [geometry], or the [mesh] file converted. "
                                      "The format follows OUT's suffix (.msh for gmsh meshes, .vtu, .vtk, .inp).")
    mesh.add_argument("study", type=Path, metavar="STUDY.toml")
    mesh.add_argument("-o", "--output", type=Path, required=True, metavar="OUT")
    _progress_options(mesh)
    mesh.set_defaults(func=_cmd_mesh)

    asm = sub.add_parser("assemble", help="stage 2: FE matrices (scikit-fem) of the study's or a given mesh",
                         description="Assemble K and M ([material], [fem]) on the study's mesh or on --mesh FILE "
                                     "(any meshio format with the clamp group), print the first frequencies and "
                                     "write an .npz FE model file.")
    asm.add_argument("study", type=Path, metavar="STUDY.toml")
    asm.add_argument("--mesh", type=Path, metavar="FILE", help="use this mesh instead of the study's")
    asm.add_argument("-o", "--output", type=Path, required=True, metavar="MODEL.npz")
    asm.add_argument("--calculix", type=Path, metavar="DECK.inp",
                     help="also write the model as a CalculiX deck ([fem] frequencies asked for; with [rotation] "
                          "the centrifugal static step at the study's speed first), to check the frequencies with "
                          "ccx")
    asm.add_argument("--calculix-unit", choices=("m", "mm"), default="m",
                     help="units of the deck: m (SI) or mm (N, mm, t, s); default m")
    _progress_options(asm)
    asm.set_defaults(func=_cmd_assemble)

    red = sub.add_parser("reduce", help="stage 3: contact + reduced model of an FE model file",
                         description="Apply [contact] and [reduction] to an FE model file (from 'bladecase "
                                     "assemble') and write the reduced model (.npz).")
    red.add_argument("study", type=Path, metavar="STUDY.toml")
    red.add_argument("--model", type=Path, required=True, metavar="MODEL.npz")
    red.add_argument("--method", help="override [reduction] method")
    red.add_argument("--size", type=_positive_int, help="override [reduction] size")
    red.add_argument("-o", "--output", type=Path, required=True, metavar="REDUCED.npz")
    _progress_options(red)
    red.set_defaults(func=_cmd_reduce)

    modes = sub.add_parser("modes", help="stage 4: nonsmooth modes ([search]) of a reduced model or matrices",
                           description="Find and follow the families of [search] ipp over its period range, on a "
                                       "reduced model file or on user matrices (.npz with M, K, w, gap); write "
                                       "the families as JSON and optionally the frequency–energy plot.")
    modes.add_argument("study", type=Path, metavar="STUDY.toml")
    src = modes.add_mutually_exclusive_group(required=True)
    src.add_argument("--reduced", type=Path, metavar="REDUCED.npz")
    src.add_argument("--matrices", type=Path, metavar="FILE.npz",
                     help="user system: arrays M, K (n×n), w (n,) or an integer contact dof, gap; the study "
                          "then needs only [search] (and [study])")
    modes.add_argument("-o", "--output", type=Path, required=True, metavar="MODES.json")
    modes.add_argument("--plot", type=Path, metavar="FILE.png", help="also write the frequency–energy plot")
    _progress_options(modes)
    modes.set_defaults(func=_cmd_modes)

    ani = sub.add_parser("animate", help="stage 5: animations and VTK time series of chosen orbits",
                         description="Animate the orbits chosen by [output] (orbits, or the widest admissible "
                                     "arcs) of a modes file on the reduced model's mesh: GIF/MP4 (pyvista, "
                                     "off-screen) and VTK time series (.pvd + .vtu).")
    ani.add_argument("study", type=Path, metavar="STUDY.toml")
    ani.add_argument("--reduced", type=Path, required=True, metavar="REDUCED.npz")
    ani.add_argument("--modes", type=Path, required=True, metavar="MODES.json")
    ani.add_argument("--out", type=_out_dir, metavar="DIR", help="output directory (overrides [output] directory)")
    _progress_options(ani)
    ani.set_defaults(func=_cmd_animate)


def _setup(args) -> bool:
    """Configure logging of the 'bladecase' logger; return whether to show progress bars."""
    import logging

    logger = logging.getLogger("bladecase")
    handler = next((h for h in logger.handlers if getattr(h, "_bladecase", False)), None)
    if handler is None:
        handler = _BarSafeHandler(sys.stderr)
        handler.setFormatter(logging.Formatter("bladecase: %(message)s"))
        handler._bladecase = True
        logger.addHandler(handler)
        logger.propagate = False
    handler.stream = sys.stderr  # the current stderr (no flush of an old, possibly closed one)
    handler.setLevel(logging.WARNING if args.quiet else logging.INFO)
    logger.setLevel(logging.INFO)
    return not args.no_progress and not args.quiet and sys.stderr.isatty()


class _BarSafeHandler(logging.StreamHandler):
    """A stderr handler that writes through ``tqdm.write``: a message clears the progress bars, is printed on its
    own line, and the bars are drawn again below it (a log line never lands inside a bar)."""

    def emit(self, record) -> None:
        try:
            from tqdm import tqdm

            tqdm.write(self.format(record), file=self.stream)
            self.flush()
        except Exception:  # noqa: BLE001 — logging's own convention: report, never raise
            self.handleError(record)


def _study(path: Path, model: bool = True, contact: bool = True):
    from .study import load_study

    return load_study(path, model=model, contact=contact)


@contextmanager
def _folder_as_found(folder: Path) -> Iterator[None]:
    """A command that fails leaves no output folder it created: the folders made for it (left empty by the failed
    run, whose staging is gone) are removed again; an existing folder is left to the run's own all-or-nothing
    publication."""
    missing = []
    p = Path(folder).absolute()
    while not os.path.lexists(p) and p != p.parent:
        missing.append(p)
        p = p.parent
    ok = False
    try:
        yield
        ok = True
    finally:
        if not ok:
            for made in missing:  # deepest first
                try:
                    made.rmdir()  # only an empty folder
                except OSError:
                    break


def _cmd_run(args) -> int:
    from .io import check_output_dir

    progress = _setup(args)
    study = _study(args.study)
    with _folder_as_found(study.output_dir(args.out)):
        check_output_dir(study.output_dir(args.out))
        result = _run_study(study, args, progress)
    print(result.directory / "report.md")
    return 0


def _cmd_demo(args) -> int:
    from .io import check_output_dir
    from .study.demo import demo_study, demo_text

    if args.print_study:
        print(demo_text(), end="")
        return 0
    progress = _setup(args)
    study = demo_study()
    with _folder_as_found(study.output_dir(args.out)):
        check_output_dir(study.output_dir(args.out))
        result = _run_study(study, args, progress)
    print(result.directory / "report.md")
    return 0


def _cmd_mesh(args) -> int:
    from .fe import save_mesh
    from .io import written_together
    from .study.stages import build_mesh

    _setup(args)
    _check_outputs(args.output)
    study = _study(args.study, contact=False)  # meshing needs no contact
    _not_onto_inputs({"-o": args.output}, {"STUDY": args.study,
                                           "[mesh] path": None if study.parametric else study.mesh_path()})
    with written_together(args.output) as (out,):  # the mesh's groups are checked before it appears
        if study.parametric and args.output.suffix == ".msh":
            mesh = build_mesh(study, path=out)
        else:
            mesh = build_mesh(study)
            save_mesh(mesh, out)
    groups = ", ".join(f"{k} ({len(v)})" for k, v in sorted(mesh.groups.items()))
    print(f"{args.output}: {len(mesh.points)} nodes, {len(mesh.cells[mesh.body_type])} {mesh.body_type}; "
          f"groups {groups}")
    return 0


def _cmd_assemble(args) -> int:
    from .fe import load_mesh, natural_frequencies, save_model
    from .io import write_text, written_together
    from .study.stages import build_mesh, build_model, check_plausibility

    _setup(args)
    _check_outputs(args.output, args.calculix)
    if args.calculix is not None and args.calculix.suffix != ".inp":
        raise ValueError(f"--calculix {args.calculix}: a CalculiX deck is an .inp file, e.g. model.inp")
    study = _study(args.study, contact=False)  # assembling needs no contact
    _not_onto_inputs({"-o": args.output, "--calculix": args.calculix},
                     {"STUDY": args.study, "--mesh": args.mesh,
                      "[mesh] path": None if study.parametric else study.mesh_path()})
    if args.mesh is not None:
        clamp = study["fem"]["clamp"]
        m = study.config.get("mesh") or {}
        mesh = load_mesh(args.mesh, require=[clamp] if isinstance(clamp, str) else [], unit=m.get("unit") or "m",
                         file_format=m.get("format"))
    else:
        mesh = build_mesh(study)
    model = build_model(study, mesh)
    count = min(study["fem"]["frequencies"], model.n_dofs - 1)
    deck, speed = None, None
    if args.calculix is not None:  # before anything is written: a model the deck cannot hold is refused first
        from .fe.calculix import calculix_deck
        from .study.rotation.stage import operating_speed, rotation_axis

        speed = operating_speed(study)
        spin = {} if not speed else {"speed": speed, "axis": rotation_axis(study, model)}
        deck = calculix_deck(model, count, unit=args.calculix_unit, **spin)
    f = natural_frequencies(model, count)
    check_plausibility(study, model, float(f[0]))  # the unit slips a run warns of (a modulus in MPa…)
    at_speed = _frequencies_at_speed(study, model, count)
    with written_together(args.output, args.calculix) as (out, deck_out):  # both files or neither
        save_model(model, out)
        if deck is not None:
            write_text(deck_out, deck)
    print(f"{args.output}: {model}")
    print("linear frequencies (Hz): " + ", ".join(f"{x:.3f}" for x in f))
    if at_speed is not None:
        print(at_speed)
    if deck is not None:
        print(f"{args.calculix}: CalculiX deck ({args.calculix_unit}; run: ccx {args.calculix.with_suffix('').name}"
              + (f"; spinning at {speed:.6g} rad/s: compare with the Campbell diagram, not with the frequencies "
                 "at rest above" if speed else "")
              + ("; CalculiX's mass matrix is consistent: compare with [fem] mass = \"consistent\""
                 if model.mass == "lumped" else "") + ")")
    return 0


def _frequencies_at_speed(study, model, count: int) -> str | None:
    """With ``[rotation]``: the printed line of the model's frequencies at the operating speed (``K(Ω)``: stress
    stiffening, spin softening), and the note that the model file holds the structure at rest."""
    from .study.rotation.stage import operating_speed, rotation_axis

    speed = operating_speed(study)
    if speed is None:
        return None
    from .fe import natural_frequencies
    from .fe.rotation import spin
    from .post.rotation.report import speed_words
    from .study import StudyError

    try:
        state = spin(model, speed, rotation_axis(study, model), static=study["rotation"].get("static", "auto"))
    except ValueError as exc:
        raise StudyError(f"[rotation] speed: {exc}") from None
    f = natural_frequencies(state.model, count, factor=state.factor)
    return (f"at the operating speed {speed_words(speed, study['rotation']['speed_unit'])} ([rotation]): linear "
            "frequencies (Hz): " + ", ".join(f"{x:.3f}" for x in f) + " — the model file holds the structure at rest; "
            "'bladecase reduce' spins it to this speed")


def _cmd_reduce(args) -> int:
    from .fe import load_model
    from .reduction import save_reduced
    from .study.rotation.stage import operating_point
    from .study.stages import build_contact, build_reduced

    _setup(args)
    _check_outputs(args.output)
    _not_onto_inputs({"-o": args.output}, {"STUDY": args.study, "--model": args.model})
    study = _study(args.study)
    model = load_model(args.model)
    contact = build_contact(study, model)
    model, contact, factor, rotation = operating_point(study, model, contact)  # [rotation]: K(Ω), running clearance
    reduced = build_reduced(study, model, contact, args.method, args.size, factor=factor)
    save_reduced(reduced, args.output)
    sp = reduced.system.spectrum
    print(f"{args.output}: {reduced}; contact node {model.mesh.node_id(contact.node)}"
          + ("" if rotation is None else f"; at {rotation['speed_rad_s']:.6g} rad/s ([rotation]), running clearance "
             f"{rotation['clearance_running_m'] * 1e3:.4g} mm"))
    print("reduced frequencies (Hz): " + ", ".join(f"{x:.3f}" for x in sp.frequencies[sp.active][:12]))
    return 0


def _cmd_modes(args) -> int:
    from .io import save_figure, write_json, written_together
    from .study.documents import families_document
    from .study.stages import search

    progress = _setup(args)
    _check_outputs(args.output, args.plot)
    _not_onto_inputs({"-o": args.output, "--plot": args.plot},
                     {"STUDY": args.study, "--reduced": args.reduced, "--matrices": args.matrices})
    study = _study(args.study, model=args.reduced is not None)  # with --matrices: [search] is enough
    if args.reduced is not None:
        from .reduction import load_reduced

        system = load_reduced(args.reduced).system
    else:
        args.chain, args.gap = None, None
        system = _load_system(args)
    families = search(study, system, progress=progress)
    document = families_document(families, system)
    figure = _plot(families) if args.plot else None  # before anything is written: nothing to plot is an error
    with written_together(args.output, args.plot) as (out, plot):
        write_json(out, document)
        if figure is not None:
            save_figure(figure, plot, dpi=150)
    for i, fam in enumerate(families):
        if fam.arcs:
            print(f"family {i}: " + fam.table())
    print(f"{args.output}: {len(families)} families, {sum(len(f.arcs) for f in families)} admissible arcs")
    return 0


def _cmd_animate(args) -> int:
    from .io import check_output_dir
    from .reduction import load_reduced
    from .study.documents import load_families
    from .study.publish import check_inputs
    from .study.render import animate_families

    progress = _setup(args)
    study = _study(args.study)
    check_inputs(study.output_dir(args.out), [args.study, args.reduced, args.modes], ("animations", "vtk"))
    with _folder_as_found(study.output_dir(args.out)):
        reduced = load_reduced(args.reduced)
        families = load_families(args.modes, reduced.system, reduced=args.reduced)
        check_output_dir(study.output_dir(args.out))
        written = animate_families(study, reduced, families, out=args.out, progress=progress)
        if not written:  # nothing was published: the folder is as it was
            raise _NothingToAnimate()
    for entry in written:
        print(", ".join(str(entry[k]) for k in ("gif", "mp4", "pvd", "manifold") if k in entry))
    return 0


class _NothingToAnimate(Exception):
    """``bladecase animate`` found no orbit to animate (exit 1; the output folder untouched)."""


class _Terminated(KeyboardInterrupt):
    """SIGTERM, raised like Ctrl-C so that every ``finally`` and staging clean-up runs."""


def _on_sigterm(signum, frame) -> None:
    raise _Terminated()


def _one_line(exc: BaseException) -> str:
    return "; ".join(line.strip() for line in str(exc).splitlines() if line.strip()) or type(exc).__name__


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``bladecase`` command; returns the exit code: 0 on success, 2 on bad arguments
    or input (a one-line reason on stderr, never a traceback), 1 when a computation fails (e.g. no
    off-screen rendering, out of memory), 130 on Ctrl-C and 143 on SIGTERM (the shell's convention:
    128 + signal number, so that scripts see an interruption, not bad input) — an interrupted run removes
    its staging folder and leaves the previous results untouched."""
    import signal
    import threading

    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a bad argument (message already printed)
        return int(exc.code or 0) if not isinstance(exc.code, str) else 2
    if args.command is None:
        parser.print_help()
        return 2
    main_thread = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGTERM, _on_sigterm) if main_thread else None
    where = f"bladecase {args.command}"
    try:
        return args.func(args)
    except ValueError as exc:  # includes StudyError: the message names the key
        print(f"{where}: error: {_one_line(exc)}", file=sys.stderr)
        return 2
    except _NothingToAnimate:
        print(f"{where}: no admissible orbit to animate: nothing written, the output folder is as it was",
              file=sys.stderr)
        return 1
    except BrokenPipeError:  # output piped into e.g. `head`
        sys.stdout = open(os.devnull, "w")
        return 0
    except OSError as exc:  # a file or folder the command cannot read or write (full disk, permissions…)
        from .io import os_reason

        name = f" {exc.filename!s}:" if exc.filename else ""
        print(f"{where}: error:{name} {os_reason(exc)}", file=sys.stderr)
        return 2
    except MemoryError:
        print(f"{where}: error: out of memory (reduce the sizes asked for: [reduction] size, [search] scan, "
              "[output] frames, manifold_size)", file=sys.stderr)
        return 1
    except RecursionError:  # (before RuntimeError, its base class)
        print(f"{where}: error: an input is nested too deeply to be read (a study, mesh or JSON file)", file=sys.stderr)
        return 2
    except RuntimeError as exc:  # e.g. no off-screen rendering
        print(f"{where}: error: {_one_line(exc)}", file=sys.stderr)
        return 1
    except KeyboardInterrupt as exc:  # Ctrl-C or SIGTERM
        what = "terminated" if isinstance(exc, _Terminated) else "interrupted"
        print(f"{where}: {what}, previous results untouched", file=sys.stderr)
        return 143 if isinstance(exc, _Terminated) else 130
    except Exception as exc:  # an input no check caught, or a bug: one line, never a traceback
        if os.environ.get("BLADECASE_TRACEBACK"):
            raise
        print(f"{where}: error: unexpected {type(exc).__name__}: {_one_line(exc)} — an input bladecase failed to "
              "check, or a bug in bladecase (BLADECASE_TRACEBACK=1 shows where; please report it)", file=sys.stderr)
        return 2
    finally:
        if main_thread:
            signal.signal(signal.SIGTERM, previous if previous is not None else signal.SIG_DFL)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
