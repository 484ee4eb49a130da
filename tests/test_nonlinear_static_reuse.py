"""The nonlinear centrifugal state solved cheaper over a sweep of speeds (``bladecase.fe.nonlinear_static``'s
``previous``/``preconditioner``/``krylov``, ``bladecase.fe.krylov``, ``spin(previous=...)``, the rub stage's states
passed on from speed to speed).

* a warm start from the states at other speeds reaches the cold start's state and tangent to round-off (both are
  converged to the same residual test), in fewer Newton iterations and factorisations;
* the preconditioned conjugate gradients (the Krylov path) and a factorisation per Newton iteration (the direct
  path) give the same state and tangent; the direct path factorises once per iteration, the Krylov path far less;
* ``spin`` with the previous speeds' states gives the same spin state (``"nonlinear"``, ``"auto"``, ``"linear"``)
  with fewer factorisations;
* a state that cannot converge raises the same error with a warm start; bad ``previous`` are named;
* a preconditioner that does not fit (an indefinite matrix) falls back to a factorisation.
"""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest
import scipy.sparse as sp
from test_nonlinear_static import Z_AXIS, strip, swept_strip

from bladecase.fe import assemble
from bladecase.fe.krylov import ReusedFactor, pcg
from bladecase.fe.nonlinear_static import nonlinear_state
from bladecase.fe.rotation import RotationAxis, spin
from bladecase.linalg import spd_factor

RPM = math.pi / 30
#: Three speeds of the swept strip (its linear state bends it by half its length at 3000 rpm: a large rotation).
SPEEDS = (2600 * RPM, 2800 * RPM, 3000 * RPM)


@pytest.fixture(scope="module")
def strip_model():
    return swept_strip(8, 1)


def _close(a, b, rtol: float) -> float:
    """``max |a − b| / max |b|`` (vectors or sparse matrices), asserted ``<= rtol``."""
    diff = abs(a - b).max() / abs(b).max()
    assert diff <= rtol, diff
    return diff


def test_warm_start_is_the_cold_state_in_fewer_iterations(strip_model):
    w1, w2, w3 = SPEEDS
    s1, s2 = (nonlinear_state(strip_model, w, Z_AXIS) for w in (w1, w2))
    cold = nonlinear_state(strip_model, w3, Z_AXIS, krylov=False)
    assert not cold.warm and cold.factorisations == cold.iterations >= 15  # measured 19
    for previous in ([(w2, s2.displacement)], [(w1, s1.displacement), (w2, s2.displacement)]):
        warm = nonlinear_state(strip_model, w3, Z_AXIS, previous=previous, krylov=False)
        assert warm.warm and warm.steps == 1 and warm.residual <= math.sqrt(1e-9)
        # both converged to the same test: the same state and tangent to the solver's tolerance (measured 1e-14)
        _close(warm.displacement, cold.displacement, 1e-8)
        _close(warm.tangent, cold.tangent, 1e-8)
        # the nearest state scaled by Ω² (9 iterations), the two nearest extrapolated linearly in Ω² (6)
        assert warm.iterations <= (10 if len(previous) == 1 else 7) < cold.iterations
        assert warm.factorisations == warm.iterations  # the direct path
    # and with the previous speed's tangent factorised as the preconditioner: no factorisation needed at all
    pre = spd_factor(s2.tangent)
    both = nonlinear_state(strip_model, w3, Z_AXIS, previous=[(w1, s1.displacement), (w2, s2.displacement)],
                           preconditioner=pre)
    _close(both.displacement, cold.displacement, 1e-8)
    assert both.factorisations <= 1 and both.krylov_iterations > 0


def test_krylov_and_direct_paths_give_the_same_state_and_tangent(strip_model):
    w = SPEEDS[-1]
    direct = nonlinear_state(strip_model, w, Z_AXIS, krylov=False)
    krylov = nonlinear_state(strip_model, w, Z_AXIS)
    _close(krylov.displacement, direct.displacement, 1e-8)
    _close(krylov.tangent, direct.tangent, 1e-8)
    assert direct.factorisations == direct.iterations and direct.krylov_iterations == 0
    assert krylov.factorisations <= direct.factorisations / 3 and krylov.krylov_iterations > 0  # measured 4 vs 19
    # the tangent returned is the one assembled at the converged state (the problem's exact Jacobian)
    from bladecase.fe.centrifugal import _operators
    from bladecase.fe.nonlinear_static import _body

    ops = _operators(strip_model, Z_AXIS)
    K = _body(strip_model, ops).tangent(krylov.displacement) - w * w * ops.M_perp
    _close(krylov.tangent, sp.csr_array(0.5 * (K + K.T)), 1e-13)
    # a beam spun gently (hub 0.5 L): its tangent barely moves, one factorisation serves every Newton step
    beam = assemble(strip(10, 2, 1, 1.0, 0.04, 0.02, hub=0.5), "steel", order=2)
    b_direct, b_krylov = (nonlinear_state(beam, 60.0, Z_AXIS, krylov=k) for k in (False, True))
    _close(b_krylov.displacement, b_direct.displacement, 1e-8)
    assert b_krylov.factorisations == 1 < b_direct.factorisations


@pytest.mark.parametrize("static", ["nonlinear", "auto", "linear"])
def test_spin_with_the_previous_speeds(strip_model, static):
    w1, w2, w3 = SPEEDS
    alone = spin(strip_model, w3, Z_AXIS, static=static)
    earlier = [spin(strip_model, w, Z_AXIS, static=static) for w in (w1, w2)]
    swept = spin(strip_model, w3, Z_AXIS, static=static, previous=earlier)
    assert swept.static == alone.static == ("linear" if static == "linear" else "nonlinear")
    _close(swept.displacement, alone.displacement, 1e-8)
    _close(swept.model.K, alone.model.K, 1e-8)
    # alone: the probes (auto: 2), the Newton tangents and K(Ω); swept: K(Ω) and at most one more (auto: the probes
    # of a state far from the previous tangents may need one)
    assert swept.factorisations <= (2 if static == "nonlinear" else 3) < alone.factorisations or static == "linear"
    assert swept.krylov_iterations > 0 and alone.krylov_iterations >= 0
    if static == "linear":  # the linear state: one factorisation and K(Ω)'s, or the conjugate gradients and K(Ω)'s
        assert (alone.factorisations, swept.factorisations) == (2, 1)
    assert (swept.factor.solve(swept.model.K @ np.ones(strip_model.n_dofs)) == pytest.approx(1.0, abs=1e-8))


def test_auto_with_the_previous_speeds_keeps_a_linear_state_solved_to_full_accuracy(strip_model):
    """At 30 rpm ``"auto"`` keeps the linear state: decided on loosely solved probes, solved again to 1e-11."""
    slow = [spin(strip_model, w * RPM, Z_AXIS, static="auto") for w in (26, 28, 30)]
    swept = spin(strip_model, 30 * RPM, Z_AXIS, static="auto", previous=slow[:2])
    assert swept.static == slow[2].static == "linear"
    assert swept.second_order_change == pytest.approx(slow[2].second_order_change, rel=1e-4)
    # K − Ω² M⊥ of this thin strip has a condition number of 1.4e9: the factorisation's solution has a true relative
    # residual of 1.7e-8, the conjugate gradients' (1e-11 by their recurrence) 2.0e-8: both at round-off, and they
    # differ by that much (measured 1.7e-8)
    from bladecase.fe.centrifugal import _operators

    ops = _operators(strip_model, Z_AXIS)
    A, b = strip_model.K - (30 * RPM) ** 2 * ops.M_perp, (30 * RPM) ** 2 * ops.f1
    residual = [np.linalg.norm(b - A @ s.displacement) / np.linalg.norm(b) for s in (swept, slow[2])]
    assert max(residual) <= 1e-7 and residual[0] <= 3 * residual[1]
    _close(swept.displacement, slow[2].displacement, 1e-7)
    assert swept.factorisations == 1 < slow[2].factorisations  # K(Ω) only


def test_a_failing_state_raises_the_same_error_with_a_warm_start(strip_model):
    w1, w2, w3 = SPEEDS
    s2 = nonlinear_state(strip_model, w2, Z_AXIS)
    for previous in ((), [(w2, s2.displacement)]):
        with pytest.raises(ValueError, match=r"did not converge: reached .* rpm\) of 314\.159 rad/s.*relative "
                                             r"residual"):
            nonlinear_state(strip_model, w3, Z_AXIS, max_iter=1, previous=previous)
    with pytest.raises(ValueError, match=r"previous\[0\] must be a speed > 0 \(rad/s\) and 288 finite displacements"):
        nonlinear_state(strip_model, w3, Z_AXIS, previous=[(w2, s2.displacement[:-1])])
    with pytest.raises(ValueError, match=r"previous\[0\] must be a \(speed in rad/s, displacement\) pair"):
        nonlinear_state(strip_model, w3, Z_AXIS, previous=[s2.displacement])
    with pytest.raises(ValueError, match="previous states start a spinning body's state: give a speed"):
        nonlinear_state(strip_model, load=np.ones(strip_model.n_dofs), previous=[(w2, s2.displacement)])
    other = spin(strip_model, w2, RotationAxis((0, 0, 0), (0, 1, 0)))
    with pytest.raises(ValueError, match=r"previous\[0\] spins about another axis"):
        spin(strip_model, w3, Z_AXIS, previous=[other])
    with pytest.raises(ValueError, match=r"previous\[0\] must be a SpinState of this model \(288 free dofs\)"):
        spin(strip_model, w3, Z_AXIS, previous=[s2])


def test_a_preconditioner_that_does_not_fit_falls_back_to_a_factorisation():
    n = 30
    A = sp.diags_array([[-1.0] * (n - 1), [2.0] * n, [-1.0] * (n - 1)], offsets=[-1, 0, 1], format="csr")
    b = np.linspace(1.0, 2.0, n)
    shifted = sp.csr_array(A - 0.5 * sp.eye_array(n))  # indefinite: its lowest eigenvalues are < 0.5
    assert pcg(shifted, b, spd_factor(A), 1e-12)[0] is None  # negative curvature, or too slow
    solver = ReusedFactor(spd_factor(A))
    x = solver.solve(shifted, b, 1e-12, "A - I/2")
    assert solver.factorisations == 1 and np.allclose(shifted @ x, b, rtol=0, atol=1e-10)
    again = solver.solve(sp.csr_array(A - 0.49 * sp.eye_array(n)), b, 1e-12)  # not SPD: no preconditioning
    assert solver.factorisations == 2 and np.allclose((A - 0.49 * sp.eye_array(n)) @ again, b, atol=1e-10)
    direct = ReusedFactor(spd_factor(A), krylov=False)
    direct.solve(sp.csr_array(A * 1.01), b, 1e-12)
    assert (direct.factorisations, direct.iterations) == (1, 0)


def test_the_rub_stage_passes_each_speed_on_within_a_process(strip_model):
    from bladecase.study.rub.stage import _Earlier

    earlier = _Earlier()
    for w in SPEEDS:
        earlier.add(spin(strip_model, w, Z_AXIS, static="linear", previous=earlier.states))
    assert [s.speed for s in earlier.states] == list(SPEEDS[1:])  # the last two, the older without its factor
    assert earlier.states[0].factor is None and earlier.states[1].factor is not None
    assert pickle.loads(pickle.dumps(earlier)).states == []  # shipped to a worker empty


def test_each_speed_logs_its_time_and_its_centrifugal_state_solves():
    """A long sweep's progress without a progress bar (``--no-progress``): one line per speed as it ends."""
    from bladecase.log import transcript
    from bladecase.study.rub.stage import _log_point

    out = {"switches": 12, "revolutions_run": 40, "response": "settled",
           "seconds": {"state": 20.5, "reduction": 9.5, "simulation": 6.0},
           "state_solves": {"newton": 4, "factorisations": 1, "krylov": 17}}
    with transcript() as lines:
        _log_point(1014.0, out)
        _log_point(1050.0, {"error": "refused", "seconds": out["seconds"]})
    assert lines[0].endswith("rub: 1014 rad/s: 12 switches over 40 revolutions, settled; 36.0 s (centrifugal state "
                             "20.5 s, reduction 9.5 s, simulation 6.0 s); centrifugal state: 4 Newton iterations, 1 "
                             "factorisations, 17 conjugate-gradient solves")
    assert "rub: 1050 rad/s: refused (refused); 36.0 s" in lines[1]
