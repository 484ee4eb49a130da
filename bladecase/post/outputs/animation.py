"""``gif`` and ``mp4``: the blade over one period of an orbit, rendered off-screen by pyvista
(:func:`bladecase.post.animation.animate`; the frames are rendered once for both)."""

from __future__ import annotations

from pathlib import Path

from ... import log
from .. import animation
from .registry import OrbitScene


def write(scene: OrbitScene, folder: Path, formats: set[str]) -> dict[str, str]:
    """``animations/<stem>.gif`` and/or ``.mp4``; MP4 is skipped, with a warning, without imageio-ffmpeg."""
    want_mp4 = "mp4" in formats
    if want_mp4 and not animation.mp4_available():
        log.warning("MP4 skipped: imageio-ffmpeg is not installed (pip install imageio-ffmpeg)")
        want_mp4 = False
    if not want_mp4 and "gif" not in formats:
        return {}
    o = scene.options
    paths = animation.animate(scene.mesh, scene.u, scene.times, period=scene.orbit.T, impact_frames=scene.impact,
                              contact_node=scene.contact_node, normal=scene.normal, gap=scene.gap,
                              scale=scene.scale, gif=folder / "animations" / f"{scene.stem}.gif",
                              mp4=folder / "animations" / f"{scene.stem}.mp4" if want_mp4 else None,
                              title=scene.title, window_size=tuple(o["window"]), fps=o["fps"],
                              contact_label="CONTACT" if _massless(scene.orbit) else "IMPACT",
                              marks=scene.face_points, marked=scene.face_beyond)
    if "gif" not in formats:
        paths.pop("gif").unlink()
    return {k: f"animations/{p.name}" for k, p in paths.items()}


def _massless(orbit) -> bool:
    """An orbit of the massless contact model (contact phases, not impacts)."""
    return getattr(getattr(orbit, "system", None), "contact_model", "newton") == "massless"
