"""Progress of a simulation: callable, tqdm bar, or silence."""

from __future__ import annotations

import time

import pytest
from conftest import ROOT

import uvms_pin as up
from uvms_pin.errors import ParameterError
from uvms_pin.results import progress as progress_module
from uvms_pin.results.progress import ProgressBar, callback_or_none

SCENARIO = ROOT / "scenarios" / "passive_still_water.toml"


def _short(duration_s: float = 0.1):
    return up.load_scenario(SCENARIO, {"scenario.duration_s": duration_s})


def test_callable_sees_every_logged_time_up_to_the_duration():
    seen = []
    rollout = up.simulate(_short(), progress=lambda t, total: seen.append((t, total)))
    assert [t for t, _ in seen] == pytest.approx(list(rollout.time_s))
    assert {total for _, total in seen} == {0.1}


def test_false_and_none_are_silent(capsys):
    for off in (False, None):
        up.simulate(_short(0.04), progress=off)
    captured = capsys.readouterr()
    assert captured.err == "" and captured.out == ""


class SteppedClock:
    """The progress module's ``time``: each ``perf_counter`` reading is ``step_s`` later
    than the previous one (0: held still); everything else is the real ``time``."""

    def __init__(self, step_s: float = 0.0) -> None:
        self.now_s, self.step_s = 1000.0, step_s

    def perf_counter(self) -> float:
        self.now_s += self.step_s
        return self.now_s

    def __getattr__(self, name: str):
        return getattr(time, name)


def test_default_progress_is_silent_until_its_delay_has_passed(capsys, monkeypatch):
    """Wall time as the test sets it, not as the machine runs: held still, a run never
    reaches the 2 s delay and prints nothing; 1 s per reading, the second sample (t = 0.02
    s, read 2 s after the start) is past it: a line; then only the end gets one (the next
    is due 10 s later)."""
    clock = SteppedClock()
    monkeypatch.setattr(progress_module, "time", clock)
    up.simulate(_short(0.04))
    assert capsys.readouterr().err == ""
    clock.step_s = 1.0
    up.simulate(_short(0.1))
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 2, lines
    assert "t =   0.020/0.1 s" in lines[0] and "elapsed    2.0 s" in lines[0]
    assert "t =   0.100/0.1 s" in lines[1]


def test_bar_reports_simulated_seconds(capsys):
    with ProgressBar("demo", 2.0, delay_s=0.0) as bar:
        bar(0.5, 2.0)
        bar(2.0, 2.0)
    err = capsys.readouterr().err
    assert "demo" in err and "2/2 s" in err and "100%" in err


def test_bad_progress_value_is_a_parameter_error():
    with pytest.raises(ParameterError, match="progress must be"):
        callback_or_none("yes")
    with pytest.raises(ParameterError, match="progress must be"):
        up.simulate(_short(0.04), progress=1)


def test_lines_in_a_log_after_the_delay_then_every_interval_and_at_the_end():
    import io

    from uvms_pin.results.progress import ProgressLines, progress_printer

    log = io.StringIO()
    lines = ProgressLines("run", 10.0, log, delay_s=0.0, interval_s=3600.0)
    for t in (0.0, 5.0, 10.0):
        lines(t, 10.0)
    text = log.getvalue().splitlines()
    assert len(text) == 2  # the first call, then the end (the interval is an hour)
    assert text[0].startswith("run [") and "t =   0.000/10 s" in text[0]
    assert text[0].endswith("left ~     ? s")  # no rate yet: unknown, not nan
    assert "#" * 30 in text[1] and "t =  10.000/10 s" in text[1]
    quiet = io.StringIO()
    silent = ProgressLines("run", 10.0, quiet, delay_s=3600.0)
    for t in (0.0, 10.0):
        silent(t, 10.0)
    assert quiet.getvalue() == ""  # shorter than the delay: nothing, not even the end
    with progress_printer("run", 10.0, stream=io.StringIO()) as printer:
        assert isinstance(printer, ProgressLines)  # a file: lines, not a bar


def test_a_line_extrapolates_what_is_left_from_the_rate_so_far(monkeypatch):
    """A quarter simulated in 3 s of wall time leaves 9 s at that rate, three quarters in 6 s
    2 s; the bar is a quarter (7 of 30 marks) and three quarters (22) full."""
    import io

    from uvms_pin.results.progress import ProgressLines

    clock = iter([100.0, 103.0, 106.0])
    monkeypatch.setattr(progress_module.time, "perf_counter", lambda: next(clock))
    log = io.StringIO()
    lines = ProgressLines("run", 8.0, log, delay_s=0.0, interval_s=1.0)
    lines(2.0, 8.0)
    lines(6.0, 8.0)
    first, second = log.getvalue().splitlines()
    assert first.endswith("elapsed    3.0 s  left ~   9.0 s")
    assert second.endswith("elapsed    6.0 s  left ~   2.0 s")
    assert first.count("#") == 7 and second.count("#") == 22
