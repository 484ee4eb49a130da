"""The demo's face contact meets the casing through its mean; its nodes are reported one by one: the summary's
excursion against the written VTK frames (read back with meshio), and the invariants of a mean."""

from __future__ import annotations

import json

import meshio
import numpy as np
import pytest

from bladecase.study import run
from bladecase.study.demo import demo_text
from bladecase.study.schema import loads


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    text = demo_text().replace('formats = ["gif", "mp4", "vtu", "png"]', 'formats = ["vtu"]')
    text = text.replace("animate = 2", "animate = 1").replace("frames = 40", "frames = 80")
    return run(loads(text + "\n", source="demo"), tmp_path_factory.mktemp("tip") / "out", progress=False)


def test_the_face_nodes_run_beyond_the_clearance_the_mean_meets(demo):
    a = demo.summary["files"]["animations"][0]
    x = a["tip_excursion"]
    assert x["nodes"] == len(demo.summary["contact"]["face_nodes"]) > 10
    # a weighted mean never exceeds its largest member
    assert x["node_max_m"] >= x["mean_max_m"]
    # the demo's compliant casing lets the mean go beyond the clearance; the tip's corners go much farther
    assert 0 < x["mean_max_m"] < x["node_max_m"] and x["node_max_m"] > 3 * x["mean_max_m"]
    assert 0 < x["nodes_beyond"] <= x["nodes"]
    assert "Tip nodes beyond the clearance" in (demo.directory / "report.md").read_text()
    assert json.loads((demo.directory / "summary.json").read_text())["files"]["animations"][0]["tip_excursion"] == x


def test_the_excursion_agrees_with_the_written_frames(demo):
    """The VTK time series (80 frames, the true displacement on every FE node) read back: the largest ν·u − d over
    the frames and the face's nodes is the summary's, to the sampling (400 instants vs 80 frames)."""
    a = demo.summary["files"]["animations"][0]
    x = a["tip_excursion"]
    c = demo.summary["contact"]
    series = demo.directory / a["pvd"]
    frames = sorted((series.parent / series.stem).glob("*.vtu"))
    assert len(frames) == 80
    position = np.array(c["position"])
    normal = np.array(c["normal"])
    face = None
    top = -np.inf
    for path in frames:
        m = meshio.read(path)
        if face is None:  # the face nodes: the grid points of the tip group
            face = np.flatnonzero(m.point_data["group:tip"] > 0)
            assert face.size >= x["nodes"]
            assert np.abs((m.points[face] - position) @ normal).max() < 1e-9  # a flat tip face
        top = max(top, float((m.point_data["displacement"][face] @ normal).max()))
    excess = top - x["clearance_m"]
    assert excess <= x["node_max_m"] * (1 + 1e-6) + 1e-12  # frames are instants of the same period
    assert excess == pytest.approx(x["node_max_m"], rel=0.1)


def test_the_animation_marks_the_face_nodes_past_their_clearance(demo, tmp_path):
    """The scene carries, frame by frame, the face nodes past their own clearance (red dots in the GIF): the nodes
    marked at some frame are the summary's nodes beyond the clearance, and the GIF renders with them."""
    from bladecase.post import animation
    from bladecase.study.choose import choose_orbits
    from bladecase.study.render import orbit_scene
    from bladecase.study.stages import period_unit

    model = next(iter(demo.models.values()))
    reduced = model.reduced
    study = loads(demo_text().replace("frames = 40", "frames = 80") + "\n", source="demo")
    unit, _ = period_unit(study, reduced.system)
    (choice,) = choose_orbits(study, demo.families, unit)[:1]
    scene = orbit_scene(study, reduced, demo.families, choice)
    x = demo.summary["files"]["animations"][0]["tip_excursion"]
    assert scene.face_beyond.shape == (x["nodes"], 80)
    assert int(scene.face_beyond.any(axis=1).sum()) == pytest.approx(x["nodes_beyond"], abs=1)  # 80 frames vs 400
    assert not scene.face_beyond.all()                                     # open frames: nobody past it
    out = animation.animate(scene.mesh, scene.u[:, :, ::8], scene.times[::8], period=scene.orbit.T,
                            impact_frames=scene.impact[::8], contact_node=scene.contact_node, normal=scene.normal,
                            gap=scene.gap, scale=scene.scale, gif=tmp_path / "a.gif", window_size=(320, 240),
                            marks=scene.face_points, marked=scene.face_beyond[:, ::8])
    assert out["gif"].stat().st_size > 0
