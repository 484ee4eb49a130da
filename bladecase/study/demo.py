"""The embedded demo study (``bladecase demo``): its TOML text and the seed paper's Newton variant."""

from __future__ import annotations

from importlib import resources
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .schema import Study


def demo_text() -> str:
    """The TOML text of the embedded demo study (``bladecase demo``)."""
    return resources.files("bladecase").joinpath("study/studies/demo.toml").read_text(encoding="utf-8")


#: The seed paper's variant of the demo: Newton's impact law on the tip node, 1- and 2-ipp modes below T1.
NEWTON_DEMO = {"contact": {"model": "newton", "face": None, "weights": None, "group": "contact",
                           "casing_stiffness": None},
               "reduction": {"method": "lanczos-si"}, "search": {"ipp": [1, 2], "periods": [0.9, 0.9999]}}


def demo_study(contact_model: str = "massless") -> Study:
    """The embedded demo study: a twisted, leaned 3-D blade of a few thousand dofs, its tip face rubbing a
    compliant casing (1e6 N/m) with the massless contact model; ``contact_model="newton"``: the seed paper's
    variant (:data:`NEWTON_DEMO`: Newton's impact law on the tip node against a rigid casing, lanczos-si, 1- and
    2-ipp).

    >>> study = demo_study()
    >>> blade = study.geometry()
    >>> type(blade).__name__, blade.naca, blade.span, blade.twist_deg, blade.lean, blade.contact_point
    ('BladeGeometry', '2412', 0.15, 40.0, 0.03, (0.0, 0.03, 0.15))
    >>> study["material"]["preset"], study["fem"]["order"], study["contact"]["face"], study["contact"]["model"]
    ('Ti-6Al-4V', 2, 'tip', 'massless')
    >>> study["contact"]["casing_stiffness"], demo_study("newton")["contact"]["casing_stiffness"]
    (1000000.0, None)
    >>> study["search"]["ipp"], study["search"]["periods"], study["output"]["formats"]
    ([1], [0.95, 1.0001], ['gif', 'mp4', 'vtu', 'png'])
    >>> newton = demo_study("newton")
    >>> newton["contact"]["group"], newton["reduction"]["method"], newton["search"]["ipp"]
    ('contact', 'lanczos-si', [1, 2])
    """
    if contact_model not in ("massless", "newton"):
        raise ValueError(f"contact_model must be 'massless' or 'newton', got {contact_model!r}")
    from .schema import loads, validate

    study = loads(demo_text(), source="<demo>")
    if contact_model == "massless":
        return study
    raw = {sec: {k: v for k, v in keys.items() if v is not None} for sec, keys in study.config.items()}
    for section, keys in NEWTON_DEMO.items():
        for key, value in keys.items():
            if value is None:
                raw[section].pop(key, None)
            else:
                raw[section][key] = value
    return validate(raw, source="<demo, newton>")
