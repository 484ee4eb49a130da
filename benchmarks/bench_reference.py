"""The orbit check's reference model: its cost against the model it checks, Krylov extension vs an eigen-solve.

A study checks each chosen orbit in a reference model with 4 × the reduced model's dofs
(``bladecase.study.reference``). Two ways to build it:

* ``krylov`` (the default): the model's basis extended by the block Krylov sequence of the factorisation the
  model was built with (``bladecase.reduction.krylov_extension``) — one solve per added dof, no eigen-solve;
* ``independent``: another reduced model, 4 × the size, from its own eigen-solve (the only kind before).

On the twisted NACA blade of ``bench_fem.py`` (P2, Ti-6Al-4V, root clamped; ``--size 0.00175`` gives 61 704
free dofs, the size of the CalculiX comparison), with ONE factorisation of ``K`` shared by everything, this
times (``time.perf_counter``, one process, ``OPENBLAS_NUM_THREADS=1``):

* the massless model (lumped mass, the tip face's mean normal displacement as the contact, ``massless`` of
  ``--size-r`` modes) and its reference both ways;
* the Newton model (consistent mass, the tip node farthest along the span, ``lanczos-si`` of ``--size-r`` steps)
  and its reference both ways (``modal`` of 4 × the size when independent);

and prints, per contact model, the seconds of the model, of each reference, and the share of the reference in
the ``reduce`` stage (model + reference; the goal: ≤ 50 %, i.e. a reference that costs no more than the model),
plus how exactly the extension contains the model (the largest ``M``-norm residual of the model's basis vectors
projected on the extension; round-off) and the lowest frequencies of both references against the FE model's.

Run::

    .venv/bin/python benchmarks/bench_reference.py [--size 0.00175] [--size-r 20] [--json FILE]

Exit status 0 whatever the figures.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import json  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import scipy.linalg as sla  # noqa: E402
from bench_core import line, machine, verdict  # noqa: E402
from bench_fem import blade  # noqa: E402

import bladecase  # noqa: E402
from bladecase.fe import stiffness_factor  # noqa: E402
from bladecase.reduction import Contact  # noqa: E402
from bladecase.study.reference import reference_model  # noqa: E402

#: The goal: the reference takes at most this share of the reduce stage (model + reference).
GOAL_SHARE = 0.5


def timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t0


class SolveCounter:
    """Counts the right-hand sides solved with ``factor`` (a cost that does not depend on the machine's load)."""

    def __init__(self, factor):
        self.count, self._inner = 0, factor._solve

        def solve(b):
            self.count += 1 if b.ndim == 1 else b.shape[1]
            return self._inner(b)
        factor._solve = solve

    def take(self) -> int:
        count, self.count = self.count, 0
        return count


def containment(reduced, reference) -> float:
    """Largest relative ``M``-norm residual of the model's basis columns projected on the reference's basis."""
    M = getattr(reference, "mass_matrix", reference.model.M)
    V, Q = np.asarray(reduced.basis), np.asarray(reference.basis)
    MQ = M @ Q
    coef = np.linalg.solve(Q.T @ MQ, MQ.T @ V)
    R = V - Q @ coef
    num = np.einsum("ij,ij->j", R, M @ R)
    den = np.einsum("ij,ij->j", V, M @ V)
    return float(np.sqrt(np.max(num / den)))


def lowest_hz(reference, count: int = 5) -> np.ndarray:
    s = reference.system
    K = getattr(s, "S", None)
    K = s.K if K is None else K
    lam = sla.eigh(np.asarray(K.toarray() if hasattr(K, "toarray") else K), np.asarray(s.M),
                   eigvals_only=True)[:count]
    return np.sqrt(np.maximum(lam, 0.0)) / (2 * np.pi)


def case(name: str, model, contact, method: str, size: int, factor, fe_hz: np.ndarray) -> dict:
    counter = SolveCounter(factor)
    reduced, t_model = timed(lambda: bladecase.reduce(model, contact, method, size, factor=factor))
    row = {"model": f"{method} {size} ({reduced.n} dofs)", "model_s": t_model, "model_solves": counter.take()}
    for basis in ("krylov", "independent"):
        ref, t_ref = timed(lambda b=basis: reference_model(model, contact, reduced, factor, b))
        share = t_ref / (t_model + t_ref)
        row[basis] = {"reference": f"{ref.method} ({ref.n} dofs)", "seconds": t_ref, "share_of_reduce": share,
                      "solves": counter.take(),
                      "contains_model": containment(reduced, ref) if basis == "krylov" else None,
                      "lowest_hz": lowest_hz(ref).tolist()}
    row["speedup"] = row["independent"]["seconds"] / row["krylov"]["seconds"]
    row["fe_hz"] = fe_hz[:5].tolist()
    print(f"\n{name}: {row['model']}: {t_model:.2f} s, {row['model_solves']} solves with the factorisation")
    for basis in ("krylov", "independent"):
        r = row[basis]
        extra = (f", model's basis inside to {r['contains_model']:.1e}" if r["contains_model"] is not None else "")
        line(f"reference {basis} {r['reference']}",
             f"{r['seconds']:.2f} s, {r['solves']} solves, {100 * r['share_of_reduce']:.0f} % of reduce{extra}")
        line("  lowest frequencies (Hz)", " ".join(f"{f:.1f}" for f in r["lowest_hz"]))
    line("FE model's lowest frequencies (Hz)", " ".join(f"{f:.1f}" for f in fe_hz[:5]))
    line("independent / krylov time", f"{row['speedup']:.1f}x")
    line(f"krylov reference ≤ {GOAL_SHARE:.0%} of reduce", verdict(row["krylov"]["share_of_reduce"] <= GOAL_SHARE))
    return row


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", type=float, default=0.00175, help="blade mesh size in m (default 0.00175)")
    parser.add_argument("--size-r", type=int, default=20, help="reduced model size (default 20)")
    parser.add_argument("--json", metavar="FILE", type=Path, help="also write the figures to FILE (JSON)")
    args = parser.parse_args(argv)
    print("bladecase benchmark: the orbit check's reference model, Krylov extension vs independent eigen-solve")
    info: dict = {"machine": machine(), "size_m": args.size, "size_r": args.size_r}
    mesh = blade(args.size)
    rows = {}
    for name, mass, contact_kind, method in (("massless, tip face", "lumped", "face", "massless"),
                                             ("newton, tip node", "consistent", "node", "lanczos-si")):
        model, t_asm = timed(lambda m=mass: bladecase.assemble(mesh, "Ti-6Al-4V", order=2, clamp="root", mass=m))
        factor, t_fac = timed(lambda m=model: stiffness_factor(m))
        if contact_kind == "face":
            contact = Contact.face(model, "tip", [0.0, 0.0, 1.0], 1e-4)
        else:
            contact = Contact.farthest(model, [0.0, 0.0, 1.0], None, 1e-4, group="tip")
        fe_hz = bladecase.natural_frequencies(model, 5, factor=factor)
        print(f"\n{model.n_dofs} free dofs, {mass} mass: assemble {t_asm:.2f} s, factor {t_fac:.2f} s "
              f"({factor.backend})")
        rows[name] = case(name, model, contact, method, args.size_r, factor, np.asarray(fe_hz))
        rows[name].update(dofs=model.n_dofs, assemble_s=t_asm, factor_s=t_fac)
    info["cases"] = rows
    if args.json:
        args.json.write_text(json.dumps(info, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
