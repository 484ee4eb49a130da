"""Full-field animation of a periodic impact orbit: the blade warped over one period, with the casing.

:func:`animate` renders every frame off-screen with pyvista (one plotter, the
actors updated in place) and writes a looping GIF, plus an MP4 when
imageio-ffmpeg is installed (:func:`mp4_available`).  :func:`auto_scale` picks
an amplitude scale that makes the motion visible.  pyvista, Pillow and
imageio-ffmpeg are imported only when a function needs them.
"""

from __future__ import annotations

import math
import numbers
import os
import warnings
from pathlib import Path

import numpy as np

from .. import log
from ..fe import Mesh
from ..fe.cells import KINDS
from ..io import atomic_path
from .grid import vtk_cells

_FIELD = "magnitude of u (m)"  # VTK's fonts draw no "|"

#: Subdivision level of the faces of quadratic cells when drawn (each level splits a face in 4).
SUBDIVISION = 2


def mp4_available() -> bool:
    """``True`` if imageio-ffmpeg is importable and finds an ``ffmpeg`` executable."""
    try:
        import imageio_ffmpeg

        return bool(imageio_ffmpeg.get_ffmpeg_exe())
    except Exception:  # not installed, or no binary for this platform
        return False


def auto_scale(mesh: Mesh, u: np.ndarray, fraction: float = 0.1) -> float:
    """Amplitude scale that draws the largest displacement as ``fraction`` of the mesh bounding-box diagonal.

    Parameters
    ----------
    mesh : Mesh
    u : (n_nodes, dim, ...) ndarray
        Displacements (any number of trailing frame axes).
    fraction : float
        Target drawn size of ``max |u|`` relative to the bounding-box diagonal.

    Raises
    ------
    ValueError
        ``u`` not finite or all zero, ``fraction`` not positive.
    """
    u = np.asarray(u, dtype=float)
    if not (math.isfinite(fraction) and fraction > 0):
        raise ValueError(f"fraction must be a finite number > 0, got {fraction!r}")
    if u.ndim < 2 or u.shape[0] != len(mesh.points) or u.shape[1] != mesh.dim:
        raise ValueError(f"u must have shape ({len(mesh.points)}, {mesh.dim}, ...), got {u.shape}")
    if not np.all(np.isfinite(u)):
        raise ValueError("u has non-finite values (NaN or inf); cannot choose a scale")
    umax = float(np.linalg.norm(u, axis=1).max())
    if umax == 0.0:
        raise ValueError("u is zero everywhere; no amplitude scale makes it visible")
    return fraction * float(np.linalg.norm(np.ptp(mesh.points, axis=0))) / umax


def animate(
    mesh: Mesh,
    u: np.ndarray,
    times: np.ndarray,
    *,
    period: float,
    impact_frames: np.ndarray,
    contact_node: int,
    normal: np.ndarray,
    gap: float,
    scale: float,
    gif: str | os.PathLike,
    mp4: str | os.PathLike | None = None,
    title: str = "",
    window_size: tuple[int, int] = (800, 600),
    fps: float = 20.0,
    contact_label: str = "IMPACT",
    marks: np.ndarray | None = None,
    marked: np.ndarray | None = None,
) -> dict[str, Path]:
    """Render the blade over one period of an impact orbit to a looping GIF (and an MP4).

    Each frame shows the blade surface warped by ``scale * u`` and coloured by
    the true ``|u|`` (m, colour range fixed to ``[0, max |u|]``), the faint
    undeformed outline, the contact node, and the casing: the plane normal to
    ``normal`` through ``points[contact_node] + scale * gap * normal`` (drawn
    at the same scale, so the contact node touches it exactly at impact); it
    turns red, with the word ``contact_label`` (IMPACT), on the impact frames.  Text gives the
    title, frame number, ``t/T``, ``T``, ``f`` and the scale.  The camera is
    fixed and frames every warped position.

    Parameters
    ----------
    mesh : Mesh
        Body cells of any type of :data:`~bladecase.post.grid.VTK_CELL_TYPES`: tetrahedra, hexahedra, wedges
        (3-D) or triangles, quadrilaterals (2-D, ``z = 0``), of first or second order (``tetra10``,
        ``hexahedron20``/``27``, ``wedge15``/``18``, ``triangle6``, ``quad8``/``9``).
        Quadratic cells are drawn with all their nodes: their faces are
        subdivided (:data:`SUBDIVISION`) and ``u`` is interpolated by the
        quadratic shape functions, so a P2 field shows its bending within a
        cell and a curved cell its curved faces.  To draw everything a model
        computed, pass :func:`bladecase.post.grid.fe_grid` and
        :func:`bladecase.post.grid.nodal_field`.
    u : (n_nodes, dim, F) ndarray
        Displacement of every node at the ``F >= 2`` frames (m).
    times : (F,) ndarray
        Frame times in ``[0, period]``, shown as ``t/T``.
    period : float
        Period ``T`` of the orbit (s).
    impact_frames : (F,) bool ndarray
        The frames that are impact instants.
    contact_node : int
        Node index of the contact point.
    normal : (dim,) or (3,) ndarray
        Casing normal, from the blade towards the casing (normalised here).
    gap : float
        Clearance (m) between the contact node at rest and the casing.
    scale : float
        Amplitude scale of the drawing (see :func:`auto_scale`).
    gif, mp4 : path-like
        Output files (parent directories are created; written atomically).
        The MP4 is skipped, with a warning, if imageio-ffmpeg is missing.
    title : str
    window_size : (width, height)
        Pixel size of every frame.
    fps : float
        Frames per second.
    contact_label : str
        The word shown on the frames of ``impact_frames``: ``"IMPACT"`` (Newton's law), ``"CONTACT"`` for the
        frames inside a contact phase of the massless model.
    marks, marked : (k,) int array and (k, n_frames) bool array, optional
        Nodes drawn as red dots on the frames where ``marked`` holds them (a contact face's nodes past their own
        clearance: where the tip rubs).

    Returns
    -------
    dict
        ``{"gif": Path, "mp4": Path}`` — ``"mp4"`` only if it was written.

    Raises
    ------
    ValueError
        Inconsistent or invalid arguments (the message names the argument).
    RuntimeError
        Off-screen rendering is not available.
    """
    pts = np.asarray(mesh.points, dtype=float)
    n, dim = len(pts), mesh.dim
    u, times, impact, normal, window_size = _check(
        n, dim, u, times, period, impact_frames, contact_node, normal, gap, scale, fps, window_size
    )
    nframes = u.shape[2]
    u3 = np.zeros((n, 3, nframes))
    u3[:, :dim] = u
    mag = np.linalg.norm(u3, axis=1)  # (n, F) true |u|
    umax = float(mag.max()) or 1.0
    warped = pts[:, :, None] + scale * u3  # (n, 3, F)
    e1, e2 = _plane_axes(normal, u3, dim)
    size = float(np.linalg.norm(np.ptp(pts, axis=0)))
    corners = _casing(pts[contact_node] + scale * gap * normal, normal, e1, e2, warped, size, dim)
    lo = np.minimum(warped.min(axis=(0, 2)), corners.min(axis=0))
    hi = np.maximum(warped.max(axis=(0, 2)), corners.max(axis=0))
    bounds = np.column_stack([lo, hi]).ravel().tolist()  # of every drawn frame: the camera frames them all

    texts = [
        f"T = {period:.4g} s   f = {1.0 / period:.4g} Hz",
        f"displacements \u00d7 {scale:.4g} (casing at clearance {_length(gap)}, same scale)",
    ]
    if marks is not None:
        marks = np.asarray(marks, dtype=int)
        marked = np.asarray(marked, dtype=bool)
        if marks.ndim != 1 or marked.shape != (marks.size, nframes) or (marks.size and not
                                                                          0 <= marks.min() <= marks.max() < n):
            raise ValueError(f"marks must be node indices (k,) with marked of shape (k, {nframes}), got "
                             f"{marks.shape} and {marked.shape}")
        texts.append("red dots: face nodes past their own clearance")
    frames = _render(pts, mesh, dim, u3, scale, warped, umax, corners, contact_node, impact, times / period, title,
                     texts, window_size, size, bounds, normal, e1, contact_label, marks, marked)
    out = {"gif": Path(gif)}
    with atomic_path(gif) as tmp:
        _write_gif(tmp, frames, impact, fps)
    if mp4 is not None:
        if mp4_available():
            with atomic_path(mp4) as tmp:
                _write_mp4(tmp, frames, fps)
            out["mp4"] = Path(mp4)
        else:
            warnings.warn("MP4 not written: imageio-ffmpeg is not installed (pip install imageio-ffmpeg)", stacklevel=2)
    return out


def _check(n, dim, u, times, period, impact_frames, contact_node, normal, gap, scale, fps, window_size):
    """Validated ``(u, times, impact, unit 3-D normal, window_size)``; ``ValueError`` naming the argument."""
    for name, value in (("period", period), ("gap", gap), ("scale", scale), ("fps", fps)):
        if not isinstance(value, numbers.Real) or isinstance(value, bool) or not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    u = np.asarray(u, dtype=float)
    if u.ndim != 3 or u.shape[:2] != (n, dim) or u.shape[2] < 2:
        raise ValueError(f"u must have shape (n_nodes={n}, dim={dim}, F>=2 frames), got {u.shape}")
    if not np.all(np.isfinite(u)):
        raise ValueError(f"u has {int((~np.isfinite(u)).sum())} non-finite value(s) (NaN or inf)")
    nframes = u.shape[2]
    times = np.asarray(times, dtype=float)
    if times.shape != (nframes,):
        raise ValueError(f"times must have shape (F={nframes},) like u[:, :, F], got {times.shape}")
    if not np.all(np.isfinite(times)) or times.min() < 0 or times.max() > period:
        raise ValueError(f"times must be finite and in [0, period={period:g}], got [{times.min():g}, {times.max():g}]")
    impact = np.asarray(impact_frames)
    if impact.shape != (nframes,):
        raise ValueError(f"impact_frames must have shape (F={nframes},), got {impact.shape}")
    if impact.dtype != bool and not (np.issubdtype(impact.dtype, np.integer) and np.isin(impact, (0, 1)).all()):
        raise ValueError(f"impact_frames must be booleans (or 0/1), got dtype {impact.dtype}")
    if isinstance(contact_node, bool) or not isinstance(contact_node, numbers.Integral) or not 0 <= contact_node < n:
        raise ValueError(f"contact_node must be a node index in 0..{n - 1}, got {contact_node!r}")
    nv = np.asarray(normal, dtype=float).ravel()
    if nv.size not in (dim, 3) or not np.all(np.isfinite(nv)) or not np.any(nv):
        raise ValueError(f"normal must be a finite non-zero vector of {dim} or 3 components, got {normal!r}")
    nv = np.concatenate([nv, np.zeros(3 - nv.size)]) / np.linalg.norm(nv)
    if dim == 2 and abs(nv[2]) > 1e-9:
        raise ValueError(f"normal must lie in the plane z = 0 for a 2-D mesh, got {normal!r}")
    ws = tuple(window_size)
    if len(ws) != 2 or not all(isinstance(w, numbers.Integral) and w >= 16 for w in ws):
        raise ValueError(f"window_size must be (width, height), integers >= 16, got {window_size!r}")
    return u, times, impact.astype(bool), nv, (int(ws[0]), int(ws[1]))


def _plane_axes(normal: np.ndarray, u3: np.ndarray, dim: int) -> tuple[np.ndarray, np.ndarray]:
    """Orthonormal ``e1, e2`` across ``normal``: ``e1`` along the main motion (3-D), ``e2 = z`` (2-D)."""
    if dim == 2:
        return np.array([-normal[1], normal[0], 0.0]), np.array([0.0, 0.0, 1.0])
    flat = u3.transpose(0, 2, 1).reshape(-1, 3)
    flat = flat - np.outer(flat @ normal, normal)
    e1 = np.linalg.svd(flat, full_matrices=False)[2][0] if np.any(flat) else np.eye(3)[np.argmin(np.abs(normal))]
    e1 = e1 - (e1 @ normal) * normal
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(normal, e1)


def _casing(point, normal, e1, e2, warped, size, dim) -> np.ndarray:
    """Corners (4, 3) of the casing through ``point``: 1.5x the drawn blade across ``normal`` (a wall in 2-D)."""
    flat = warped.transpose(0, 2, 1).reshape(-1, 3)
    lo, hi = (flat @ e1).min(), (flat @ e1).max()
    across = [((lo + hi) / 2, 0.75 * max(hi - lo, 0.05 * size), e1)]
    if dim == 3:
        lo, hi = (flat @ e2).min(), (flat @ e2).max()
        across.append(((lo + hi) / 2, 0.75 * max(hi - lo, 0.05 * size), e2))
    else:  # the wall's thickness, beyond the clearance
        across.append((point @ normal + 0.02 * size, 0.02 * size, normal))
    (m1, h1, a1), (m2, h2, a2) = across
    base = point - (point @ a1) * a1 - (point @ a2) * a2 + m1 * a1 + m2 * a2
    return np.array([base + i * h1 * a1 + j * h2 * a2 for i, j in ((-1, -1), (1, -1), (1, 1), (-1, 1))])


def _length(x: float) -> str:
    """``0.1 mm``, ``25 µm``, ``1.2 m``."""
    for unit, f in (("m", 1.0), ("mm", 1e-3), ("\u00b5m", 1e-6)):
        if x >= f or unit == "\u00b5m":
            return f"{x / f:.3g} {unit}"
    raise AssertionError  # unreachable


def _surface(pts: np.ndarray, mesh: Mesh, dim: int, u3: np.ndarray):
    """``(grid, surf, ref, su)``: the body as a ``pyvista.UnstructuredGrid``, its drawn surface, and the
    reference coordinates ``(m, 3)`` and displacements ``(m, 3, F)`` of the surface points.

    Quadratic cells are kept quadratic: their boundary faces are subdivided
    :data:`SUBDIVISION` times (VTK's nonlinear subdivision), and the new points
    get the coordinates and displacements interpolated by the cells' quadratic
    shape functions (exact at the nodes).
    """
    import pyvista as pv

    body_type = mesh.body_type
    name, body = vtk_cells(body_type, mesh.cells[body_type])
    grid = pv.UnstructuredGrid({pv.CellType[name]: body}, pts.copy())
    nframes = u3.shape[2]
    grid.point_data["reference"] = pts
    grid.point_data["u"] = u3.reshape(len(pts), 3 * nframes)
    level = SUBDIVISION if KINDS[body_type].order == 2 else None
    surf = grid.extract_surface(pass_pointid=False, pass_cellid=False, nonlinear_subdivision=level,
                                algorithm="dataset_surface")
    ref = np.array(surf.point_data["reference"], dtype=float)
    su = np.array(surf.point_data["u"], dtype=float).reshape(-1, 3, nframes)
    for name in ("reference", "u"):
        surf.point_data.remove(name)
        grid.point_data.remove(name)
    surf.points = ref
    return grid, surf, ref, su


def _render(pts, mesh, dim, u3, scale, warped, umax, corners, contact_node, impact, phase, title, texts,
            window_size, size, bounds, normal, e1, contact_label="IMPACT", marks=None, marked=None):
    """The ``(F, h, w, 3)`` uint8 frames, rendered with one plotter whose actors are updated in place."""
    if not os.environ.get("DISPLAY"):  # headless: go straight to EGL rather than failing over from X11 noisily
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import pyvista as pv

    grid, surf, ref, su = _surface(pts, mesh, dim, u3)
    smag = np.linalg.norm(su, axis=1)  # (m, F) true |u| at the surface points
    outline = surf.extract_feature_edges(boundary_edges=True, feature_edges=dim == 3, manifold_edges=False,
                                         non_manifold_edges=False, feature_angle=40.0)
    surf.point_data[_FIELD] = smag[:, 0]
    sphere0 = pv.Sphere(radius=0.02 * size, center=(0.0, 0.0, 0.0))
    marker = sphere0.copy()
    casing = pv.PolyData(corners, faces=[4, 0, 1, 2, 3])
    nframes = warped.shape[2]
    try:
        pl = pv.Plotter(off_screen=True, window_size=list(window_size), theme=pv.themes.DocumentTheme())
    except Exception as exc:
        raise RuntimeError(_NO_OFFSCREEN + f" ({type(exc).__name__}: {exc})") from exc
    try:
        pl.add_mesh(surf, scalars=_FIELD, clim=(0.0, umax), cmap="viridis", smooth_shading=dim == 3,
                    scalar_bar_args=dict(title=_FIELD, fmt="%.2e", vertical=True, position_x=0.86, position_y=0.2,
                                         height=0.55, width=0.06, title_font_size=14, label_font_size=12))
        if dim == 2:  # the reference mesh, just behind the plane z = 0 (the warped mesh hides it)
            outline = outline.merge(grid.extract_all_edges()).translate((0, 0, -0.01 * size))
        pl.add_mesh(outline, color="black", opacity=0.25 if dim == 3 else 0.12, line_width=1)
        casing_actor = pl.add_mesh(casing, color="grey", opacity=0.4 if dim == 3 else 0.8, lighting=False)
        pl.add_mesh(marker, color="magenta", lighting=False)
        dots = dots_actor = None
        if marks is not None and marks.size:
            dots = pv.PolyData(warped[marks, :, 0].copy())
            dots_actor = pl.add_mesh(dots, color="red", point_size=9, render_points_as_spheres=True,
                                     lighting=False)
        pl.add_text(title, position="upper_left", font_size=11)
        clock = pl.add_text("", position="lower_left", font_size=8)
        hit = pl.add_text(str(contact_label), position="upper_right", font_size=12, color="red")
        _camera(pl, dim, normal, e1, bounds)
        frames = []
        for i in range(nframes):
            surf.points = ref + scale * su[:, :, i]
            surf.point_data[_FIELD] = smag[:, i]
            marker.points = sphere0.points + warped[contact_node, :, i]
            if dots is not None:  # the marked nodes; the others hidden behind the first marked one
                on = marked[:, i]
                if on.any():
                    at = warped[marks, :, i]
                    at[~on] = at[on][0]
                    dots.points = at
                dots_actor.SetVisibility(bool(on.any()))
            casing_actor.prop.color = "red" if impact[i] else "grey"
            hit.SetVisibility(bool(impact[i]))
            # the frame number keeps consecutive frames distinct: GIF writers merge identical ones
            clock.set_text("lower_left", "\n".join([f"frame {i + 1}/{nframes}   t/T = {phase[i]:.3f}", *texts]))
            try:
                pl.render()  # screenshot() renders by itself only the first time
                img = np.asarray(pl.screenshot(return_img=True))[:, :, :3]
            except Exception as exc:
                raise RuntimeError(_NO_OFFSCREEN + f" ({type(exc).__name__}: {exc})") from exc
            if i == 0 and (img.shape[:2] != window_size[::-1] or np.ptp(img) == 0):
                raise RuntimeError(_NO_OFFSCREEN + f" (the render window produced a blank {img.shape} image)")
            frames.append(img.copy())
        return frames
    finally:
        pl.close()


_NO_OFFSCREEN = (
    "off-screen rendering is not available: pyvista/VTK could not render without a display; install a VTK "
    "built with EGL or OSMesa (e.g. `pip install vtk-osmesa` or VTK >= 9.4 wheels with EGL drivers), or run "
    "under a virtual display (`xvfb-run`)"
)


def _camera(pl, dim: int, normal: np.ndarray, e1: np.ndarray, bounds: list[float]) -> None:
    """Fix the camera: along ``z`` in 2-D; in 3-D across the main motion ``e1``, tilted, casing up."""
    center = np.array(bounds).reshape(3, 2).mean(axis=1)
    view = np.array([0.0, 0.0, 1.0]) if dim == 2 else np.cross(normal, e1) + 0.45 * e1 - 0.3 * normal
    cam = pl.camera
    cam.focal_point = tuple(center)
    cam.position = tuple(center + view / np.linalg.norm(view))
    cam.up = tuple(normal)
    if dim == 2:
        pl.enable_parallel_projection()
    pl.renderer.ResetCamera(bounds)
    cam.zoom(0.95)
    pl.camera_set = True  # else pyvista resets the camera to the first frame's bounds on the first render


def _write_gif(path: Path, frames: list[np.ndarray], impact: np.ndarray, fps: float) -> None:
    """Looping GIF, one frame per image, one 256-colour palette; checks that no frame was merged away."""
    from PIL import Image

    # the palette: median cut over a montage of a few frames (an impact frame among them, for its red),
    # plus the exact colours of the text, the marker and the impact casing
    pick = set(np.linspace(0, len(frames) - 1, 8).round().astype(int)) | set(np.flatnonzero(impact)[:1])
    montage = np.concatenate([frames[i][::2, ::2] for i in sorted(pick)])
    median = Image.fromarray(montage).quantize(252, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
    palette = Image.new("P", (1, 1))
    palette.putpalette(median.getpalette()[: 3 * 252] + [0, 0, 0, 255, 255, 255, 255, 0, 0, 255, 0, 255])
    ims = [Image.fromarray(f).quantize(palette=palette, dither=Image.Dither.NONE) for f in frames]
    ims[0].save(path, format="GIF", save_all=True, append_images=ims[1:], duration=1000.0 / fps, loop=0)
    with Image.open(path) as im:
        written = im.n_frames
    if written != len(frames):  # Pillow merges identical consecutive frames and adds their durations
        log.info("GIF %s: %d identical consecutive frame(s) merged (timing kept)", path.name, len(frames) - written)


def _write_mp4(path: Path, frames: list[np.ndarray], fps: float) -> None:
    """H.264 MP4 (yuv420p: frames padded to even sizes)."""
    import imageio_ffmpeg

    h, w = frames[0].shape[:2]
    pad = ((0, h % 2), (0, w % 2), (0, 0))
    writer = imageio_ffmpeg.write_frames(str(path), (w + w % 2, h + h % 2), fps=fps, codec="libx264",
                                         pix_fmt_out="yuv420p", quality=7, macro_block_size=1,
                                         ffmpeg_log_level="error")
    writer.send(None)
    try:
        for img in frames:
            writer.send(np.ascontiguousarray(np.pad(img, pad, mode="edge")))
    finally:
        writer.close()
