"""Held-out check: the NASA Rotor 37 blade of a public CalculiX deck, bladecase against CalculiX ``NLGEOM``.

The deck (``blade.inp`` with ``*INCLUDE, INPUT=blade.msh``: N-mm-t-s, 15-node wedges ``C3D15``, the root held by
``*BOUNDARY``, ``*MATERIAL`` 210 000 MPa / 0.3 / 9e-9 t/mm³) is the Rotor 37 blade of the blade–casing rubbing
example of NLstep (Monjaraz-Tec, Gross & Krack; github.com/maltekrack/NLstep, ``EXAMPLES/03_bladeCasingRubbing/
FEmodel``).  Its radial direction is ``x``, the engine axis is ``z`` through the origin.

1. bladecase reads the deck through a study (``[mesh] unit = "mm"``, ``[fem] order = 2``, ``mass = "consistent"``,
   ``clamp = "boundary"``, no ``[material]``: the deck's own) and computes f1–f4 at rest and, with
   ``spin(..., static="nonlinear")`` about the z axis, at each speed (default 900 and 1800 rad/s);
2. CalculiX runs the deck itself (its mesh, ``*BOUNDARY`` and ``*MATERIAL`` as written; only its steps are
   replaced): at rest ``*FREQUENCY``; at speed ``*STEP, NLGEOM`` / ``*STATIC`` with ``*DLOAD ... CENTRIF`` then
   ``*STEP, PERTURBATION`` / ``*FREQUENCY``;
3. prints both and the relative differences against the goals (0.05 % at rest, 0.3 % at speed), and the number of
   points of bladecase's nodal grid (the animation frames' and ``mesh.vtu``'s, ``post.grid.fe_grid``) against the
   deck's nodes.

Run (a few minutes on a 2-core machine; CalculiX single-threaded):

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_rotor37.py DATA/blade.inp [--speeds 900 1800]
        [--no-ccx] [--threads 1] [--rub 1344 [--rub-only]]
"""

from __future__ import annotations

import argparse
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from bladecase.fe.rotation import RotationAxis, spin
from bladecase.linalg import lowest_modes
from bladecase.post.grid import fe_grid
from bladecase.study.schema import loads
from bladecase.study.stages import build_mesh, build_model

AXIS = RotationAxis((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
GOALS = {"rest": 5e-4, "speed": 3e-3}
#: The 16 tip nodes of the NLstep rub example (its nodeSet_contact).
TIP_NODES = [188, 190, 192, 194, 196, 198, 200, 203, 253, 255, 257, 259, 261, 263, 265, 267]


def deck_text(deck: Path, name: str, mass: str = "consistent") -> str:
    """The ``[study]``, ``[mesh]`` and ``[fem]`` tables of a study of the deck (N-mm, quadratic wedges, the root's
    boundary clamped), for this file's studies and ``bench_rotor37_rub.py``'s."""
    return f"""
[study]
name = "{name}"

[mesh]
path = "{deck.resolve()}"
unit = "mm"

[fem]
order = 2
mass = "{mass}"
clamp = "boundary"
"""


def study_text(deck: Path) -> str:
    return deck_text(deck, "rotor37") + f"""
[contact]
nodes = {TIP_NODES}
normal = [1.0, 0.0, 0.0]
clearance = 3.56e-4
"""


def rub_text(deck: Path, speed: float, rub: bool = True) -> str:
    """A study of the deck's blade turning at ``speed`` (rad/s) in a two-lobed conical casing, every one of the 16
    tip nodes a massless contact (``[rub]``), and the face mean's first nonsmooth mode animated (VTK frames).  The
    tip nodes lie on the cone ``r = 640.006 mm − 0.27245 (z − 6.55 mm)``; the casing is 2 mm outside it (cold:
    at 900 rad/s CalculiX's NLGEOM state moves the tip nodes out radially by 0.05–0.64 mm), its two lobes reach
    1 mm inwards."""
    z0, z1 = 0.00655, 0.06859
    r = lambda z: 0.640006 - 0.27245 * (z - z0) + 2e-3  # noqa: E731
    text = deck_text(deck, "rotor37_rub", "lumped") + f"""
[contact]
nodes = {TIP_NODES}
model = "massless"
weights = "equal"           # a line of nodes has no area (the default under [casing] is "area")
# no casing_stiffness: a rigid casing (a stiffness is shared by tributary area, which a line of nodes lacks)

[casing]
radii = [[{z0}, {r(z0)!r}], [{z1}, {r(z1)!r}]]
axis = {{origin = [0.0, 0.0, 0.0], direction = [0.0, 0.0, 1.0]}}
lobes = 2
amplitude = 1e-3

[reduction]
method = "massless"
size = 8

[search]
ipp = [1]
periods = [0.95, 1.0001]
period_unit = "T1"
scan = 6
amplitude_limit = 0.2       # the 2 mm clearance needs a large orbit: do not cut it at 5 % of the span

[output]
animate = 1
frames = 8
formats = ["vtu"]
reference = false

[rub]
speeds = [{speed!r}]
speed_unit = "rad/s"
ratio = 0.005
revolutions = 20
window = 5
max_revolutions = 20
"""
    return text if rub else text.split("[rub]")[0]


def rub_run(deck: Path, speed: float, rub: bool = True) -> None:
    """Run :func:`rub_text` with ``bladecase run``; print its time, ``rub.csv`` and the points of ``mesh.vtu``
    against those of the animation's frames (when the run with ``[rub]`` fails, the study again without it)."""
    out = Path(tempfile.mkdtemp(prefix="rotor37_rub_"))
    (out / "study.toml").write_text(rub_text(deck, speed, rub))
    t = time.perf_counter()
    run = subprocess.run([sys.executable, "-m", "bladecase", "run", "--quiet", "--no-progress", "--out",
                          str(out / "run"), str(out / "study.toml")], capture_output=True, text=True)
    print(f"\n{'[rub] ' if rub else ''}study at {speed:g} rad/s: exit {run.returncode}, "
          f"{time.perf_counter() - t:.0f} s -> {out / 'run'}")
    if run.returncode != 0:
        print(run.stderr[-3000:])
        if rub:
            rub_run(deck, speed, rub=False)
        return
    print(vtu_points(out / "run"))
    csv = out / "run" / "rub.csv"
    print(csv.read_text() if csv.exists() else "no rub.csv")


def vtu_points(folder: Path) -> str:
    """The points of ``mesh.vtu`` and of the animation frames in a results folder (pyvista: meshio has no wedge15)."""
    import pyvista

    frames = [f for f in sorted(folder.rglob("*.vtu")) if f.name != "mesh.vtu" and "rub" not in f.name
              and "manifold" not in f.name]
    counts = sorted({pyvista.read(f).n_points for f in frames})
    return (f"mesh.vtu points {pyvista.read(folder / 'mesh.vtu').n_points}; animation frames ({len(frames)} files) "
            f"points {counts}")


def bladecase_frequencies(deck: Path, speeds, count: int):
    study = loads(study_text(deck), source=str(deck))
    t = time.perf_counter()
    mesh = build_mesh(study)
    model = build_model(study, mesh)
    print(f"bladecase: {model!r} ({time.perf_counter() - t:.1f} s)")
    out = {}
    for w in speeds:
        t = time.perf_counter()
        if w == 0:
            f = np.sqrt(lowest_modes(model.K, model.M, count)[0]) / (2 * math.pi)
            out[w] = (f, time.perf_counter() - t, "")
        else:
            state = spin(model, w, AXIS, static="nonlinear")
            f = np.sqrt(lowest_modes(state.model.K, state.model.M, count, factor=state.factor)[0]) / (2 * math.pi)
            out[w] = (f, time.perf_counter() - t, f"{state.iterations} Newton iterations, largest |u_i| "
                      f"{np.abs(state.displacement).max() * 1e3:.4f} mm")
        print(f"bladecase {w:7.1f} rad/s: " + " ".join(f"{x:10.4f}" for x in out[w][0])
              + f" Hz  ({out[w][1]:.1f} s) {out[w][2]}")
    return model, mesh, out


def ccx_deck(deck: Path, speed: float, count: int) -> str:
    """The deck's model part (everything before its first ``*STEP``, the include made absolute) and our steps."""
    text = deck.read_text()
    head = re.split(r"(?mi)^\*STEP", text)[0]
    head = re.sub(r"(?mi)^(\*include\s*,\s*input\s*=\s*)(\S+)",
                  lambda m: m.group(1) + str((deck.parent / m.group(2)).resolve()), head)
    if speed == 0:
        return head + f"*STEP\n*FREQUENCY\n{count}\n*END STEP\n"
    return head + (f"*STEP, NLGEOM, INC=100\n*STATIC\n0.25, 1.0, 1e-5, 0.25\n*DLOAD\nEall, CENTRIF, {speed ** 2!r}, "
                   "0., 0., 0., 0., 0., 1.\n*NODE PRINT, NSET=Nall\nU\n*END STEP\n"
                   f"*STEP, PERTURBATION\n*FREQUENCY\n{count}\n*END STEP\n")


def dat_frequencies(dat: Path, count: int) -> np.ndarray:
    """The last eigenvalue table of a CalculiX ``.dat``: frequencies (cycles/time)."""
    text = dat.read_text()
    if "E I G E N V A L U E   O U T P U T" not in text:
        raise RuntimeError(f"{dat}: no eigenvalue output")
    rows = []
    for line in text.split("E I G E N V A L U E   O U T P U T")[-1].splitlines():
        parts = line.split()
        if len(parts) == 5 and parts[0].isdigit():
            rows.append(float(parts[3]))
        elif rows and not parts:
            break
    return np.array(rows[:count])


def ccx_displacement(dat: Path) -> float:
    """The largest displacement component printed by ``*NODE PRINT`` at the end of the static step (mm)."""
    text = dat.read_text().split("E I G E N V A L U E")[0]
    block = text.split("displacements (vx,vy,vz)")[-1]
    vals = [list(map(float, ln.split()[1:4])) for ln in block.splitlines() if len(ln.split()) == 4]
    return float(np.abs(np.array(vals)).max()) if vals else float("nan")


def calculix_frequencies(deck: Path, speeds, count: int, threads: int):
    out = {}
    with tempfile.TemporaryDirectory(prefix="rotor37_ccx_") as tmp:
        for w in speeds:
            name = f"r37_{int(round(w))}"
            (Path(tmp) / f"{name}.inp").write_text(ccx_deck(deck, w, count))
            t = time.perf_counter()
            env = dict(os.environ, OMP_NUM_THREADS=str(threads), CCX_NPROC_EQUATION_SOLVER=str(threads))
            run = subprocess.run(["ccx", "-i", name], cwd=tmp, env=env, capture_output=True, text=True)
            dat = Path(tmp) / f"{name}.dat"
            if run.returncode != 0 or not dat.exists() or "E I G E N" not in dat.read_text():
                raise RuntimeError(f"ccx failed at {w} rad/s:\n{run.stdout[-2000:]}\n{run.stderr[-2000:]}")
            f = dat_frequencies(dat, count)
            extra = f"largest |u_i| {ccx_displacement(dat):.4f} mm" if w else ""
            out[w] = (f, time.perf_counter() - t, extra)
            print(f"CalculiX  {w:7.1f} rad/s: " + " ".join(f"{x:10.4f}" for x in f)
                  + f" Hz  ({out[w][1]:.1f} s) {extra}")
    return out


def deck_nodes(deck: Path) -> int:
    """The number of nodes the deck's elements use (read from its text, independently of bladecase's reader)."""
    text = deck.read_text()
    for inc in re.findall(r"(?mi)^\*include\s*,\s*input\s*=\s*(\S+)", text):
        text += "\n" + (deck.parent / inc).read_text()
    used = set()
    for block in re.split(r"(?m)^\*", text):
        if block.upper().startswith("ELEMENT"):
            nums = [int(x) for x in re.split(r"[,\s]+", block.split("\n", 1)[1]) if x.strip().isdigit()]
            rows, row, per = [], [], 16  # element id + 15 nodes (C3D15), continued over lines
            for x in nums:
                row.append(x)
                if len(row) == per:
                    rows.append(row[1:])
                    row = []
            used.update(n for r in rows for n in r)
    return len(used)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("deck", type=Path)
    ap.add_argument("--speeds", type=float, nargs="+", default=[900.0, 1800.0], help="rad/s (rest is added)")
    ap.add_argument("--count", type=int, default=4)
    ap.add_argument("--no-ccx", action="store_true")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--rub", type=float, metavar="RAD_S", help="also run the [rub] study at this speed (rad/s)")
    ap.add_argument("--rub-only", action="store_true", help="only the [rub] study")
    ap.add_argument("--no-rub-section", action="store_true", help="the --rub study without its [rub] section")
    args = ap.parse_args()
    if args.rub is not None:
        rub_run(args.deck, args.rub, rub=not args.no_rub_section)
        if args.rub_only:
            return
    speeds = [0.0] + [s for s in args.speeds if s > 0]
    model, mesh, bc = bladecase_frequencies(args.deck, speeds, args.count)
    grid = fe_grid(model)
    print(f"points: bladecase's nodal grid (animation frames, mesh.vtu) {len(grid.points)}, deck's element nodes "
          f"{deck_nodes(args.deck)}, mesh points {len(mesh.points)}")
    if args.no_ccx or shutil.which("ccx") is None:
        print("CalculiX not run")
        return
    cx = calculix_frequencies(args.deck, speeds, args.count, args.threads)
    print(f"\n{'rad/s':>7} " + " ".join(f"{'f' + str(k + 1) + ' diff':>10}" for k in range(args.count))
          + "   (bladecase / CalculiX − 1)  goal")
    ok = True
    for w in speeds:
        rel = bc[w][0] / cx[w][0] - 1
        goal = GOALS["rest" if w == 0 else "speed"]
        met = bool(np.all(np.abs(rel) <= goal))
        ok &= met
        print(f"{w:7.1f} " + " ".join(f"{100 * x:+9.4f}%" for x in rel)
              + f"   |diff| <= {100 * goal:g} %: {'MET' if met else 'NOT MET'}")
    print(f"all goals: {'MET' if ok else 'NOT MET'}")


if __name__ == "__main__":
    main()
