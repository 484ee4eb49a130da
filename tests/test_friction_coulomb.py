"""Stick–slip friction (bladecase.nsm.massless.friction_coulomb): closed forms of a tangential oscillator under a
constant normal load on a moving belt and on a casing at rest, the reduction to the rotation model when the casing
slides too fast to stick, and an independent regularised integration."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq
from test_nodes import V0, X0, chain

from bladecase.nsm import Damping
from bladecase.nsm.massless.friction import Friction, simulate_friction
from bladecase.nsm.massless.friction_coulomb import CODES, simulate_coulomb
from bladecase.nsm.massless.nodes import NodalSystem, Rub

# a normal dof (kn) pressed by a constant load F on a massless contact (stiffness kc, gap g): the normal force is
# N at rest; a tangential dof (k) hangs its massless node by a spring kt (the node's tangential compliance 1/kt)
KN, K, KC, KT, GAP, F, MU = 4.0, 1.0, 50.0, 20.0, 0.1, 3.0, 0.5
XN = (F + GAP * KC) / (KN + KC)
N = (XN - GAP) * KC


def belt(mu: float = MU) -> tuple[NodalSystem, Friction]:
    s = NodalSystem(np.eye(2), np.diag([KN, K]), np.array([[1.0], [0.0]]), np.array([[1 / KC]]), gap=[GAP])
    return s, Friction(mu, T=np.array([[0.0], [1.0]]), C_tt=[[1 / KT]], model="coulomb")


class Linear:
    """``x'' + w² x = a + b t`` from ``(x0, v0)`` at ``t0``, in closed form."""

    def __init__(self, w2, a, b, t0, x0, v0):
        self.w, self.a, self.b, self.t0 = np.sqrt(w2), a / w2, b / w2, t0
        self.A, self.B = x0 - self.a - self.b * t0, (v0 - self.b) / self.w

    def x(self, t):
        s = self.w * (t - self.t0)
        return self.a + self.b * t + self.A * np.cos(s) + self.B * np.sin(s)

    def v(self, t):
        s = self.w * (t - self.t0)
        return self.b - self.A * self.w * np.sin(s) + self.B * self.w * np.cos(s)


def first_root(f, t0, t1, h=1e-3):
    """The first sign change of ``f`` after ``t0`` (a fine grid, then Brent to round-off)."""
    t = np.arange(t0 + h, t1, h)
    y = f(t)
    i = int(np.flatnonzero(y[1:] * y[:-1] <= 0)[0])
    return brentq(f, t[i], t[i + 1], xtol=1e-15, rtol=1e-15)


def belt_closed_form(V: float, events: int) -> list[float]:
    """The stick–slip switch times from rest on a belt at ``V``: stick (``x'' + (k + kt)x = kt(z̄ + Vt)``) until
    ``kt(z̄ + Vt − x) = ±μN``, slide (``x'' + kx = σμN``) until ``x' = V``."""
    t, x, v, zbar, out, stick, sigma = 0.0, 0.0, 0.0, 0.0, [], True, 1.0
    for _ in range(events):
        if stick:
            ph = Linear(K + KT, KT * zbar, KT * V, t, x, v)
            tau = lambda s, ph=ph, zb=zbar: KT * (zb + V * s - ph.x(s))  # noqa: E731
            t_new = first_root(lambda s, tau=tau: tau(s) ** 2 - (MU * N) ** 2, t, t + 50)
            sigma = np.sign(tau(t_new))
        else:
            ph = Linear(K, sigma * MU * N, 0.0, t, x, v)
            t_new = first_root(lambda s, ph=ph: V - ph.v(s), t, t + 50)
            zbar = ph.x(t_new) + sigma * MU * N / KT - V * t_new
        t, x, v, stick = t_new, ph.x(t_new), ph.v(t_new), not stick
        out.append(t)
    return out


def test_stick_slip_on_a_moving_belt_closed_form():
    """From rest on a belt: the stick phase's duration, then each slide and stick, against the closed forms."""
    V = 0.3
    s, f = belt()
    tr = simulate_coulomb(s, f, [XN, 0.0], [0.0, 0.0], 8.0, sliding=[V], load=[F, 0.0], codes=[CODES["stick"]])
    assert tr.complete
    ref = belt_closed_form(V, 6)
    assert tr.switch_times[:6] == pytest.approx(ref, rel=1e-10, abs=1e-12)
    assert tr.codes[:, 0][np.r_[True, np.any(tr.codes[1:] != tr.codes[:-1], axis=1)]][:4].tolist() == [3, 1, 3, 1]
    x, _, lam, tau, _, zd = tr.sample(np.linspace(0.0, 8.0, 801))
    assert np.ptp(lam) < 1e-12 * N                      # the normal load stays N
    assert np.all(np.abs(tau) <= MU * N * (1 + 1e-12))  # inside the cone
    stuck = tr.stick_time(0.0, 8.0)[0]
    assert 0 < stuck < 8.0


def turning_points(X0: float, count: int) -> list[float]:
    """The closed-form turning points of a casing at rest, signed (``x_i = (−1)^i X_i``), from rest at ``X0`` with
    no tangential force: the first slide from ``½k(X0² − X1²) = ½(μN)²/kt + μN(X0 + X1 − μN/kt)``, each next one
    from a reversal on the cone, ``½k(X_i² − X²) = μN(X_i + X − 2μN/kt)`` (the energy lost: ``μN`` × the node's
    slide)."""
    mn = MU * N
    X = (-mn + np.sqrt(mn**2 + K * (K * X0**2 - 2 * mn * X0 + mn**2 / KT))) / K
    out = [X0, X]
    for _ in range(count - 1):
        X = (-mn + np.sqrt(mn**2 + K * (K * X**2 - 2 * mn * X + 4 * mn**2 / KT))) / K
        out.append(X)
    return out


def test_casing_at_rest_energy_per_cycle():
    """A casing at rest: the node slides back and forth, sticking at each reversal while its force crosses the cone.
    The turning points follow the closed-form decrement; each cycle loses ``4μN(X̄ − μN/kt)`` — ``4μNX`` of a rigid
    node — and the oscillator stops in the dead band: it turns on the same side, and stays stuck."""
    s, f = belt()
    X0 = 12.0
    tr = simulate_coulomb(s, f, [XN, X0], [0.0, 0.0], 25.0, sliding=[0.0], load=[F, 0.0])
    assert tr.complete and tr.codes[0, 0] == CODES["stick"]
    c = tr.codes[:, 0]
    into = tr.starts[1:][(c[1:] == CODES["stick"]) & (c[:-1] != CODES["stick"])]  # slide → stick: x' = 0
    ref = turning_points(X0, 6)
    count = int(np.argmax(np.array(ref) < 0))        # the first turning point on the same side: the last slide
    assert count == 6 and into.size == count
    x = tr.state(into[:count])[0][1]
    X = np.r_[X0, x * (-1.0) ** np.arange(1, count + 1)]
    assert X == pytest.approx(ref[:count + 1], rel=1e-10)
    assert np.all(tr.codes[tr.starts >= into[-1], 0] == CODES["stick"])                    # stuck for good
    loss = 0.5 * K * (X[1:-2] ** 2 - X[3:] ** 2)                 # one cycle: turning points two apart
    mean = (X[1:-2] + 2 * X[2:-1] + X[3:]) / 4
    assert loss == pytest.approx(4 * MU * N * (mean - MU * N / KT), rel=1e-10)
    assert loss[0] == pytest.approx(4 * MU * N * mean[0], rel=0.02)   # the rigid node's 4μNX, within μN/(kt X)
    # the friction's work on the vibration over a cycle, from the forces (Gauss–Legendre on each phase's pieces):
    # ∫ τ z' dt = the change of the energy ½x'² + ½kx² + ½τ²/kt
    cuts = np.r_[into[0], tr.starts[(tr.starts > into[0]) & (tr.starts < into[2])], into[2]]
    edges = np.concatenate([np.linspace(a, b, 9)[:-1] for a, b in zip(cuts[:-1], cuts[1:])] + [cuts[-1:]])
    g, w = np.polynomial.legendre.leggauss(20)
    mid, half = 0.5 * (edges[1:] + edges[:-1]), 0.5 * np.diff(edges)
    t = (mid[:, None] + half[:, None] * g).ravel()
    _, _, _, tau, _, zd = tr.sample(t)
    work = float((tau[0] * zd[0]) @ (half[:, None] * w).ravel())
    xs, v, _, tau_e, *_ = tr.sample([into[0], into[2]])
    E = 0.5 * v[1] ** 2 + 0.5 * K * xs[1] ** 2 + 0.5 * tau_e[0] ** 2 / KT
    assert E[1] - E[0] == pytest.approx(work, rel=1e-11)
    assert E[1] - E[0] == pytest.approx(-loss[0], rel=1e-11)


def test_fast_casing_is_the_rotation_model():
    """A casing sliding far faster than the nodes vibrate: every contact slides along +, never sticks; the same
    orbit as the rotation model's solver, switch for switch (two coupled contacts, damping, an out-of-round
    casing, normal–tangential compliance)."""
    T = np.array([[0.2, 0.0], [0.5, 0.1], [0.0, 0.6]])
    kw = dict(T=T, C_nt=[[0.02, 0.005], [0.0, 0.03]], C_tt=[[0.1, 0.01], [0.01, 0.08]])
    s, d, rub = chain(12.0), Damping(zeta=0.02), Rub(3, 0.3, 0.7, (0.0, 0.4))
    rot = simulate_friction(s, Friction(0.15, **kw), X0, V0, 30.0, damping=d, rub=rub)
    cou = simulate_coulomb(s, Friction(0.15, model="coulomb", **kw), X0, V0, 30.0, damping=d, rub=rub,
                           sliding=[1e6, 1e6])
    assert cou.complete and not np.any(cou.codes == CODES["stick"]) and not np.any(cou.codes == CODES["slip-"])
    assert cou.switch_times.size == rot.switch_times.size > 10
    assert np.max(np.abs(cou.switch_times - rot.switch_times)) < 1e-10
    assert np.array_equal(cou.active, rot.active)
    t = np.linspace(0.0, 30.0, 301)
    x1, v1, lam1 = rot.sample(t)
    x2, v2, lam2, tau2, *_ = cou.sample(t)
    assert np.max(np.abs(x2 - x1)) < 1e-10 * np.abs(x1).max()
    assert np.max(np.abs(lam2 - lam1)) < 1e-10 * lam1.max()
    assert np.max(np.abs(tau2 - 0.15 * lam2)) < 1e-12 * lam1.max()


@pytest.mark.parametrize("V", [0.1, 0.0])
def test_two_coupled_contacts_obey_coulomb(V):
    """Two coupled contacts, damping, an out-of-round casing and normal–tangential compliance, on a slow casing
    (0.1) and one at rest: both nodes stick and slide; along the whole run (sampled, and just after every phase
    start) the normal forces are >= 0, the friction forces in the cone, a sliding node's force along its relative
    velocity at μλ, a sticking node moving with the casing; a signal that started several at once is not missed
    (the certified search takes the earliest of them)."""
    T = np.array([[0.2, 0.0], [0.5, 0.1], [0.0, 0.6]])
    f = Friction(0.15, T=T, C_nt=[[0.02, 0.005], [0.0, 0.03]], C_tt=[[0.1, 0.01], [0.01, 0.08]], model="coulomb")
    tr = simulate_coulomb(chain(12.0), f, X0, V0, 60.0, damping=Damping(zeta=0.02), rub=Rub(3, 0.3, 0.7, (0.0, 0.4)),
                          sliding=[V, V])
    assert tr.complete and np.all(tr.stick_time() > 0.5) and np.all(tr.stick_time() < tr.contact_time())
    t = np.union1d(np.linspace(0, 60.0, 6001), np.minimum(tr.starts + 1e-9, 60.0))
    k = np.searchsorted(tr.starts, t, side="right") - 1
    codes = tr.codes[k].T
    _, _, lam, tau, _, zd = tr.sample(t)
    scale = lam.max()
    assert np.all(lam >= -1e-9 * scale) and np.all(lam[codes == 0] == 0)
    assert np.all(np.abs(tau) <= 0.15 * lam + 1e-9 * scale)
    slide = (codes == CODES["slip+"]) | (codes == CODES["slip-"])
    sigma = np.where(codes == CODES["slip+"], 1.0, -1.0)
    assert np.allclose(tau[slide], 0.15 * sigma[slide] * lam[slide], rtol=0, atol=1e-12 * scale)
    assert np.all(sigma[slide] * (V - zd[slide]) >= -1e-7)
    assert np.allclose(zd[codes == CODES["stick"]], V, rtol=0, atol=1e-9)


def stepped_belt(V: float, t_end: float, h: float) -> tuple[np.ndarray, np.ndarray]:
    """The belt oscillator integrated independently by time stepping: the trapezoidal rule (Newmark's average
    acceleration) for the mass, implicit in the node's force, and the massless node's Coulomb law by return
    mapping at each step (its position on the casing held while ``|kt(z − x)| <= μN``, else slid to the cone)."""
    mn, steps = MU * N, int(round(t_end / h))
    x, v, w = 0.0, 0.0, 0.0              # w = z − V t: the node's position relative to the casing
    a = 0.0
    xs = np.empty(steps + 1)
    xs[0] = x
    c4 = h * h / 4
    for i in range(1, steps + 1):
        t = i * h
        rhs = x + h * v + c4 * a
        c = w + V * t
        x_new = (rhs + c4 * KT * c) / (1 + c4 * (K + KT))     # sticking
        tau = KT * (c - x_new)
        if abs(tau) > mn:                                    # sliding
            tau = np.sign(tau) * mn
            x_new = (rhs + c4 * tau) / (1 + c4 * K)
            w = x_new + tau / KT - V * t
        a_new = -K * x_new + tau
        v = v + 0.5 * h * (a + a_new)
        x, a = x_new, a_new
        xs[i] = x
    return np.linspace(0.0, steps * h, steps + 1), xs


def test_time_stepping_agrees():
    """Against an independent time-stepping integrator (steps 2e-4 s and 1e-4 s, return mapping for the node): the
    displacement agrees over six stick–slip switches to 2e-8 relative (7e-9 measured), and the error falls as the
    step squared (second order)."""
    V, t_end = 0.3, 6.0
    s, f = belt()
    tr = simulate_coulomb(s, f, [XN, 0.0], [0.0, 0.0], t_end, sliding=[V], load=[F, 0.0], codes=[CODES["stick"]])
    errors = []
    for h in (2e-4, 1e-4):
        t, xr = stepped_belt(V, t_end, h)
        x = tr.state(t[::50])[0][1]
        errors.append(np.max(np.abs(x - xr[::50])) / np.abs(xr).max())
    assert errors[1] < 2e-8 and errors[1] < 0.35 * errors[0]


def stepped_rub(V: float, lobes: int, amplitude: float, speed: float, t_end: float, h: float):
    """A normal dof (kn) on its massless contact (kc) inside an out-of-round casing, ``g(t) = d + a cos(nΩt)`` (a node
    at the angle ``π/n``: open at the start), and a
    tangential dof (k) on its node's spring kt, integrated by time stepping: the trapezoidal rule, implicit in the
    contact forces — the normal one first (open or closed), then the node's Coulomb law by return mapping with the
    cone μλ of the step's end; a node that opens follows its dof, and one that closes is anchored where it touched."""
    kn, k, kc, kt, d = 4.0, 1.0, 50.0, 20.0, 0.1
    steps = int(round(t_end / h))
    xn = vn = an = xt = vt = at = 0.0
    w, closed = 0.0, False
    c4 = h * h / 4
    out = np.empty((steps + 1, 2))
    out[0] = 0.0
    for i in range(1, steps + 1):
        t = i * h
        g = d + amplitude * np.cos(lobes * speed * t)
        rn = xn + h * vn + c4 * an
        x_new = rn / (1 + c4 * kn)
        lam = 0.0
        if x_new > g:                                          # closed: λ = kc (x − g)
            x_new = (rn + c4 * kc * g) / (1 + c4 * (kn + kc))
            lam = kc * (x_new - g)
        a_new = -kn * x_new - lam
        vn, xn, an = vn + 0.5 * h * (an + a_new), x_new, a_new
        rt = xt + h * vt + c4 * at
        if lam > 0:
            if not closed:
                w, closed = xt - V * (t - h), True             # touched at the step's start, no force yet
            c = w + V * t
            x_new = (rt + c4 * kt * c) / (1 + c4 * (k + kt))
            tau = kt * (c - x_new)
            if abs(tau) > MU * lam:
                tau = np.sign(tau) * MU * lam
                x_new = (rt + c4 * tau) / (1 + c4 * k)
                w = x_new + tau / kt - V * t
        else:
            closed, tau = False, 0.0
            x_new = rt / (1 + c4 * k)
        a_new = -k * x_new + tau
        vt, xt, at = vt + 0.5 * h * (at + a_new), x_new, a_new
        out[i] = xn, xt
    return np.linspace(0.0, steps * h, steps + 1), out


def test_time_stepping_agrees_through_contact_changes():
    """The normal load varies and the contact opens and closes (an out-of-round casing), the node sticking when it
    touches, then sliding, over two contacts: the exact solution against the time-stepping integrator (steps 2e-4
    and 1e-4 s) — the normal displacement to 1e-6 of its range, the tangential one to 2.5e-4 (1.5e-4 measured: the
    integrator anchors a closing node at the step's start), both errors falling with the step."""
    lobes, amplitude, speed, V, t_end = 1, 0.25, 1.3, 0.05, 6.0
    s = NodalSystem(np.eye(2), np.diag([4.0, 1.0]), np.array([[1.0], [0.0]]), np.array([[1 / 50.0]]), gap=[0.1])
    f = Friction(MU, T=np.array([[0.0], [1.0]]), C_tt=[[1 / 20.0]], model="coulomb")
    tr = simulate_coulomb(s, f, [0.0, 0.0], [0.0, 0.0], t_end, rub=Rub(lobes, amplitude, speed, (np.pi,)),
                          sliding=[V])
    c = tr.codes[:, 0]
    assert c.tolist()[:4] == [CODES["open"], CODES["stick"], CODES["slip+"], CODES["open"]] and c.size == 7
    errors = []
    for h in (2e-4, 1e-4):
        t, ref = stepped_rub(V, lobes, amplitude, speed, t_end, h)
        errors.append(np.abs(tr.state(t)[0] - ref.T).max(axis=1) / np.ptp(ref, axis=0))
    assert errors[1][0] < 1e-6 and errors[1][1] < 2.5e-4 and np.all(errors[1] < 0.8 * errors[0])


def test_bad_input():
    s, f = belt()
    with pytest.raises(ValueError, match="tangential compliance C_tt > 0"):
        simulate_coulomb(s, Friction(0.3, T=[[0.0], [1.0]], model="coulomb"), [0.0, 0.0], [0.0, 0.0], 1.0)
    with pytest.raises(ValueError, match="codes must give each"):
        simulate_coulomb(s, f, [0.0, 0.0], [0.0, 0.0], 1.0, codes=[7])
    with pytest.raises(ValueError, match="not admissible"):
        simulate_coulomb(s, f, [0.0, 0.0], [0.0, 0.0], 1.0, codes=[CODES["slip+"]])   # open, said sliding
    with pytest.raises(ValueError, match="simulate_coulomb"):
        simulate_friction(s, f, [0.0, 0.0], [0.0, 0.0], 1.0)
