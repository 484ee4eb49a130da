"""``bladecase backbone``: the nonsmooth modes of a chain or of stored matrices, without a study."""

from __future__ import annotations

import sys

from .cli_input import check_outputs, load_system, not_onto_inputs


def cmd_backbone(args) -> int:
    """``bladecase backbone``: a chain's or stored matrices' backbone (1-ipp) or k-ipp families, as a table, JSON
    and a frequency–energy plot, written together or not at all."""
    from .io import save_figure, write_json, write_text, written_together
    from .nsm import backbone

    check_outputs(args.table, args.json, args.plot)
    not_onto_inputs({"--table": args.table, "--json": args.json, "--plot": args.plot},
                     {"--matrices": args.matrices})
    system = load_system(args)
    progress = not args.no_progress and sys.stderr.isatty()
    if args.ipp == 1:
        result = backbone(system, args.periods, ipp=1, progress=progress)
        curves = [result]
        table = result.table()
        summary = table.split("\n\n", 1)[-1]
        data = result.to_dict()
    else:
        from .nsm import nonsmooth_mode

        P = args.periods
        if P.size < 2 or P[0] == P[-1]:
            raise ValueError("--ipp K >= 2 needs a period range: START < STOP and COUNT >= 2")
        curves = nonsmooth_mode(system, args.ipp, (P[0], P[-1]), scan=P.size, progress=progress)
        if curves:
            summary = "\n".join(f.table() for f in curves)
            table = summary if args.quiet else "\n\n".join(f.table(points=True) for f in curves)
        else:
            summary = table = f"no {args.ipp}-ipp family found in T in [{P[0]:g}, {P[-1]:g}]"
        data = {
            "ipp": args.ipp,
            "system": {"n": system.n, "gap": system.gap},
            "T_range": [float(P[0]), float(P[-1])],
            "families": [f.to_dict() for f in curves],
        }
    figure = plot(curves) if args.plot else None  # before anything is written: nothing to plot is an error
    with written_together(args.table, args.json, args.plot) as (table_out, json_out, plot_out):
        if args.table:
            write_text(table_out, table + "\n")
        if args.json:
            write_json(json_out, data)
        if figure is not None:
            save_figure(figure, plot_out, dpi=150)
    print(summary if args.quiet else table)
    for label, path in (("table", args.table), ("json", args.json), ("plot", args.plot)):
        if path:
            print(f"wrote {label}: {path}", file=sys.stderr)
    return 0


def plot(curves):
    """The frequency–energy plot (a Figure) of backbones/families; ``ValueError`` when there is none."""
    from .post.plots import frequency_energy

    if not curves:
        raise ValueError("nothing to plot: no family found (--plot needs one; leave it out, or widen the periods)")
    return frequency_energy(curves)
