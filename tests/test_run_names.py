"""Every result file name the package writes into a run's folder is one a run owns (``RUN_RESULTS``): a user's file
of that name in the output folder is then refused before any work, and an older result of that name that this run
did not write is removed. Read from the package's source: each literal ``"<name>.csv|png|vtu|json|md"`` joined to a
folder."""

import re
from pathlib import Path

from bladecase.study.publish import RUN_RESULTS

PACKAGE = Path(__file__).resolve().parents[1] / "bladecase"

#: Literal names that are not results of a run (docstring examples).
NOT_RESULTS = {"plate.vtu"}


def test_every_written_name_is_owned_by_the_run():
    names = set()
    for path in PACKAGE.rglob("*.py"):
        names |= set(re.findall(r"/ \"([a-z_0-9]+\.(?:csv|png|vtu|json|md))\"", path.read_text()))
        names |= set(re.findall(r"\"([a-z_0-9]+\.(?:csv|png|vtu))\"", path.read_text()))
    assert len(names) > 30
    missing = sorted(names - set(RUN_RESULTS) - NOT_RESULTS)
    assert not missing, f"written into a run's folder but not in RUN_RESULTS: {missing}"
