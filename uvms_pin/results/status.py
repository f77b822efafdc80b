"""How a run ended: a typed status, saved in the rollout's metadata and read back from it.

The kinds are the names runs have always recorded (``rollout.json``'s ``status``): ``"ok"``
(it ran to the end), ``"interrupted"`` (Ctrl-C), ``"error"`` (the controller raised: the
message names its method, the time and the exception; ``error_traceback`` holds the frames
of a user's own controller), or the type of the error that stopped it, ``"FunnelViolation"``
or ``"SimulationError"`` (a diverged state, a failed solve, a body at the free surface).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

OK = "ok"
INTERRUPTED = "interrupted"
ERROR = "error"  # the controller raised (its message and, for the user's own, traceback)


@dataclass(frozen=True)
class Violation:
    """A prescribed-performance error that reached its funnel: |e| >= rho.

    Attributes:
        level: "first" (task space) or "second" (generalized velocity).
        component: the error's name (e.g. "f_x", "u", a joint name).
        time_s: when [s]. error: e at that time. bound: rho at that time (same unit).
    """

    level: str
    component: str
    time_s: float
    error: float
    bound: float


@dataclass(frozen=True)
class RunStatus:
    """How a run ended.

    Attributes:
        kind: "ok", "interrupted", or the error type that stopped the run.
        reason: the error's message ("" when ok).
        time_s: when the run stopped [s]: the violation time, else the last logged sample;
            None for a run that reached its end.
        violation: the funnel that broke, for a FunnelViolation.
    """

    kind: str = OK
    reason: str = ""
    time_s: float | None = None
    violation: Violation | None = None

    @property
    def ok(self) -> bool:
        return self.kind == OK

    @property
    def stopped_early(self) -> bool:
        """True when something stopped the run (not for ``ok`` nor ``interrupted``)."""
        return self.kind not in (OK, INTERRUPTED, "")

    def summary(self) -> str | None:
        """One line saying when and why the run stopped; None for a run that reached its end.

        A funnel violation names the level, component, time, error and bound (the state it
        happened in is not a logged sample: the figures end before it).
        """
        if self.kind in (OK, ""):
            return None
        v = self.violation
        if v is not None:
            return (
                f"{self.kind} at t = {v.time_s:.6g} s: {v.level}-level error "
                f"'{v.component}' = {v.error:.4g} reached its bound rho = {v.bound:.4g}"
            )
        reason = self.reason
        return f"{self.kind}: {reason[:120] + '...' if len(reason) > 120 else reason}"

    def to_metadata(self) -> dict[str, Any]:
        """The keys a rollout's metadata (``rollout.json``) holds for this status."""
        out: dict[str, Any] = {"status": self.kind, "error": self.reason}
        if self.time_s is not None:
            out["stop_time_s"] = self.time_s
        if self.violation is not None:
            out["violation"] = asdict(self.violation)
        return out

    @classmethod
    def from_metadata(cls, metadata: dict[str, Any], last_time_s: float | None) -> RunStatus:
        """The status recorded in ``metadata`` (rollouts saved before ``stop_time_s`` was
        recorded: the violation time, else ``last_time_s``, the last logged sample)."""
        kind = str(metadata.get("status", OK))
        raw = metadata.get("violation")
        violation = Violation(**raw) if isinstance(raw, dict) else None
        time_s = metadata.get("stop_time_s")
        if time_s is None and kind not in (OK, ""):
            time_s = violation.time_s if violation is not None else last_time_s
        return cls(kind, str(metadata.get("error", "")), time_s, violation)
