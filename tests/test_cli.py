"""The ``bladecase`` command line, through its entry point ``bladecase.cli.main(argv)``."""

from __future__ import annotations

import json

import numpy as np
import pytest
from _util import dense, random_spd_system

import bladecase as bc
from bladecase.cli import main

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
TWO_DOF_ARGS = ["backbone", "--chain", "2", "--k", "1", "--m", "0.5", "--gap", "1", "--periods", "1:12:111"]


def _exit_code(argv):
    """``main(argv)``'s exit code, whether returned or raised as SystemExit (argparse)."""
    try:
        return main(argv)
    except SystemExit as exc:
        return exc.code


def test_backbone_command_writes_json_png_table(tmp_path, capsys, two_dof_backbone):
    js, png, tbl = tmp_path / "bb.json", tmp_path / "bb.png", tmp_path / "out" / "bb.txt"
    rc = main(TWO_DOF_ARGS + ["--json", str(js), "--plot", str(png), "--table", str(tbl), "--no-progress"])
    assert rc == 0
    out, err = capsys.readouterr()
    # the intervals are printed (same as the API, 12 significant digits)
    assert "admissible intervals of T" in out
    for iv in two_dof_backbone.intervals:
        assert f"[{iv.T_lo:.12g}, {iv.T_hi:.12g}]" in out
    assert out.strip() == two_dof_backbone.table().strip()
    assert f"wrote json: {js}" in err and f"wrote plot: {png}" in err
    # JSON parses back, with the intervals of the API
    data = json.loads(js.read_text())
    assert set(data) >= {"ipp", "system", "linear_frequencies", "linear_periods", "orbits", "intervals"}
    assert data["ipp"] == 1 and data["system"] == {"n": 2, "gap": 1.0}
    assert len(data["orbits"]) == 111
    assert len(data["intervals"]) == 3
    for d, iv in zip(data["intervals"], two_dof_backbone.intervals):
        assert d["T_lo"] == pytest.approx(iv.T_lo, rel=1e-15) and d["T_hi"] == pytest.approx(iv.T_hi, rel=1e-15)
        assert d["refined_lo"] is True and d["refined_hi"] is True
    np.testing.assert_allclose(data["linear_periods"], [7.1887356, 2.7458527], rtol=1e-7)
    # PNG: non-empty, with the PNG signature
    blob = png.read_bytes()
    assert len(blob) > 1000 and blob[:8] == PNG_MAGIC
    # table file (parent directory created)
    assert tbl.read_text().strip() == two_dof_backbone.table().strip()
    # no temporary files left behind by the atomic writes
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bb.json", "bb.png", "out"]


def test_quiet_prints_only_intervals(capsys):
    assert main(TWO_DOF_ARGS + ["--quiet"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("admissible intervals of T")
    assert len(out.strip().splitlines()) == 1 + 3


def test_matrices_file(tmp_path, capsys):
    s = random_spd_system()
    f = tmp_path / "sys.npz"
    np.savez(f, M=dense(s.M), K=dense(s.K), w=s.w, gap=s.gap)
    js = tmp_path / "r.json"
    rc = main(["backbone", "--matrices", str(f), "--periods", "1.0:4.5:71", "--json", str(js), "--quiet"])
    assert rc == 0
    ref = bc.backbone(s, np.linspace(1.0, 4.5, 71))
    data = json.loads(js.read_text())
    assert [(d["T_lo"], d["T_hi"]) for d in data["intervals"]] == [(iv.T_lo, iv.T_hi) for iv in ref.intervals]
    assert data["system"] == {"n": 6, "gap": 0.7}
    # --gap overrides the file's gap; an integer w is a contact dof
    np.savez(f, M=dense(s.M), K=dense(s.K), w=np.array(5))
    rc = main(["backbone", "--matrices", str(f), "--gap", "0.3", "--periods", "1:2:3", "--json", str(js), "--quiet"])
    assert rc == 0
    assert json.loads(js.read_text())["system"]["gap"] == 0.3
    capsys.readouterr()


@pytest.mark.parametrize(
    "argv, match",
    [
        (["backbone", "--chain", "2", "--gap", "-1", "--periods", "1:12:10"], "gap must be a finite clearance > 0"),
        (["backbone", "--chain", "2", "--gap", "1", "--periods", "1:12"], "expected START:STOP:COUNT"),
        (["backbone", "--chain", "2", "--periods", "1:12:10"], "--gap D is required with --chain"),
        (["backbone", "--chain", "2", "--gap", "1"], "required: --periods"),
        (["backbone", "--chain", "2", "--gap", "1", "--periods", "5:1:10"], "need 0 < START <= STOP"),
        (["backbone", "--chain", "2", "--gap", "1", "--periods", "1:5:0"], "COUNT must be >= 1"),
        (["backbone", "--chain", "0", "--gap", "1", "--periods", "1:5:3"], "expected a positive integer"),
        (["backbone", "--gap", "1", "--periods", "1:5:3"], "exactly one of --chain N or --matrices"),
        (["backbone", "--chain", "2", "--k", "1,2,3", "--gap", "1", "--periods", "1:5:3"],
         "k must be a scalar or have 2"),
        (["backbone", "--chain", "2", "--k", "x", "--gap", "1", "--periods", "1:5:3"], "expected a number"),
        (["backbone", "--chain", "2", "--gap", "1", "--periods", "2:2:1", "--ipp", "2"], "period range"),
        (["backbone", "--matrices", "/nonexistent/sys.npz", "--periods", "1:5:3"], "cannot read"),
    ],
)
def test_bad_arguments_give_one_line_error(capsys, argv, match):
    rc = _exit_code(argv)
    assert rc != 0
    out, err = capsys.readouterr()
    assert err.endswith("\n") and err.count("\n") == 1, err  # exactly one line
    assert err.startswith("bladecase")
    assert "error" in err
    assert match in err
    assert "Traceback" not in err


def test_matrices_file_missing_arrays(tmp_path, capsys):
    f = tmp_path / "bad.npz"
    np.savez(f, M=np.eye(2))
    assert _exit_code(["backbone", "--matrices", str(f), "--gap", "1", "--periods", "1:5:3"]) != 0
    err = capsys.readouterr().err
    assert "lacks array(s) K, w" in err and err.count("\n") == 1


def test_no_command_prints_help(capsys):
    assert _exit_code([]) == 2
    assert "backbone" in capsys.readouterr().out


def test_main_returns_exit_code_on_parse_errors(capsys):
    assert main(["backbone", "--chain", "2", "--gap", "1", "--periods", "1:12"]) == 2


def test_backbone_ipp2_writes_json_plot_table(tmp_path, capsys):
    """--ipp 2: a table per family, JSON with the families and their arcs, a plot."""
    import json

    out = tmp_path / "m.json"
    png = tmp_path / "m.png"
    txt = tmp_path / "m.txt"
    rc = main(["backbone", "--chain", "2", "--k", "1", "--m", "0.5", "--gap", "1", "--periods", "12:14.5:6",
               "--ipp", "2", "--json", str(out), "--plot", str(png), "--table", str(txt), "--no-progress"])
    assert rc == 0
    data = json.loads(out.read_text())
    assert data["ipp"] == 2 and data["families"]
    arcs = [a for f in data["families"] for a in f["arcs"]]
    assert any(abs(a["T_hi"] - 5 * 2 * np.pi / 2.2882456112707374) < 1e-6 for a in arcs)  # the paper's point 2
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "2-ipp family" in txt.read_text() and "admissible arc" in capsys.readouterr().out


def test_log_lines_do_not_land_inside_a_progress_bar():
    """The command line's log handler writes through tqdm: the bar is cleared, the message printed on its own line,
    the bar drawn again (before, a message written mid-bar read ``…]bladecase: …``)."""
    import io
    import logging

    from tqdm import tqdm

    from bladecase.cli import _BarSafeHandler

    buf = io.StringIO()
    handler = _BarSafeHandler(buf)
    handler.setFormatter(logging.Formatter("bladecase: %(message)s"))
    record = logging.LogRecord("bladecase", logging.INFO, __file__, 1, "mesh: %d nodes", (360,), None)
    with tqdm(total=4, desc="bladecase run", file=buf, mininterval=0, ascii=True) as bar:
        bar.update(1)
        handler.emit(record)
        bar.update(1)
    out = buf.getvalue()
    at = out.index("bladecase: mesh: 360 nodes\n")
    assert at > 0 and out[at - 1] in "\r\n"            # on a line of its own, after the bar was cleared
    assert "]bladecase" not in out and "|bladecase" not in out
    assert out.rstrip().count("bladecase run") >= 2     # the bar drawn again after the message
