"""Full-field animation (``bladecase.viz``): off-screen pyvista frames written to GIF/MP4.

The displacement fields are synthetic but physically shaped: a cantilever-like
``(s/span)²`` bending shape along the chord, with a small stretch along the
span sized so that the contact node touches the casing (``u·n = gap``) exactly
at ``t = 0``, times ``cos(2π t/T)``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pyvista")
imageio = pytest.importorskip("imageio.v3")

import bladecase as bc
from bladecase.post import animation as viz

MESHES = Path(__file__).resolve().parents[1] / "meshes"
F = 12
PERIOD = 1.25e-3
GAP = 1e-4
BLADE_WINDOW = (321, 241)  # odd on purpose: the MP4 pads it to even


def _orbit(mesh: bc.Mesh, nframes: int = F):
    """``(u, times, impact_frames, contact_node, normal)`` of a synthetic orbit touching the casing at frame 0."""
    dim = mesh.dim
    normal = np.eye(dim)[-1]  # the span direction: +z (3-D), +y (2-D)
    s = mesh.points[:, dim - 1]
    shape = np.zeros((len(s), dim))
    shape[:, 0] = 20 * GAP * (s / s.max()) ** 2  # bending along x
    shape[:, -1] = GAP * (s / s.max()) ** 2  # stretch: the tip moves by exactly GAP along the normal
    times = np.arange(nframes) * PERIOD / nframes
    u = shape[:, :, None] * np.cos(2 * np.pi * times / PERIOD)
    impact = np.zeros(nframes, bool)
    impact[0] = True
    contact = int(mesh.group("contact")[0])
    assert np.isclose(u[contact, :, 0] @ normal, GAP, rtol=1e-12)  # the field is what the test claims
    return u, times, impact, contact, normal


def _kwargs(mesh: bc.Mesh, out: Path, **over):
    u, times, impact, contact, normal = _orbit(mesh)
    kw = dict(mesh=mesh, u=u, times=times, period=PERIOD, impact_frames=impact, contact_node=contact,
              normal=normal, gap=GAP, scale=viz.auto_scale(mesh, u), gif=out / "orbit.gif", title="test orbit")
    kw.update(over)
    return kw


@pytest.fixture(scope="module")
def plate() -> bc.Mesh:
    return bc.load_mesh(MESHES / "plate.msh")


@pytest.fixture(scope="module")
def blade() -> bc.Mesh:
    return bc.load_mesh(MESHES / "twisted_blade.msh")


@pytest.fixture(scope="module")
def blade_movie(blade, tmp_path_factory):
    """The 3-D animation, GIF and (if possible) MP4, at an odd window size (the MP4 pads it).

    321×241, not 641×481: any odd size proves the padding, and the claims of ``test_gif_frames`` hold at the
    same thresholds with room (measured at 321×241: red casing pixels 2771 at impact vs 0 at T/2, > 500 asked;
    frame std >= 53, > 10 asked; > 100 colours, > 20 asked); software rendering costs ~3× less."""
    out = tmp_path_factory.mktemp("blade") / "anim"  # a directory that does not exist yet
    kw = _kwargs(blade, out, window_size=BLADE_WINDOW, mp4=out / "orbit.mp4")
    written = viz.animate(**kw)
    return out, written, imageio.imread(written["gif"], index=None)[..., :3]


@pytest.fixture(scope="module")
def plate_movie(plate, tmp_path_factory):
    out = tmp_path_factory.mktemp("plate")
    written = viz.animate(**_kwargs(plate, out, window_size=(400, 300), fps=10.0))
    return out, written, imageio.imread(written["gif"], index=None)[..., :3]


def _red(img: np.ndarray) -> int:
    """Number of vivid red pixels (red well above green and blue; viridis and magenta have none)."""
    img = img.astype(int)
    return int((img[..., 0] - np.maximum(img[..., 1], img[..., 2]) > 80).sum())


def _colours(img: np.ndarray) -> int:
    """Number of distinct RGB colours of an image: each pixel packed into one integer (exactly the rows of
    ``np.unique(img.reshape(-1, 3), axis=0)``, without its row-wise sort, which took seconds per movie)."""
    rgb = img[..., :3].astype(np.int64)
    return int(np.unique((rgb[..., 0] << 16) | (rgb[..., 1] << 8) | rgb[..., 2]).size)


@pytest.mark.parametrize("movie, size", [("blade_movie", BLADE_WINDOW), ("plate_movie", (400, 300))])
def test_gif_frames(movie, size, request):
    out, written, frames = request.getfixturevalue(movie)
    assert written["gif"] == out / "orbit.gif" and written["gif"].is_file()
    assert frames.shape[:3] == (F, size[1], size[0])  # one frame per time, the window size
    for img in frames:  # not blank: many colours, real contrast
        assert img.std() > 10.0
        assert _colours(img) > 20
    diffs = [np.abs(frames[i].astype(int) - frames[0]).max() for i in range(1, F)]
    assert max(diffs) > 0 and min(diffs) > 0  # the blade moves (and the frame counter changes)
    # the impact frame (0) shows the red casing and the word IMPACT; the half-period frame does not
    assert _red(frames[0]) > _red(frames[F // 2]) + 500
    from PIL import Image

    with Image.open(written["gif"]) as im:  # loops forever
        assert im.info.get("loop") == 0


def test_mp4_and_no_leftovers(blade_movie):
    out, written, _ = blade_movie
    if viz.mp4_available():
        import imageio_ffmpeg

        mp4 = written["mp4"]
        assert mp4 == out / "orbit.mp4" and mp4.stat().st_size > 0
        nframes, _ = imageio_ffmpeg.count_frames_and_secs(str(mp4))
        assert nframes == F
        meta = next(imageio_ffmpeg.read_frames(str(mp4)))
        assert tuple(meta["size"]) == (BLADE_WINDOW[0] + 1, BLADE_WINDOW[1] + 1)  # odd window padded to even (yuv420p)
    else:
        assert "mp4" not in written
    assert sorted(p.name for p in out.iterdir()) == sorted(p.name for p in written.values())  # no temp files


def test_identical_frames_are_all_written(plate, tmp_path):
    """A motionless orbit (u = 0, repeated times) still gives one GIF frame per time."""
    u = np.zeros((len(plate.points), 2, 4))
    written = viz.animate(**_kwargs(plate, tmp_path, u=u, times=np.zeros(4), impact_frames=np.zeros(4, bool),
                                    scale=1.0, window_size=(200, 160)))
    assert imageio.imread(written["gif"], index=None).shape[:3] == (4, 160, 200)


def test_casing_through_the_scaled_clearance(blade):
    """The casing plane passes through the contact node + scale·gap·n, where the drawn node is at impact."""
    u, _, _, c, n = _orbit(blade)
    scale = 123.0
    warped = blade.points[:, :, None] + scale * u
    e1, e2 = viz._plane_axes(n, u, 3)
    np.testing.assert_allclose([e1 @ n, e2 @ n, e1 @ e2, e1 @ e1, e2 @ e2], [0, 0, 0, 1, 1], atol=1e-12)
    corners = viz._casing(blade.points[c] + scale * GAP * n, n, e1, e2, warped, 0.15, 3)
    np.testing.assert_allclose(corners @ n, warped[c, :, 0] @ n, rtol=1e-12)
    # it spans the drawn blade across the normal (1.5x its extent)
    flat = warped.transpose(0, 2, 1).reshape(-1, 3)
    for e in (e1, e2):
        assert np.ptp(corners @ e) == pytest.approx(1.5 * np.ptp(flat @ e), rel=1e-12)


@pytest.mark.parametrize("name", ["plate", "blade"])
def test_auto_scale(name, request):
    mesh = request.getfixturevalue(name)
    u = _orbit(mesh)[0]
    s = viz.auto_scale(mesh, u)
    diag = np.linalg.norm(mesh.points.max(axis=0) - mesh.points.min(axis=0))
    assert s * np.linalg.norm(u, axis=1).max() == pytest.approx(0.1 * diag, rel=1e-12)
    assert viz.auto_scale(mesh, u, fraction=0.3) == pytest.approx(3 * s, rel=1e-12)
    with pytest.raises(ValueError, match="zero"):
        viz.auto_scale(mesh, np.zeros_like(u))
    bad = u.copy()
    bad[0, 0, 0] = np.nan
    with pytest.raises(ValueError, match="non-finite"):
        viz.auto_scale(mesh, bad)


def _nan_u(kw):
    u = kw["u"].copy()
    u[5, 0, 3] = np.nan
    return u


@pytest.mark.parametrize(
    "change, arg",
    [
        (lambda kw: {"u": kw["u"][:, :, :1]}, "u"),  # a single frame
        (lambda kw: {"u": kw["u"][:-1]}, "u"),  # one node short
        (lambda kw: {"u": np.zeros((kw["u"].shape[0], 3, F))}, "u"),  # 3 components on a 2-D mesh
        (lambda kw: {"u": _nan_u(kw)}, "u"),
        (lambda kw: {"times": kw["times"][:-1]}, "times"),
        (lambda kw: {"times": kw["times"] + 2 * PERIOD}, "times"),
        (lambda kw: {"impact_frames": np.zeros(F + 1, bool)}, "impact_frames"),
        (lambda kw: {"scale": 0.0}, "scale"),
        (lambda kw: {"scale": -3.0}, "scale"),
        (lambda kw: {"scale": np.inf}, "scale"),
        (lambda kw: {"gap": 0.0}, "gap"),
        (lambda kw: {"period": -1.0}, "period"),
        (lambda kw: {"fps": 0.0}, "fps"),
        (lambda kw: {"contact_node": len(kw["mesh"].points)}, "contact_node"),
        (lambda kw: {"contact_node": -1}, "contact_node"),
        (lambda kw: {"normal": np.zeros(2)}, "normal"),
        (lambda kw: {"normal": [0.0, 0.0, 1.0]}, "normal"),  # out of the plane of a 2-D mesh
        (lambda kw: {"window_size": (0, 100)}, "window_size"),
    ],
)
def test_bad_inputs(plate, tmp_path, change, arg):
    kw = _kwargs(plate, tmp_path)
    kw.update(change(kw))
    with pytest.raises(ValueError, match=arg):
        viz.animate(**kw)
    assert list(tmp_path.iterdir()) == []


def test_failed_write_leaves_nothing(plate, tmp_path, monkeypatch):
    def broken(path, *args):
        Path(path).write_bytes(b"GIF89a half")
        raise OSError("disk full")

    monkeypatch.setattr(viz, "_write_gif", broken)
    with pytest.raises(OSError, match="disk full"):
        viz.animate(**_kwargs(plate, tmp_path, window_size=(160, 120)))
    assert list(tmp_path.iterdir()) == []


def test_no_offscreen_rendering_is_a_clear_error(plate, tmp_path, monkeypatch):
    import pyvista as pv

    def no_window(*args, **kwargs):
        raise RuntimeError("vtkXOpenGLRenderWindow: bad X server connection")

    monkeypatch.setattr(pv, "Plotter", no_window)
    with pytest.raises(RuntimeError, match="off-screen rendering is not available.*xvfb"):
        viz.animate(**_kwargs(plate, tmp_path))
    assert list(tmp_path.iterdir()) == []


# ----------------------------------------------------------------------------- quadratic cells (P2 models)


@pytest.fixture(scope="module", params=["plate", "blade"])
def p2_grid(request):
    """``(model, fe_grid(model))`` of a P2 model: all FE nodes, quadratic cells (the blade: conftest's, shared with
    tests/test_export.py; the fields drawn are synthetic, the material does not enter)."""
    from bladecase.post.grid import fe_grid

    if request.param == "blade":
        model = request.getfixturevalue("twisted_blade_p2")
    else:
        model = bc.assemble(request.getfixturevalue(request.param), "steel", order=2, thickness=0.002)
    return model, fe_grid(model)


def _quadratic(x: np.ndarray, dim: int, L: float) -> np.ndarray:
    """A quadratic displacement field ``(n, dim)`` of ``x / L``, exact on P2 cells."""
    y = x / L
    cols = [y[:, 1] ** 2 + 0.3 * y[:, 0] * y[:, 1], 0.5 * y[:, 0] - y[:, 1] ** 2, y[:, 0] * y[:, 2] + y[:, 2] ** 2]
    return GAP * np.column_stack(cols[:dim])


def test_quadratic_surface_interpolates_the_p2_field(p2_grid):
    """The drawn surface of quadratic cells: subdivided faces through all the boundary nodes, with the
    displacement interpolated by the quadratic shape functions (exact for a quadratic field)."""
    _, grid = p2_grid
    dim, L = grid.dim, float(np.abs(grid.points).max())
    u = _quadratic(grid.points, dim, L)
    u3 = np.zeros((len(grid.points), 3, 2))
    u3[:, :dim, 0] = u
    u3[:, :dim, 1] = -2 * u
    _, surf, ref, su = viz._surface(grid.points, grid, dim, u3)
    assert surf.n_points == len(ref) == len(su)
    if dim == 2:  # the whole plate is its surface: every node, plus the subdivision points
        assert len(ref) > len(grid.points)
    np.testing.assert_allclose(su[:, :dim, 0], _quadratic(ref, dim, L), rtol=0, atol=1e-12 * GAP)
    np.testing.assert_allclose(su[:, :, 1], -2 * su[:, :, 0], rtol=0, atol=1e-15 * GAP)
    # every node of the clamped root face (vertices and midside nodes) is a point of the drawn surface
    root = grid.points[grid.groups["root"]]
    from scipy.spatial import cKDTree

    assert cKDTree(ref).query(root)[0].max() < 1e-12 * L


def test_animate_p2_grid(p2_grid, tmp_path):
    """A P2 field on the full grid (quadratic cells) renders like a linear mesh: one moving frame per time."""
    from bladecase.post.grid import grid_index, nodal_field

    model, grid = p2_grid
    dim = grid.dim
    s = model.dofs.coords[:, dim - 1] / model.dofs.coords[:, dim - 1].max()
    shape = np.where(model.dofs.direction == 0, 20 * GAP, GAP) * s**2
    times = np.arange(4) * PERIOD / 4
    u = nodal_field(model, shape[:, None] * np.cos(2 * np.pi * times / PERIOD))
    contact = grid_index(model, int(model.mesh.group("contact")[0]))
    written = viz.animate(grid, u, times, period=PERIOD, impact_frames=np.arange(4) == 0, contact_node=contact,
                          normal=np.eye(dim)[-1], gap=GAP, scale=viz.auto_scale(grid, u), gif=tmp_path / "p2.gif",
                          window_size=(240, 180))
    frames = imageio.imread(written["gif"], index=None)[..., :3]
    assert frames.shape[:3] == (4, 180, 240)
    assert all(img.std() > 10.0 for img in frames)
    assert min(np.abs(frames[i].astype(int) - frames[0]).max() for i in range(1, 4)) > 0
    assert _red(frames[0]) > _red(frames[2])
