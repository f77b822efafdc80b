"""The sampled closed loop in the compiled core: many ticks per call, the GIL released.

`ClosedLoop` (`uvms_pin.sim.closed_loop`) runs its sampled loop here, a chunk of ticks per
call of the core's ``run_sampled_chunk`` (src/uvms_core/sampled_loop.hpp), when every part of
the loop has a compiled counterpart: the plant (`Plant`'s compiled plant, no world, no stop at
the surface), a fixed-step integrator, the controller's law (the package's PPC, force
baselines, tracking controllers and the MPC on its compiled planner, their own classes:
`uvms_pin.sim.compiled.laws`), sensors without navigation, the actuation (`Unlimited`, or thrusters with their ideal
drives and the joints' effort limits), and observers that need only the log and the progress.
Otherwise `CompiledLoop.build` says why not, and the loop runs in Python as always; the
rollout's metadata ``closed_loop`` says which path ran and why.

Everything random or user-written stays Python's and comes in as tables per chunk: the
sensors' seeded noise at the ticks (`SensorSuite.noise_table`, the very numbers `measure`
adds) and the law's desired values, f_d(t), rpy_d(t). A tick the core does not finish as the
ordinary case (the law's status not ok: a funnel left, the solver declining; a failed or
diverged step) is not committed: the Python loop runs that tick (and raises as it does), the
law's state (an integral, an anchor) handed over, then the chunks resume. So
both paths give the same rollout (to rounding: tests/sim/test_compiled_loop.py), a funnel
violation stops at the same tick, and Ctrl-C, honoured between chunks, keeps the rows of the
chunks done.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np

from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.sim.compiled.actuation import actuation_to_core
from uvms_pin.sim.compiled.laws import CoreLaw, law_to_core
from uvms_pin.sim.compiled.loop_settings import loop_settings_to_core
from uvms_pin.sim.log import RolloutLog
from uvms_pin.sim.pipeline import Pipeline, RunParts, why_not_compiled
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.sample import ProgressReport
from uvms_pin.sim.settings import SimulationSettings
from uvms_pin.sim.system import SystemState

#: Ticks per call at most: a 500 Hz loop returns to Python (Ctrl-C, progress) every 0.5 s
#: simulated. A run starts with `FIRST_CHUNK_TICKS`, doubled at every call: a run that stops
#: early (most of a study's) does not draw noise and f_d for ticks it never reaches.
CHUNK_TICKS = 250
FIRST_CHUNK_TICKS = 32


@dataclass
class LoopPath:
    """Which loop ran a run: why not compiled (None when it was), and the ticks each path
    ran (the Python loop runs the ticks the core hands back, see the module docstring)."""

    reason: str | None = None
    compiled_ticks: int = 0
    python_ticks: int = 0

    def record(self) -> dict[str, Any]:
        return {
            "path": "compiled" if self.compiled_ticks else "python",
            "reason": self.reason,
            "compiled_ticks": self.compiled_ticks,
            "python_ticks": self.python_ticks,
        }


class CompiledLoop:
    """One run's compiled sampled loop: its core objects, tables and log buffer."""

    def __init__(self, core: ModuleType, loop, log: RolloutLog, law: CoreLaw, actuation_core):
        plant: Plant = loop.plant
        settings: SimulationSettings = loop.settings
        self.core, self.loop, self.log, self.law = core, loop, log, law
        self.actuation_core = actuation_core
        self.settings = loop_settings_to_core(core, settings, loop.sensors.state_noisy)
        uvms = plant.uvms
        self.nq, self.nv = uvms.nq, uvms.nv
        self.m = len(plant.actuation.thrusters) if actuation_core.thrusters else 0
        n_signals = len(law.law.signals())
        self.row = {
            name: slice(*span)
            for name, span in core.loop_row(self.nq, self.nv, self.m, n_signals).items()
        }
        width = self.row["thrust"].stop
        self.buffer = np.zeros((CHUNK_TICKS // self.settings.ticks_per_log + 1, width))
        self.progress = [o for o in loop.observers if isinstance(o, ProgressReport)]
        self.chunk_ticks = FIRST_CHUNK_TICKS

    @classmethod
    def build(cls, loop, log: RolloutLog) -> tuple[CompiledLoop | None, str | None]:
        """(the compiled loop of ``loop``, None) or (None, why it runs in Python: the
        pipeline's one list of reasons, `uvms_pin.sim.pipeline`)."""
        plant = loop.plant
        observers = [o for o in loop.observers if o is not log]
        parts = RunParts(
            loop.system, loop.settings, loop.sensors.config, loop.controller, observers
        )
        reason = why_not_compiled(parts, Pipeline.LOOP)
        if reason is not None:
            return None, reason
        core = core_module()
        law = law_to_core(loop.controller, core)
        actuation = actuation_to_core(plant.actuation, core, plant.uvms.nv)
        return cls(core, loop, log, law, actuation), None

    # ---- one chunk ----------------------------------------------------------------------
    def _desired(self, times: Sequence[float]) -> np.ndarray:
        """The law's desired rows at ``times`` (n x desired_size), up to the first time where
        one raises (the Python loop's tick then raises it)."""
        desired = self.law.desired
        out = np.empty((len(times), self.law.desired_size))
        for i, t in enumerate(times):
            try:
                out[i] = desired(t)
            except Exception:
                return out[:i]
        return out

    def run(self, first: int) -> tuple[int, bool]:
        """Ticks from ``first`` in one call: (the next tick to run, stopped: that tick is
        the Python loop's)."""
        loop, settings = self.loop, self.settings
        n = min(self.chunk_ticks, settings.final_tick + 1 - first)
        self.chunk_ticks = min(2 * self.chunk_ticks, CHUNK_TICKS)
        times = (np.arange(first, first + n, dtype=float) * settings.period_s).tolist()
        desired = np.ascontiguousarray(self._desired(times))
        n = len(desired)
        if n == 0:
            return first, True
        noise = loop.sensors.noise_table(np.array(times[:n]))
        q, v = np.array(loop.q), np.array(loop.v)
        actuation = loop.plant.actuation
        command, thrust, dropped = (
            (actuation.thruster_command, actuation.thrust_N, actuation.dropped_max)
            if self.actuation_core.thrusters
            else (np.zeros(0), np.zeros(0), np.zeros(0))
        )
        self.law.push()  # the Python loop may have run ticks: its state is the law's
        done, rows, stopped = self.core.run_sampled_chunk(
            loop.plant.compiled, self.law.law, self.actuation_core, settings, first, n,
            q, v, noise, desired, self.buffer, command, thrust, dropped,
        )  # fmt: skip
        if done:
            self._commit(first, done, rows, q, v, desired)
        return first + done, stopped or done < n

    def _commit(self, first: int, done: int, rows: int, q, v, desired: np.ndarray) -> None:
        """The loop's state after the chunk's ``done`` ticks, its ``rows`` into the log."""
        loop, period = self.loop, self.settings.period_s
        last = first + done - 1
        q.setflags(write=False)
        v.setflags(write=False)
        loop.state = SystemState(q, v)  # the compiled loop runs the robot alone
        if last < self.settings.final_tick:
            loop.time_s = (last + 1) * period
        else:
            loop.time_s = last * period
        self.law.pull(last * period, desired[done - 1])
        if rows:
            logged = [i for i in range(done) if (first + i) % self.settings.ticks_per_log == 0]
            self._log(self.buffer[:rows], desired[logged])
            for report in self.progress:
                for t in self.buffer[:rows, 0].tolist():
                    report.on_sample(_AtTime(t))

    def _log(self, block: np.ndarray, desired: np.ndarray) -> None:
        """``block``'s rows into the rollout, as `RolloutLog.on_sample` writes samples."""
        log, row = self.log, self.row
        rows = len(block)
        while log.count + rows > len(log.rollout):
            log.grow()
        rollout, k = log.rollout, slice(log.count, log.count + rows)
        rollout.time_s[k] = block[:, 0]
        rollout.q[k] = block[:, row["q"]]
        rollout.v[k] = block[:, row["v"]]
        rollout.tau[k] = block[:, row["tau"]]
        rollout.signal("tau_commanded", self.nv)[k] = block[:, row["tau_commanded"]]
        rollout.wrench_contact_world[k] = block[:, row["contact"]]
        rollout.wrench_measured_world[k] = block[:, row["measured_wrench"]]
        rollout.wrench_disturbance_body[k] = block[:, row["disturbance"]]
        for name, values in self.law.columns(block[:, row["signals"]], desired):
            rollout.signal(name, values.shape[1])[k] = values
            signal = self.law.described.get(name)
            if signal is not None and name not in log.described:
                log.describe(name, signal)
        if self.m:
            rollout.signal("thruster_command", self.m)[k] = block[:, row["command"]]
            rollout.signal("thrust", self.m)[k] = block[:, row["thrust"]]
        log.count += rows


@dataclass(frozen=True)
class _AtTime:
    """What a `ProgressReport` reads of a sample: its time."""

    time_s: float
