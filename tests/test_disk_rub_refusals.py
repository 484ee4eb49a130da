"""A bladed disk's rub (a [cyclic] study with [rub] speeds) runs without friction and wear: asking for either is
refused by name, never silently dropped."""

import pytest

from bladecase.study.schema import StudyError, loads

BASE = ('mesh = {{path = "s.inp"}}\n[search]\nipp = [1]\n[cyclic]\nsectors = 6\n'
        '[contact]\nface = "tip"\nmodel = "massless"\n{friction}[rub]\nspeeds = [1000]\nratio = 0.01\n'
        '[casing]\nradius = 0.3\nlobes = 3\namplitude = 1e-4\naxis = {{direction = [1, 0, 0]}}\n{abradable}')


@pytest.mark.parametrize("friction, abradable, what", [
    ("friction = {mu = 0.15}\n", "", r"\[contact\] friction"),
    ("", "abradable = {thickness = 1e-3, yield = 2e6, stiffness = 1e12}\n", r"\[casing\] abradable"),
])
def test_disk_rub_refuses_friction_and_wear(friction, abradable, what):
    with pytest.raises(StudyError, match=what + r": the rub of a bladed disk \(a \[cyclic\] study\) is computed "
                                              r"without friction and wear"):
        loads(BASE.format(friction=friction, abradable=abradable))


def test_disk_rub_without_them_is_accepted():
    study = loads(BASE.format(friction="", abradable=""))
    assert study["rub"]["speeds"] == [1000]
