"""docs/study.md stays in step with the study schema (bladecase.study.schema.SCHEMA).

* every section of SCHEMA has a heading containing ``[section]``;
* every key of every section, and every field of BladeGeometry and
  PlateGeometry, appears in backticks — and the default given in its table
  row is the schema's (TOML spelling, ``required``, or ``—`` for "not set");
* every TOML block with a ``[study]`` table is a valid study (paths relative
  to the repository root), and the demo block is the embedded demo study.
"""

from __future__ import annotations

import dataclasses
import re
import tomllib
from pathlib import Path

import pytest

from bladecase.fe.geometry import BladeGeometry, PlateGeometry
from bladecase.fe.sector import SectorGeometry
from bladecase.study.demo import demo_text
from bladecase.study.schema import GEOMETRY_FIELDS, REQUIRED, SCHEMA, loads

ROOT = Path(__file__).resolve().parent.parent
DOC = ROOT / "docs" / "study.md"


@pytest.fixture(scope="module")
def text() -> str:
    return DOC.read_text(encoding="utf-8")


def _sections(text: str) -> dict[str, str]:
    """Body of each ``## ... [section] ...`` heading, up to the next level-2 heading."""
    parts = re.split(r"^(?=## )", text, flags=re.M)
    out = {}
    for part in parts:
        heading = part.split("\n", 1)[0]
        m = re.match(r"## .*\[(\w+)\]", heading)
        if m:
            out[m.group(1)] = part
    return out


def _rows(body: str) -> dict[str, list[str]]:
    """``key -> [default cell, ...]`` of the table rows ``| `key` | type | default | meaning |``."""
    rows: dict[str, list[str]] = {}
    for line in body.splitlines():
        cells = [c.strip() for c in re.split(r"(?<!\\)\|", line)[1:-1]]
        if len(cells) == 4 and re.fullmatch(r"`\w+`", cells[0]):
            rows.setdefault(cells[0].strip("`"), []).append(cells[2])
    return rows


def _matches(cell: str, default) -> bool:
    if default is REQUIRED:
        return cell.lower() == "required"
    if default is None:
        return cell.startswith("—")
    value = tomllib.loads(f"v = {cell.strip('`')}")["v"]
    if isinstance(default, tuple):
        default = list(default)
    return value == default and type(value) is type(default)


def _geometry_defaults() -> dict[str, list]:
    out: dict[str, list] = {k: [spec.default] for k, spec in SCHEMA["geometry"].items()}
    for cls in (BladeGeometry, PlateGeometry, SectorGeometry):
        for f in dataclasses.fields(cls):
            default = REQUIRED if f.default is dataclasses.MISSING else f.default
            out.setdefault(f.name, []).append(default)
    return out


def test_every_section_has_a_heading(text):
    headings = [line for line in text.splitlines() if line.startswith("#")]
    for section in SCHEMA:
        assert any(f"[{section}]" in h for h in headings), f"no heading with [{section}] in {DOC}"


@pytest.mark.parametrize("section", list(SCHEMA))
def test_every_key_documented_with_its_default(text, section):
    body = _sections(text).get(section)
    assert body is not None, f"no '## ... [{section}]' section in {DOC}"
    rows = _rows(body)
    expected = _geometry_defaults() if section == "geometry" else {k: [s.default] for k, s in SCHEMA[section].items()}
    for key in SCHEMA[section]:
        assert f"`{key}`" in text, f"[{section}] {key} is not documented in {DOC}"
        assert key in rows, f"[{section}] {key} has no table row '| `{key}` | type | default | meaning |'"
    for key, cells in rows.items():
        assert key in expected, f"[{section}] {key} is documented but is not in the schema"
        for cell in cells:
            assert any(_matches(cell, d) for d in expected[key]), (
                f"[{section}] {key}: documented default {cell!r}, schema says {expected[key]!r}")


def test_every_geometry_field_documented(text):
    rows = _rows(_sections(text)["geometry"])
    for kind, fields in GEOMETRY_FIELDS.items():
        for name in fields:
            assert f"`{name}`" in text, f"[geometry] {name} (kind = {kind!r}) is not documented"
            assert name in rows, f"[geometry] {name} (kind = {kind!r}) has no table row"


def _study_blocks(text: str) -> list[str]:
    blocks = re.findall(r"^```toml\n(.*?)^```", text, flags=re.M | re.S)
    return [b for b in blocks if re.search(r"^\[study\]", b, flags=re.M)]


def test_examples_are_valid_studies(text):
    blocks = _study_blocks(text)
    assert len(blocks) >= 2, "expected the demo study and a user-mesh study"
    for block in blocks:
        study = loads(block, source="docs/study.md", base=ROOT)
        if not study.parametric:
            assert study.mesh_path().exists(), f"example mesh {study['mesh']['path']!r} is not in the repository"


def test_demo_example_is_the_embedded_demo(text):
    demo = [b for b in _study_blocks(text) if re.search(r'^name = "demo"', b, flags=re.M)]
    assert demo, "the demo study is not in docs/study.md"
    assert demo[0] == demo_text(), "docs/study.md's demo study differs from bladecase/studies/demo.toml"
