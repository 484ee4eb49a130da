"""Bad input to the Python API is a ValueError naming the argument, the value and what is valid (or a
RuntimeError saying what failed) — never another exception class, a hang, or a silently wrong result:
the Dask executor's scheduler addresses, the nonsmooth-mode solvers' arguments, and modes files read back
against another reduced model, another clearance, or hand-edited."""

from __future__ import annotations

import json
import math
import socket
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from skfem import MeshTri

import bladecase as bc
from bladecase.cli import main
from bladecase.fe import Mesh, assemble
from bladecase.reduction import Contact, load_reduced, reduce, save_reduced
from bladecase.study.documents import families_document, load_families, system_fingerprint
from bladecase.study.executor import DaskExecutor, make_executor

TWO_DOF = bc.chain(2, k=1.0, m=0.5, gap=1.0)


# ----------------------------------------------------------------------------- Dask scheduler addresses

def _silent_server():
    """A TCP server on 127.0.0.1 that accepts connections and never sends a byte: ``(port, stop)``."""
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(16)
    held = []

    def serve():
        while True:
            try:
                conn, _ = srv.accept()
            except OSError:
                return
            held.append(conn)

    threading.Thread(target=serve, daemon=True).start()

    def stop():
        srv.close()
        for c in held:
            c.close()

    return srv.getsockname()[1], stop


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_ucx_address_without_ucx_is_a_value_error():
    pytest.importorskip("distributed")
    try:
        import ucxx  # noqa: F401
        pytest.skip("UCX is installed here")
    except ImportError:
        pass
    with pytest.raises(ValueError) as info:
        DaskExecutor("ucx://127.0.0.1:8786")
    assert str(info.value) == ("Dask scheduler 'ucx://127.0.0.1:8786': the UCX transport is not installed (pip install "
                               "distributed-ucxx) — use tcp://host:port")
    with pytest.raises(ValueError, match="UCX transport is not installed"):
        make_executor(scheduler="ucx://10.0.0.1:13337")


def test_scheduler_that_never_answers_times_out():
    """A peer that accepts the connection and never answers: a ValueError naming the address and the time-out,
    within the time-out (Dask's own connect time-out does not bound its handshake)."""
    pytest.importorskip("distributed")
    port, stop = _silent_server()
    try:
        ex = DaskExecutor(f"tcp://127.0.0.1:{port}", timeout=0.5)
        t0 = time.monotonic()
        with pytest.raises(ValueError) as info:
            ex.map(abs, [1])
        elapsed = time.monotonic() - t0
    finally:
        stop()
    assert elapsed < 10, elapsed
    msg = str(info.value)
    assert f"'tcp://127.0.0.1:{port}'" in msg and "within 0.5 s" in msg and "handshake" in msg, msg
    assert ex._client is None


def test_refused_port_fails_fast():
    pytest.importorskip("distributed")
    port = _free_port()
    t0 = time.monotonic()
    with pytest.raises(ValueError) as info:
        DaskExecutor(f"tcp://127.0.0.1:{port}", timeout=20).map(abs, [1])
    assert time.monotonic() - t0 < 5  # not after the 20 s time-out Dask's own connect retries for
    assert str(info.value) == (f"Dask scheduler 'tcp://127.0.0.1:{port}': connection refused: no Dask scheduler "
                               f"listens on port {port} of 127.0.0.1 (start one with `dask scheduler`, or check host "
                               "and port)")


def test_peer_that_closes_or_talks_garbage():
    pytest.importorskip("distributed")
    for reply in (b"", b"HTTP/1.1 400 Bad Request\r\n\r\n"):
        srv = socket.socket()
        srv.bind(("127.0.0.1", 0))
        srv.listen(4)
        port = srv.getsockname()[1]

        def serve(srv=srv, reply=reply):
            try:
                while True:
                    conn, _ = srv.accept()
                    conn.sendall(reply)
                    conn.close()
            except OSError:
                return

        threading.Thread(target=serve, daemon=True).start()
        try:
            # the peer's answer is refused, or (a loaded machine: Dask's retries outlast the 3 s) the handshake
            # times out: either way one clear message naming the address
            with pytest.raises(ValueError, match=rf"Dask scheduler 'tcp://127\.0\.0\.1:{port}': (cannot connect to a "
                                                 "Dask scheduler there|accepted the connection but did not complete)"):
                DaskExecutor(f"tcp://127.0.0.1:{port}", timeout=3).map(abs, [1])
        finally:
            srv.close()


@pytest.mark.parametrize("address, words", [
    ("tcp://", "expected host:port after the scheme, with a port in 1..65535"),
    ("tcp://host:notaport", "got 'host:notaport'"),
    ("tcp://host", "got 'host'"),
    ("tcp://host:0", "with a port in 1..65535"),
    ("tcp://host:99999", "with a port in 1..65535"),
    ("tcp://[::1", "got '[::1'"),
    ("tcp://h:1/path", "got 'h:1/path'"),
    ("", "scheduler address is empty"),
    ("   ", "scheduler address is empty"),
    ("foo://host:1", "unknown address scheme 'foo'; valid: tcp://host:port, tls://host:port"),
    (12345, "scheduler must be an address string, got int 12345"),
    (True, "scheduler must be an address string, got bool True"),
    (["tcp://h:1"], "scheduler must be an address string, got list"),
    (object(), "scheduler must be an address string, got object"),
])
def test_malformed_scheduler_addresses(address, words):
    pytest.importorskip("distributed")
    with pytest.raises(ValueError) as info:
        DaskExecutor(address)
    assert words in str(info.value)
    with pytest.raises(ValueError, match="scheduler"):
        make_executor(scheduler=address)


def test_unknown_host_is_a_value_error():
    pytest.importorskip("distributed")
    with pytest.raises(ValueError, match=r"Dask scheduler 'tcp://no-such-host\.invalid:8786': host "
                                         r"'no-such-host\.invalid' is not known"):
        DaskExecutor("tcp://no-such-host.invalid:8786", timeout=5).map(abs, [1])


def test_address_without_scheme_is_tcp():
    pytest.importorskip("distributed")
    port = _free_port()
    assert DaskExecutor(f" 127.0.0.1:{port} ").scheduler == f"tcp://127.0.0.1:{port}"
    with pytest.raises(ValueError, match="connection refused"):
        DaskExecutor(f"127.0.0.1:{port}").map(abs, [1])


@pytest.mark.parametrize("timeout", [float("nan"), float("inf"), -1, "30", True])
def test_bad_timeout(timeout):
    with pytest.raises(ValueError, match=r"timeout must be > 0 seconds \(a finite number\)"):
        DaskExecutor("tcp://h:8786", timeout=timeout)


def test_bad_local_cluster_option():
    pytest.importorskip("distributed")
    ex = DaskExecutor(workers=1, no_such_option=3)
    with pytest.raises(ValueError, match=r"cannot start a local Dask cluster of 1 worker\(s\) with the options "
                                         r"\{'no_such_option': 3\}"):
        ex.map(abs, [1])
    ex.close()


def test_scheduler_without_workers_is_a_runtime_error():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=0, processes=False, dashboard_address=None) as cluster:
        ex = DaskExecutor(cluster.scheduler_address, timeout=0.5)
        with pytest.raises(RuntimeError, match=r"has no worker \(none joined within 0.5 s, the executor's timeout\)"):
            ex.map(abs, [1])
        assert ex._client is None


# ----------------------------------------------------------------------------- nonsmooth-mode solvers

MASSLESS = bc.bar(10, 0.5, contact="massless")


@pytest.mark.parametrize("call, words", [
    (lambda: bc.orbits_kipp(TWO_DOF, 13.5, k=100),
     "k (impacts per period) must be an integer with 1 <= k <= 8, got 100"),
    (lambda: bc.orbits_kipp(TWO_DOF, 13.5, k=9), "1 <= k <= 8, got 9"),
    (lambda: bc.orbits_kipp(TWO_DOF, 13.5, k=0), "1 <= k <= 8, got 0"),
    (lambda: bc.orbits_kipp(TWO_DOF, 13.5, k=2.0), "1 <= k <= 8, got 2.0"),
    (lambda: bc.orbits_kipp(TWO_DOF, float("nan"), 2), "period T must be finite and > 0, got nan"),
    (lambda: bc.orbits_kipp(TWO_DOF, -1.0, 2), "period T must be finite and > 0, got -1.0"),
    (lambda: bc.orbits_kipp(TWO_DOF, "13.5x", 2), "period T must be a number, got '13.5x'"),
    (lambda: bc.orbits_kipp(None, 13.5, 2), "orbits_kipp: system must be a LinearSystem"),
    (lambda: bc.orbits_kipp(np.eye(2), 13.5, 2),
     "system must be a LinearSystem (e.g. chain(...), LinearSystem(M, K, w, gap) or a reduced model's .system), got "
     "ndarray"),
    (lambda: bc.orbits_kipp(MASSLESS, 3.5, 2), "orbits_kipp solves Newton's contact model (a LinearSystem); got a "
                                               "MasslessSystem"),
    (lambda: bc.orbits_kipp(TWO_DOF, 13.5, 3, resolution=2), "resolution must be >= k = 3"),
    (lambda: bc.orbits_kipp(TWO_DOF, 13.5, 3, resolution=0), "resolution (grid points per impact time) must be None "
                                                              "or an integer with 1 <= resolution <= 1000, got 0"),
    (lambda: bc.orbits_kipp(TWO_DOF, 13.5, 3, resolution=3.5), "got 3.5"),
    (lambda: bc.orbits_kipp(TWO_DOF, 13.5, 4, resolution=1000), "resolution 1000 makes 1.66e+08 start cells for k = 4 "
                                                                 "at each period (at most 1e+06): resolution <= 183"),
    (lambda: bc.orbits_kipp(TWO_DOF, 13.5, 2, certify="no"), "certify must be True or False, got 'no'"),
])
def test_orbits_kipp_arguments(call, words):
    with pytest.raises(ValueError) as info:
        call()
    assert words in str(info.value)


@pytest.mark.parametrize("kwargs, words", [
    (dict(k=2, T_range=(13.75, 13.2)), "T_range must be (start, stop) with 0 < start < stop, got (13.75, 13.2)"),
    (dict(k=2, T_range=(float("nan"), 13.2)), "T_range must be (start, stop) with 0 < start < stop, got (nan, 13.2)"),
    (dict(k=2, T_range=(13.2, float("inf"))), "got (13.2, inf)"),
    (dict(k=2, T_range=3.0), "T_range must be (start, stop): two periods with 0 < start < stop, got 3.0"),
    (dict(k=2, T_range=(1, 2, 3)), "got (1, 2, 3)"),
    (dict(k=2, T_range="ab"), "got 'ab'"),
    (dict(k=9, T_range=(13.2, 13.75)), "1 <= k <= 8, got 9"),
    (dict(k=2, T_range=(13.2, 13.75), scan=2.5), "scan must be an integer >= 1, got 2.5"),
    (dict(k=2, T_range=(13.2, 13.75), scan=0), "scan must be an integer >= 1, got 0"),
    (dict(k=2, T_range=(13.2, 13.75), scan=-3), "scan must be an integer >= 1, got -3"),
    (dict(k=2, T_range=(13.2, 13.75), step=float("nan")), "step must be a number with 0 < step <= 1"),
    (dict(k=2, T_range=(13.2, 13.75), step=-1), "step must be a number with 0 < step <= 1"),
    (dict(k=2, T_range=(13.2, 13.75), max_points=0), "max_points must be an integer >= 2, got 0"),
    (dict(k=2, T_range=(13.2, 13.75), max_points=1.5), "max_points must be an integer >= 2, got 1.5"),
    (dict(k=2, T_range=(13.2, 13.75), refine="yes"), "refine must be True or False, got 'yes'"),
    (dict(k=3, T_range=(13.2, 13.75), resolution=1), "resolution must be >= k = 3"),
])
def test_nonsmooth_mode_arguments(kwargs, words):
    with pytest.raises(ValueError) as info:
        bc.nonsmooth_mode(TWO_DOF, **kwargs)
    assert words in str(info.value)


def test_nonsmooth_mode_system_type():
    with pytest.raises(ValueError, match="nonsmooth_mode: system must be a LinearSystem .* or a MasslessSystem, got "
                                         "NoneType"):
        bc.nonsmooth_mode(None, 2, (13.2, 13.75))
    with pytest.raises(ValueError, match="max_points must be an integer >= 2, got 0"):
        bc.nonsmooth_mode(MASSLESS, 1, (3.2, 4.1), max_points=0)


def test_the_default_resolution_keeps_the_grid_bounded():
    """k = 8 with the default resolution of a stiff system: the grid is cut to MAX_GRID_CELLS cells, not 6e7."""
    from bladecase.nsm.newton import kipp

    assert kipp._largest_resolution(8) == 28 and math.comb(27, 7) <= kipp.MAX_GRID_CELLS < math.comb(28, 7)
    assert kipp._largest_resolution(3) == kipp.MAX_RESOLUTION


@pytest.mark.parametrize("call, words", [
    (lambda: bc.massless_mode(MASSLESS, (4.1, 3.2)), "T_range must be (start, stop) with 0 < start < stop, got "
                                                    "(4.1, 3.2)"),
    (lambda: bc.massless_mode(MASSLESS, (float("nan"), 3.2)), "got (nan, 3.2)"),
    (lambda: bc.massless_mode(MASSLESS, (-1.0, 3.2)), "got (-1.0, 3.2)"),
    (lambda: bc.massless_mode(MASSLESS, (3.2, float("inf"))), "got (3.2, inf)"),
    (lambda: bc.massless_mode(MASSLESS, 3.2), "T_range must be (start, stop): two periods"),
    (lambda: bc.massless_mode(MASSLESS, (3.2, 4.1), mode=1.5), "mode must be an open-phase mode index, an integer "
                                                               "in [0, 9), got 1.5"),
    (lambda: bc.massless_mode(MASSLESS, (3.2, 4.1), mode=True), "got True"),
    (lambda: bc.massless_mode(MASSLESS, (3.2, 4.1), mode="a"), "got 'a'"),
    (lambda: bc.massless_mode(MASSLESS, (3.2, 4.1), mode=9), "got 9"),
    (lambda: bc.massless_mode(MASSLESS, (3.2, 4.1), max_points=2.5), "max_points must be an integer >= 2, got 2.5"),
    (lambda: bc.massless_mode(TWO_DOF, (3.2, 4.1)), "massless_mode solves the massless contact model: system must be "
                                                    "a MasslessSystem"),
    (lambda: bc.massless_mode(None, (3.2, 4.1)), "got NoneType"),
])
def test_massless_mode_arguments(call, words):
    with pytest.raises(ValueError) as info:
        call()
    assert words in str(info.value)


def test_massless_orbit_helpers_arguments():
    from bladecase.nsm.massless.follow import follow_mode
    from bladecase.nsm.massless.orbits import follow_from_grazing, orbit_at_period, orbits_at_period

    with pytest.raises(ValueError, match="T must be a finite number > 0, got 'a'"):
        orbits_at_period(MASSLESS, "a")
    with pytest.raises(ValueError, match="samples must be None or an integer >= 3, got 'x'"):
        orbits_at_period(MASSLESS, 3.5, samples="x")
    with pytest.raises(ValueError, match="orbits_at_period solves the massless contact model"):
        orbits_at_period(TWO_DOF, 3.5)
    with pytest.raises(ValueError, match=r"mode must be an open-phase mode index, an integer in \[0, 9\), got 12"):
        follow_from_grazing(MASSLESS, 3.0, mode=12)
    with pytest.raises(ValueError, match="beta0 must be a finite number > 0, got nan"):
        orbit_at_period(MASSLESS, 3.5, float("nan"))
    with pytest.raises(ValueError, match="follow_mode: start must be a PhasedOrbit"):
        follow_mode(MASSLESS, None, (3.2, 4.1))


@pytest.mark.parametrize("call, words", [
    (lambda: bc.backbone(TWO_DOF, [[1.0, 2.0], [3.0, 4.0]]), "periods must be a 1-D sequence of periods, got an "
                                                             "array of shape (2, 2)"),
    (lambda: bc.backbone(TWO_DOF, "abc"), "periods must be a sequence of periods (numbers > 0), got 'abc'"),
    (lambda: bc.backbone(TWO_DOF, None), "got None"),
    (lambda: bc.backbone(TWO_DOF, [1.0, 2.0], ipp=1.0), "ipp (impacts per period) must be the integer 1, got 1.0"),
    (lambda: bc.backbone(None, [1.0, 2.0]), "backbone: system must be a LinearSystem"),
    (lambda: bc.backbone(MASSLESS, [1.0, 2.0]), "backbone solves Newton's contact model"),
    (lambda: bc.orbit_1ipp(MASSLESS, 3.0), "orbit_1ipp solves Newton's contact model"),
    (lambda: bc.make_orbit(TWO_DOF, 6.0, [7.0], [1.0]), "make_orbit: impact_times must satisfy 0 < t1 < ... < tk = "
                                                        "T = 6.0, got [7.0]"),
    (lambda: bc.make_orbit(TWO_DOF, 6.0, [3.0, 6.0], [1.0]), "got 2 time(s) and 1 impulse(s)"),
    (lambda: bc.make_orbit(TWO_DOF, 6.0, [], []), "got 0 time(s) and 0 impulse(s)"),
    (lambda: bc.make_orbit(TWO_DOF, float("nan"), [6.0], [1.0]), "make_orbit: period T must be finite and > 0"),
])
def test_scan_and_orbit_arguments(call, words):
    with pytest.raises(ValueError) as info:
        call()
    assert words in str(info.value)


Z2 = np.zeros(2)


@pytest.mark.parametrize("call, words", [
    (lambda: bc.simulate_forced(None, Z2, Z2, 10.0), "simulate_forced: system must be a LinearSystem"),
    (lambda: bc.simulate_forced(MASSLESS, np.zeros(9), np.zeros(9), 10.0), "simulate_forced_massless"),
    (lambda: bc.simulate_forced(TWO_DOF, Z2, Z2, "a"), "t_end must be a finite number > 0, got 'a'"),
    (lambda: bc.simulate_forced(TWO_DOF, Z2, Z2, 10.0, period="a", amplitude=1.0), "period must be a finite number "
                                                                                   "> 0, got 'a'"),
    (lambda: bc.simulate_forced(TWO_DOF, Z2, Z2, 10.0, period=3.0, amplitude="a"), "amplitude must be a finite "
                                                                                   "number, got 'a'"),
    (lambda: bc.simulate_forced(TWO_DOF, Z2, Z2, 10.0, restitution="a"), "restitution must be a number in (0, 1]"),
    (lambda: bc.simulate_forced(TWO_DOF, Z2, Z2, 10.0, period=3.0, amplitude=1.0, load="ab"),
     "load must be a finite vector of 2 entries"),
    (lambda: bc.simulate_forced(TWO_DOF, "ab", Z2, 10.0), "x0 must be a vector of 2 finite numbers"),
    (lambda: bc.simulate_forced(TWO_DOF, Z2, None, 10.0), "v0 must be a vector of 2 finite numbers"),
    (lambda: bc.Damping(zeta="a"), "zeta must be a damping ratio >= 0 or a sequence of them, got 'a'"),
    (lambda: bc.Damping(zeta=[]), "zeta must be a damping ratio >= 0 or a sequence of them, got []"),
    (lambda: bc.forced_point(None, 4.5), "forced_point: system must be a LinearSystem"),
    (lambda: bc.forced_point(TWO_DOF, None), "forcing period T must be a finite number, got None"),
    (lambda: bc.forced_point(TWO_DOF, 4.5, tol="a", n_periods=20), "tol must be a finite number, got 'a'"),
    (lambda: bc.forced_point(MASSLESS, 4.5, contact_load="a", n_periods=20), "contact_load must be a finite number"),
    (lambda: bc.forced_sweep(TWO_DOF, "abc", n_periods=20), "periods must be a sequence of forcing periods"),
    (lambda: bc.forced_sweep(TWO_DOF, None, n_periods=20), "got None"),
    (lambda: bc.forced_sweep(TWO_DOF, [4.5, float("nan")], n_periods=20), "periods must be finite forcing periods > 0"),
    (lambda: bc.forced_sweep(TWO_DOF, [4.5], n_periods=20, continuation=False, executor=3),
     "executor must have a map(fn, items, desc=, progress=) method"),
    (lambda: bc.forced_sweep(TWO_DOF, [4.5], n_periods=20, continuation="no"), "continuation must be True or False"),
    (lambda: bc.forced_sweep(None, [4.5], n_periods=20), "forced_sweep: system must be a LinearSystem"),
])
def test_forced_arguments(call, words):
    with pytest.raises(ValueError) as info:
        call()
    assert words in str(info.value)


# ----------------------------------------------------------------------------- modes files

def _strip_reduced(gap: float, size: int):
    t = MeshTri.init_tensor(np.linspace(0, 0.1, 21), np.linspace(0, 0.02, 5)).oriented()
    points = np.c_[t.p.T, np.zeros(t.p.shape[1])]
    mesh = Mesh(points, {"triangle": t.t.T}, dim=2, groups={"root": np.flatnonzero(points[:, 0] == 0)},
                source="strip")
    model = assemble(mesh, "steel", order=1, thickness=0.002)
    return reduce(model, Contact.nearest(model, (0.1, 0.02), normal=(0.0, 1.0), gap=gap), "modal", size)


@pytest.fixture(scope="module")
def strips(tmp_path_factory) -> dict:
    """A 2-D steel strip reduced to 4 modes at a clearance of 1e-4 m (its modes file), the same at 2e-4 m, and
    reduced to 3 modes: as stage files."""
    folder = tmp_path_factory.mktemp("strips")
    out = {}
    for name, gap, size in (("main", 1e-4, 4), ("clearance", 2e-4, 4), ("size", 1e-4, 3)):
        reduced = _strip_reduced(gap, size)
        save_reduced(reduced, folder / f"{name}.npz")
        out[name] = {"path": folder / f"{name}.npz", "system": reduced.system}
    system = out["main"]["system"]
    branch = bc.backbone(system, np.linspace(0.5, 0.9999, 40) * system.spectrum.periods[0])
    assert branch.arcs and not branch.admissible.all(), "the fixture needs admissible and inadmissible orbits"
    out["doc"] = families_document([branch], system)
    out["branch"] = branch
    return out


def _write(tmp_path, doc) -> Path:
    path = tmp_path / "modes.json"
    path.write_text(json.dumps(doc))
    return path


def test_fingerprint_is_of_the_system(strips):
    a = strips["main"]["system"]
    fp = system_fingerprint(a)
    assert strips["doc"]["system_fingerprint"] == fp and fp.startswith("sha256:") and len(fp) == 71
    assert system_fingerprint(load_reduced(strips["main"]["path"]).system) == fp  # the file's system: the same
    assert system_fingerprint(bc.LinearSystem(a.M.toarray() if hasattr(a.M, "toarray") else a.M, a.K, a.w,
                                              a.gap)) == fp  # dense or sparse: the same
    assert system_fingerprint(strips["clearance"]["system"]) != fp
    assert system_fingerprint(strips["size"]["system"]) != system_fingerprint(strips["main"]["system"])
    assert system_fingerprint(MASSLESS) != system_fingerprint(bc.bar(10, 0.5, contact="massless", casing=1e3))
    with pytest.raises(ValueError, match="system must be a LinearSystem or a MasslessSystem"):
        system_fingerprint(np.eye(2))


def test_modes_file_reads_back_on_its_own_system(tmp_path, strips):
    path = _write(tmp_path, strips["doc"])
    back = load_families(path, load_reduced(strips["main"]["path"]).system)
    assert np.array_equal(back[0].T, strips["branch"].T)
    assert np.array_equal(back[0].admissible, strips["branch"].admissible)


def test_modes_file_of_another_clearance_refused(tmp_path, strips):
    path = _write(tmp_path, strips["doc"])
    with pytest.raises(ValueError) as info:
        load_families(path, strips["clearance"]["system"], reduced="R.npz")
    msg = str(info.value)
    assert msg.startswith(f"modes file {str(path)!r} was computed for another reduced model or clearance (fingerprint "
                          "sha256:")
    assert "its clearance is 0.0001, this model's 0.0002" in msg
    assert msg.endswith("run `bladecase modes` again on R.npz")


def test_modes_file_of_another_reduced_model_refused(tmp_path, strips):
    doc = dict(strips["doc"], system_dofs=3)  # even with the size edited to match
    path = _write(tmp_path, doc)
    with pytest.raises(ValueError, match="was computed for another reduced model or clearance"):
        load_families(path, strips["size"]["system"])


def test_modes_file_without_fingerprint_refused(tmp_path, strips):
    doc = {k: v for k, v in strips["doc"].items() if k != "system_fingerprint"}
    with pytest.raises(ValueError) as info:
        load_families(_write(tmp_path, doc), strips["main"]["system"])
    assert "has no fingerprint of the system it was computed on: it was written by an older bladecase version" \
        in str(info.value)
    assert str(info.value).endswith("run `bladecase modes` again on the reduced model")


def _first(doc, admissible: bool) -> tuple[int, dict]:
    """The first orbit of the file's family that is (not) admissible, with non-negative impulses."""
    orbits = doc["families"][0]["orbits"]
    j = next(j for j, o in enumerate(orbits)
             if not o.get("resonant") and o["admissible"] == admissible and min(o["impulses"]) >= 0)
    return j, orbits[j]


def test_hand_edited_orbit_marked_admissible_refused(tmp_path, strips):
    """An orbit that crosses the casing, marked admissible by hand: refused, naming the family and the period."""
    doc = json.loads(json.dumps(strips["doc"]))
    j, orbit = _first(doc, admissible=False)
    orbit["admissible"] = True
    with pytest.raises(ValueError) as info:
        load_families(_write(tmp_path, doc), strips["main"]["system"])
    msg = str(info.value)
    assert f"family 0 (1-ipp), orbit {j} at T = {orbit['T']:.10g} is marked admissible but is not an admissible " \
           "orbit of this system: it crosses the casing" in msg, msg


@pytest.mark.parametrize("field, change, words", [
    ("impulses", lambda v: [0.5 * x for x in v], "do not solve the orbit equations of this system"),
    ("impulses", lambda v: [-x for x in v], "do not solve the orbit equations"),
    ("impact_times", lambda v: [0.5 * v[0]], "impact data do not define an orbit here"),
    ("T", lambda v: 1.01 * v, "impact data do not define an orbit here"),
    ("energy", lambda v: 2.0 * v, "its energy"),
])
def test_hand_edited_admissible_orbit_refused(tmp_path, strips, field, change, words):
    doc = json.loads(json.dumps(strips["doc"]))
    j, orbit = _first(doc, admissible=True)
    orbit[field] = change(orbit[field])
    with pytest.raises(ValueError) as info:
        load_families(_write(tmp_path, doc), strips["main"]["system"])
    msg = str(info.value)
    assert f"family 0 (1-ipp), orbit {j} at T = " in msg and "is marked admissible but is not" in msg, msg
    assert words in msg, msg


def test_families_document_arguments(strips):
    with pytest.raises(ValueError, match="families_document: system must be a LinearSystem or a MasslessSystem"):
        families_document([strips["branch"]], None)
    with pytest.raises(ValueError, match="family 0 must be a Branch, got dict"):
        families_document([{}], strips["main"]["system"])
    with pytest.raises(ValueError, match=r"family 0 \(1-ipp\) was computed on another system"):
        families_document([strips["branch"]], strips["clearance"]["system"])
    with pytest.raises(ValueError, match="families must be a list of Branch"):
        families_document(strips["branch"], strips["main"]["system"])


def test_massless_modes_file_round_trip_and_edit(tmp_path, bar10_massless_mode):
    branch = bar10_massless_mode  # conftest's: massless_mode(MASSLESS, (3.2, 4.1)), on a bar equal to MASSLESS
    doc = families_document([branch], MASSLESS)
    back = load_families(_write(tmp_path, doc), MASSLESS)
    assert [o.T for o in back[0].orbits] == [o.T for o in branch.orbits]
    doc["families"][0]["orbits"][1]["a"] = [1.1 * x for x in doc["families"][0]["orbits"][1]["a"]]
    with pytest.raises(ValueError, match=r"family 0 \(1-ipp\), orbit 1 at T = .* do not solve the orbit equations"):
        load_families(_write(tmp_path, doc), MASSLESS)
    with pytest.raises(ValueError, match="was computed for another reduced model or clearance"):
        load_families(_write(tmp_path, families_document([branch], MASSLESS)), bc.bar(10, 0.4, contact="massless"))


def test_animate_with_the_modes_file_of_another_clearance(tmp_path, strips, capsys):
    """The command line: one error line and exit 2, nothing animated."""
    from _studies import PLATE, absolute

    study = tmp_path / "plate.toml"
    study.write_text(absolute(PLATE) + "[output]\nformats = []\nreference = false\nframes = 4\n")
    modes = _write(tmp_path, strips["doc"])
    code = main([str(a) for a in ["animate", study, "--reduced", strips["clearance"]["path"], "--modes", modes,
                                  "--out", tmp_path / "anim", "--quiet", "--no-progress"]])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err, err
    assert "was computed for another reduced model or clearance" in err, err
    assert not (tmp_path / "anim").exists() or not any((tmp_path / "anim").iterdir())


def _die(x):
    import os

    os._exit(3)


def test_a_worker_dying_is_a_runtime_error():
    """Dask's own KilledWorker (the worker running the task died) is a RuntimeError naming the item."""
    dask = pytest.importorskip("dask")
    pytest.importorskip("distributed")
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}), DaskExecutor(workers=1) as ex:
        with pytest.raises(RuntimeError, match=r"tasks 0 \(item 7\) did not run on the Dask cluster \(a local "
                                               r"cluster\): the workers running it died"):
            ex.map(_die, [7])
