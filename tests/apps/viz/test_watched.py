"""What the live views share with their runners: a saved run played to a watcher."""

from __future__ import annotations

import io

import pytest

from uvms_pin.apps.viz.watched import play_saved
from uvms_pin.errors import LiveServerError


class _View:
    """A view that records what it is given (watched from the start unless told)."""

    def __init__(self, watched: bool = True, error: BaseException | None = None):
        self.watched = watched
        self.error = error
        self.pushed: list = []
        self.finished = False

    def push(self, frame) -> None:
        self.pushed.append(frame)

    def lag_s(self) -> float:
        return 0.0

    def finish(self) -> None:
        self.finished = True


def test_a_saved_run_is_queued_in_order_after_the_wait_and_played_out():
    view, out = _View(), io.StringIO()
    play_saved(view, "a browser to connect", iter([1, 2, 3]), out)
    assert view.pushed == [1, 2, 3]
    assert view.finished
    assert out.getvalue() == "live view: waiting for a browser to connect (Ctrl-C to stop)\n"


def test_a_view_that_fails_before_it_is_watched_is_given_nothing():
    view = _View(watched=False, error=OSError("port closed"))
    with pytest.raises(LiveServerError, match="live view failed: port closed"):
        play_saved(view, "a client", [1], None)
    assert view.pushed == []
