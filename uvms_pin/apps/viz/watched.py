"""What a live view (the meshcat page, `uvms_pin.apps.viz.live`; the Foxglove server,
`uvms_pin.apps.viz.foxglove_live`) shares with its runner: a run simulated while the view is
fed, a saved run played (after the wait for a watcher), and the end of a run played out.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Iterable
from typing import Any, Protocol, TextIO

from uvms_pin.errors import LiveServerError, SimulationError
from uvms_pin.results.progress import Progress
from uvms_pin.results.rollout import Rollout
from uvms_pin.sim.run import Scenario, simulate
from uvms_pin.sim.sample import Observer

__all__ = ["Watched", "play_saved", "play_to_end", "simulate_watched", "wait_for_watcher"]


class Watched(Protocol):
    """What a live view offers its runner (`LiveView`, the Foxglove server)."""

    watched: bool
    error: BaseException | None

    def push(self, frame: Any) -> None: ...

    def lag_s(self) -> float: ...

    def finish(self) -> None: ...


def simulate_watched(
    scenario: Scenario,
    view: Watched,
    feed: Observer,
    *,
    progress: Progress | None = None,
    out: TextIO | None = sys.stdout,
) -> Rollout:
    """`simulate` with ``feed`` observing every sample for ``view``; the view shows the run
    to its end (a run that stops early too, the error then re-raised)."""
    try:
        rollout = simulate(scenario, progress=progress, observers=[feed])
    except SimulationError:  # FunnelViolation included: show the partial run, re-raise
        play_to_end(view, out)
        raise
    play_to_end(view, out)
    return rollout


def wait_for_watcher(view: Watched, what: str, out: TextIO | None) -> None:
    """Wait until ``view`` is watched (saying so: "waiting for ``what``"); LiveServerError
    if the view fails meanwhile."""
    if out is not None:
        print(f"live view: waiting for {what} (Ctrl-C to stop)", file=out)
        out.flush()
    while not view.watched:
        if view.error is not None:
            raise LiveServerError(f"live view failed: {view.error}")
        time.sleep(0.1)


def play_saved(view: Watched, what: str, frames: Iterable[Any], out: TextIO | None) -> None:
    """Play a saved run's ``frames`` (each as ``view.push`` takes it) in ``view``: wait for a
    watcher (`wait_for_watcher`, "waiting for ``what``"), queue them all, play them out."""
    wait_for_watcher(view, what, out)
    for frame in frames:
        view.push(frame)
    play_to_end(view, out)


def play_to_end(view: Watched, out: TextIO | None) -> None:
    """Let ``view`` show what it has queued (to a watcher; at once without one), then stop."""
    lag = view.lag_s()
    if out is not None and lag > 1.0 and view.watched:
        print(f"live view: playing the last {lag:.1f} s of the run (Ctrl-C to stop)", file=out)
        out.flush()
    view.finish()
    if view.error is not None and out is not None:
        print(f"live view: stopped streaming: {view.error}", file=out)
