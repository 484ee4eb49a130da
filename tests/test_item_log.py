"""A long map tells as it goes: one log line per finished item with its wall time (every item up to 200, then
about a hundred lines spread over the map and the last), whatever the executor; a map of one item says nothing."""

from __future__ import annotations

import logging

from bladecase.study.executor import SerialExecutor
from bladecase.study.tasks import ItemLog, Logged


def _lines(caplog) -> list[str]:
    return [r.getMessage() for r in caplog.records if " done (item " in r.getMessage()]


def test_a_serial_map_logs_each_item_with_its_time(caplog):
    with caplog.at_level(logging.INFO, logger="bladecase"):
        assert SerialExecutor().map(abs, [-1.5, 2, -3], desc="rub speeds") == [1.5, 2, 3]
    lines = _lines(caplog)
    assert [x.split(":")[0] for x in lines] == ["rub speeds 1/3 done (item -1.5)", "rub speeds 2/3 done (item 2)",
                                                "rub speeds 3/3 done (item -3)"]
    assert all(x.endswith(" s") and float(x.split(": ")[1][:-2]) >= 0 for x in lines)


def test_one_item_says_nothing_and_a_long_map_about_a_hundred_lines(caplog):
    with caplog.at_level(logging.INFO, logger="bladecase"):
        SerialExecutor().map(abs, [1], desc="one")
        assert _lines(caplog) == []
        log = ItemLog("samples", 1000)
        for k in range(1000):
            log(k, 0.01)
    lines = _lines(caplog)
    assert len(lines) == 100 and lines[0].startswith("samples 10/1000 done") and lines[-1].startswith(
        "samples 1000/1000 done (item 999)")
    few = ItemLog("speeds", 200)
    assert few.step == 1


def test_a_worker_task_returns_its_time():
    out, lines, seconds = Logged(abs)(-2, {})
    assert out == 2 and lines == [] and seconds >= 0
