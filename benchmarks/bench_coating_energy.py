"""The energy balance of the coating yielding in flight on the demo blade's tip: how well it closes, what it costs
beside the flight.

The demo blade's 26 tip nodes as stored in ``tests/data/demo_tip_coating_graze.npz`` (8 interior modes, μ = 0.15,
8 lobes of 0.3 mm, 0.5 % damping, the coating's yield and stiffness at each node; 1657.1 rpm):

1. ``wear_rub`` over ``--revolutions`` revolutions from rest, without and with ``energy=True``: the wall and CPU
   time of each, every revolution's balance (terms, residual, relative residual).
2. One revolution flown from rest over the profile the first revolution of (1) leaves (its phases built once
   before, as a wear rub's later revolutions find them): the flight's and the balance's time, best of two each.

    python benchmarks/bench_coating_energy.py
    python benchmarks/bench_coating_energy.py --revolutions 3
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from bladecase.nsm import Damping
from bladecase.nsm.massless.coating_energy import coating_balance, surface_steps
from bladecase.nsm.massless.coating_flight import CoatingFlight
from bladecase.nsm.massless.friction import Friction
from bladecase.nsm.massless.nodes import NodalSystem, Profile, Rub
from bladecase.nsm.massless.wear import Abradable
from bladecase.nsm.massless.wear_rub import wear_rub

DATA = Path(__file__).resolve().parents[1] / "tests" / "data" / "demo_tip_coating_graze.npz"


def _timed(f, *a, **kw):
    w, c = time.perf_counter(), time.process_time()
    out = f(*a, **kw)
    return out, time.perf_counter() - w, time.process_time() - c


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--revolutions", type=int, default=2)
    args = ap.parse_args()
    d = dict(np.load(DATA))
    s = NodalSystem(d["M"], d["S"], d["W"], d["flexibility"], d["gap"], d["casing"], nodes=tuple(d["nodes"].tolist()))
    f = Friction(float(d["mu"]), T=d["T"], C_nt=d["C_nt"], C_tt=d["C_tt"], model="rotation")
    speed, damping = float(d["speed"]), Damping(zeta=float(d["zeta"]))
    k = 1e12  # Pa/m: the nodes' areas are casing / k, the yield pressure the same at every node
    c = Abradable(1e-3, float(np.mean(d["yield_force"] / d["casing"]) * k), k, cells=360, radius=0.3, width=0.02)
    rub_args = (s, c, speed, int(d["lobes"]), float(d["amplitude"]), d["angles"], damping)
    print(f"demo tip: {s.m} nodes, {s.n} modes, {speed * 30 / np.pi:.1f} rpm, mu = {f.mu:g}")
    for energy in (False, True):
        w, wall, cpu = _timed(wear_rub, *rub_args, revolutions=args.revolutions, areas=d["casing"] / k, friction=f,
                              energy=energy)
        print(f"wear_rub energy={energy}: {w.phases} phases, {wall:.2f} s ({cpu:.2f} s CPU)")
        for r, e in enumerate(w.energy or ()):
            print(f"  revolution {r + 1}: casing {e.casing:.6g} J, friction {e.friction:.6g}, damping {e.damping:.6g}, "
                  f"plastic {e.plastic:.6g}, steps {e.steps:.6g}, stored change {e.stored_change:.6g}; residual "
                  f"{e.residual:.3g} J, relative {e.relative:.3g}, quadrature {e.quadrature_error:.3g}")
    first = wear_rub(*rub_args, revolutions=1, areas=d["casing"] / k, friction=f)
    fl = CoatingFlight(s, d["yield_force"], damping, Rub(int(d["lobes"]), float(d["amplitude"]), speed, d["angles"]),
                       f)
    prof = Profile(first.profile.depth, speed, d["angles"])
    flights, balances = [], []
    for _ in range(2):
        tr, wall, _ = _timed(fl.simulate, np.zeros(s.n), np.zeros(s.n), 2 * np.pi / speed, profile=prof)
        flights.append(wall)
        e, wall, _ = _timed(coating_balance, tr, 0.0, tr.t_end)
        balances.append(wall)
    print(f"one revolution over the worn profile: {tr.starts.size} phases ({surface_steps(tr).size} surface steps); "
          f"flight {min(flights):.2f} s, balance {min(balances):.2f} s ({100 * min(balances) / min(flights):.0f} %); "
          f"relative residual {e.relative:.3g}")


if __name__ == "__main__":
    main()
