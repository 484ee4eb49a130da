"""Property-based tests (hypothesis): random study files and random arrays thrown at the validators.

Every outcome is either a result or ONE line naming what is wrong — never a traceback of another kind, never a
non-finite number in what was accepted. The seeded searches of ``tests/test_hardening.py`` cover fixed odd
values; here hypothesis generates and shrinks.
"""

from __future__ import annotations

import copy
import math
import re

import numpy as np
import pytest
from _studies import PLATE, absolute, as_raw

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import bladecase as bc  # noqa: E402
from bladecase.study.schema import SCHEMA, StudyError, loads, validate  # noqa: E402

_BASE = as_raw(loads(absolute(PLATE)).config)
_KEYS = [(s, k) for s, ks in SCHEMA.items() if s not in ("geometry", "mesh") for k in ks]

_scalars = st.one_of(st.none(), st.booleans(), st.integers(-(10**20), 10**20),
                     st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=12))
_values = st.recursive(_scalars, lambda inner: st.one_of(st.lists(inner, max_size=4),
                                                         st.dictionaries(st.text(max_size=6), inner, max_size=3)),
                       max_leaves=6)
_edits = st.lists(st.tuples(st.sampled_from(_KEYS), _values), min_size=1, max_size=3)

_SETTINGS = settings(max_examples=150, deadline=None, derandomize=True, database=None,
                     suppress_health_check=[HealthCheck.too_slow])


def _finite(value) -> bool:
    if isinstance(value, float):
        return math.isfinite(value)
    if isinstance(value, list):
        return all(_finite(v) for v in value)
    if isinstance(value, dict):
        return all(_finite(v) for v in value.values())
    return True


@_SETTINGS
@given(_edits)
def test_random_study_values_give_a_study_or_one_line_naming_the_key(edits):
    raw = copy.deepcopy(_BASE)
    for (section, key), value in edits:
        if value is None:
            raw.get(section, {}).pop(key, None)  # TOML has no null: a missing key
        else:
            raw.setdefault(section, {})[key] = value
    try:
        study = validate(raw)
    except StudyError as exc:
        text = str(exc)
        assert "\n" not in text and re.match(r"\[\w+\]", text), text
        return
    for section, keys in study.config.items():
        for key, value in keys.items():
            assert _finite(value), (section, key, value)


_matrices = st.one_of(
    st.integers(1, 4).map(np.eye),
    st.integers(1, 4).map(lambda n: 2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1)),
    st.lists(st.floats(allow_nan=True, allow_infinity=True, width=64), min_size=1, max_size=16).map(
        lambda xs: np.array(xs).reshape(-1, 1) if len(xs) not in (1, 4, 9, 16)
        else np.array(xs).reshape(int(math.isqrt(len(xs))), -1)),
    st.just(np.zeros((0, 0))), st.just(np.eye(2) * (1 + 1j)), st.just(np.array([["a"]])))
_vectors = st.one_of(st.floats(allow_nan=True), st.integers(-3, 7), st.text(max_size=3), st.none(),
                     st.lists(st.floats(allow_nan=True, allow_infinity=True), min_size=0, max_size=4))
_gaps = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-2, 2), st.text(max_size=2),
                  st.none())


@_SETTINGS
@given(_matrices, _matrices, _vectors, _gaps)
def test_random_arrays_give_a_system_or_one_line(M, K, w, gap):
    try:
        system = bc.LinearSystem(M, K, w, gap)
    except ValueError as exc:
        assert "\n" not in str(exc).strip(), str(exc)
        return
    spec = system.spectrum  # an accepted system has a real, finite, positive spectrum
    assert np.all(np.isfinite(spec.omega)) and np.all(spec.omega > 0) and math.isfinite(system.gap) and system.gap > 0
