"""The abradable coating worn by the demo blade near its engine-order crossing, the wear coupled to the blade's
dynamics (each revolution flown exactly with the profile the revolutions before left as its clearance), through
the study's rub stage.

The coating yields during the flight: the peak contact pressure of each speed, printed against
the yield, must be the yield to round-off.

Held-out check, over the same last four revolutions: the number of lobes of the coating worn in them, read from
the profile alone (its strongest circumferential harmonic), against round(f_vib / f_rot), read from the response
alone (the strongest line of the spectrum of the tips' normal displacement, over the rotation frequency). Each
speed agrees, differs, or has no lobe count to compare, with the reason: no wear, no one lobe count in the wear,
several vibration frequencies of the tip, or a vibration too far from an engine order (smeared wear). Also printed:
the removed volume against the profile's missing area × the band's width, the speeds refused, and the cost.

    python benchmarks/bench_wear.py                          # 1550, 1626, 1700 rpm, 12 revolutions, 180 cells
    python benchmarks/bench_wear.py --speeds 1626 --revolutions 6 --cells 90 --mu 0.15

Measured (``--speeds 1550 1600 1626 1650 1700 --revolutions 12 --cells 90``, a busy two-core machine, 137 s): peak
pressure 2 MPa = the yield at every speed (peak / yield − 1 = 2.5e-11 to 2.3e-10); every final profile 8 lobes, 141
to 593 µm deep, none worn through; the check on the last four revolutions that wore the coating: agree at 1600,
1626 and 1650 rpm (8 lobes; f_vib / f_rot = 7.99, 7.99, 7.89), differ nowhere, undefined at 1550 and 1700 rpm
(8.38 and 7.80: the lobes drift by 1.5 and 0.8 lobe lengths over the revolutions read, smeared); removed volume =
missing volume to 2e-16. With ``--mu 0.15`` (151 s): every speed goes through (with the coating elastic within a
revolution: refused at all five, contact phases with friction diverging); peak / yield − 1 = 1.4e-11 to 1.8e-11;
8 lobes, 146 to 269 µm deep; agree at 1626 and 1650 rpm, differ nowhere, undefined at 1550, 1600 and 1700 rpm
(8.38, 8.14, 7.75: smeared). With the coating elastic within a revolution (before): peak pressures 5 to 1000 MPa.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from test_rub_study import _study  # noqa: E402

from bladecase.study.executor import SerialExecutor  # noqa: E402
from bladecase.study.rub.stage import rub_stage  # noqa: E402
from bladecase.study.schema import loads  # noqa: E402
from bladecase.study.stages import build_contact, build_mesh, build_model  # noqa: E402

CASING = """
[casing]
radius = 0.4505
axis = {origin = [-0.000167, 0.030778, -0.3], direction = [-0.350089, -0.936717, 0.0]}
lobes = 8
amplitude = 3e-4
abradable = {thickness = 1e-3, yield = YIELD, stiffness = STIFFNESS, cells = CELLS}
"""

RUB = """
[rub]
speeds = SPEEDS
ratio = 0.005
revolutions = REVS
window = WINDOW
max_revolutions = REVS
"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--speeds", type=float, nargs="+", default=[1550.0, 1626.0, 1700.0], help="rpm")
    ap.add_argument("--revolutions", type=int, default=12)
    ap.add_argument("--cells", type=int, default=180)
    ap.add_argument("--yield-pressure", type=float, default=2e6, help="Pa")
    ap.add_argument("--stiffness", type=float, default=1e12, help="Pa/m")
    ap.add_argument("--mu", type=float, default=0.0, help="friction coefficient (0: none)")
    args = ap.parse_args()
    casing = (CASING.replace("YIELD", f"{args.yield_pressure:g}").replace("STIFFNESS", f"{args.stiffness:g}")
              .replace("CELLS", str(args.cells)))
    rub = (RUB.replace("SPEEDS", str(list(args.speeds))).replace("REVS", str(args.revolutions))
           .replace("WINDOW", str(max(1, args.revolutions // 2))))
    contact = {"friction": f"{{mu = {args.mu:g}}}"} if args.mu > 0 else {}
    text = _study(casing, rub, **contact).replace(
        "casing_stiffness = 1e6      # N/m: a thin casing's local radial stiffness; the modes converge "
        "(docs/massless.md)\n", "")
    study = loads(text, source="<bench_wear>")
    t0 = time.perf_counter()
    model = build_model(study, build_mesh(study))
    contact_ = build_contact(study, model)
    t1 = time.perf_counter()
    section = rub_stage(study, model, contact_, executor=SerialExecutor(), figures=False)
    t2 = time.perf_counter()
    wear = section["wear"]
    c = wear["coating"]
    print(f"the demo blade in an abradable coating: {c['thickness_m'] * 1e3:g} mm, yield {c['yield_pa'] * 1e-6:g} MPa, "
          f"{c['stiffness_pa_per_m']:g} Pa/m, {c['cells']} cells over a {c['width_m'] * 1e3:.4g} mm band; 8 lobes of "
          f"0.3 mm; {args.revolutions} revolutions a speed; mu = {args.mu:g}")
    print(f"coupling: {wear['coupling']}")
    crossing = section.get("crossing") or {}
    if crossing:
        print(f"crossing speed of mode 1 with the 8 lobes: {crossing['speed']:.6g} rpm")
    verdicts = {"agree": 0, "differ": 0, "undefined": 0}
    for row, w in zip(section["rows"], wear["speeds"]):
        c = w["lobe_check"]
        verdicts[c["verdict"]] += 1
        print(f"  {w['speed']:7.6g} rpm ({row['speed_ratio']:.3f} x crossing): final profile {w['lobes']:2d} lobes, "
              f"{w['lobe_depth_um']:8.3f} um deep (deepest {w['max_depth_um']:.3f} um); removed "
              f"{w['removed_mm3']:.6g} mm3 vs missing {w['missing_mm3']:.6g} mm3 (rel. {w['volume_mismatch']:.1e})"
              + ("; worn through to the casing" if w["worn_through"] else ""))
        y = wear["coating"]["yield_pa"] * 1e-6
        print(f"      peak contact pressure over the revolutions {w['peak_pressure_mpa']:.6g} MPa (yield {y:g} MPa; "
              f"peak / yield - 1 = {w['peak_pressure_mpa'] / y - 1:.1e})")
        first = c["last"] - c["window"] + 1
        read = f"revolutions {first}-{c['last']} (the last that wore)" if c["last"] else "none wore"
        print(f"      {read}: wear {c['lobes']} lobes"
              + (f" (rival harmonic {c['rival']})" if c["rival"] else "")
              + f"; response f_vib/f_rot = {c['ratio']:.3f} -> round {c['expected']}"
              + (f" (next line {c['second']:.3g} at {c['second_share']:.2f} of it)" if c["second_share"] else "")
              + f": {c['verdict'].upper() if c['verdict'] != 'agree' else 'agree'}"
              + (f" - {c['reason']}" if c["reason"] else ""))
        print("      f_vib/f_rot of each of those revolutions alone: "
              + ", ".join(f"{r:.2f}" for r in c["per_revolution"]))
    for f in section["failed_speeds"]:
        print(f"  {f['speed']:7.6g} rpm refused: {f['reason']}")
    print(f"lobe count = round(f_vib / f_rot) over the last revolutions: agree at {verdicts['agree']}, differ at "
          f"{verdicts['differ']}, undefined at {verdicts['undefined']} of {len(wear['speeds'])} speeds run "
          f"({len(section['failed_speeds'])} refused)")
    n = len(section["rows"])
    print(f"cost: model {t1 - t0:.1f} s; rub stage {t2 - t1:.1f} s for {n} speeds ({(t2 - t1) / n:.1f} s a speed, the "
          "rub response and the coupled wear run)")


if __name__ == "__main__":
    main()
