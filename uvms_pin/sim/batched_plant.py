"""N copies of a plant stepped together, one control period per call, on T threads.

`BatchedPlant` is the compiled batch (src/uvms_core/batch_plant.hpp) of the sampled closed
loop's tick with the controller replaced by a given command, as the Gymnasium environments
step it: per environment, tau_applied = actuation(tau_commanded) (thruster allocation and
saturation, joint effort limits), (q, v) advanced over the period with it held, the true
contact wrench at the new state, and the measurement (state + sensor noise) at the new
tick. The interpreter lock is released while the threads run.

Each environment has its own state, contact anchor (where its end-effector is at its
reset), tick count, status (running or diverged) and sensor noise: the noise tables of an
episode are drawn at its reset from the episode seed with exactly the streams of
`uvms_pin.sim.sensors.SensorSuite` (one per channel), so an environment of the batch gives
the numbers of a single `ClosedLoop` run with the same seed, whatever T.

What the batch does not simulate is refused with a ParameterError naming it, the reason
`uvms_pin.sim.pipeline` gives for the batch: a world, a flow (waves, sea states; a uniform
current is supported), thruster drives with lag, navigation sensors or an estimator,
``stop_at_surface``, the Python backend, or any part without a compiled counterpart.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from uvms_pin.checks import check_memory
from uvms_pin.errors import ParameterError
from uvms_pin.physics.compiled.contact import contact_to_core
from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.sim.compiled.batch import batch_to_core
from uvms_pin.sim.pipeline import Pipeline, RunParts, why_not_compiled
from uvms_pin.sim.plant import Plant, checked_start
from uvms_pin.sim.sensors import SensorConfig
from uvms_pin.sim.settings import SimulationSettings
from uvms_pin.sim.system import System

#: BatchStatus of the core: what became of an environment in the last step
RUNNING, DIVERGED = 0, 1
#: a thread's copy of the compiled plant (model, data, scratch) [bytes]: an upper bound
#: (the reference model's is under 1 MiB)
THREAD_BYTES = 8 * 2**20
#: an environment's share of the Python side (its generator slot, seed, flags, final
#: observation slot; the per-environment observations are counted from their size)
ENV_PYTHON_BYTES = 256


def batch_bytes(rows: int, nq: int, nv: int, num_envs: int, num_threads: int) -> int:
    """What a batch takes at its peak [bytes]: per environment its noise tables (``rows``
    samples of the 6 + 2 nv noise channels), its state rows (q, q_measured: nq; v,
    v_measured, tau_applied, an observation: nv; wrench and contact: 12) and its Python
    share; per thread (at most one per environment) a copy of the plant; and while an
    environment is reset, its tables drawn in Python, their copy made by the core's
    binding, and a channel's normal draw before it is clipped (the widest: nv columns).
    Measured (peak resident memory, tests/sim/test_batched_plant.py): without the reset's
    share the estimate was 30 % short of a 4-environment batch of 50,000 rows.
    ``num_envs`` and ``num_threads`` may be any size: the estimate is exact integer
    arithmetic."""
    table = 6 + 2 * nv  # an environment's noise channels, summed
    per_env = 8 * (rows * table + 2 * nq + 4 * nv + 12) + 16 + ENV_PYTHON_BYTES
    reset = 8 * rows * (2 * table + nv)
    return num_envs * per_env + min(num_threads, num_envs) * THREAD_BYTES + reset


def check_batch_fits(rows: int, nq: int, nv: int, num_envs: int, num_threads: int) -> None:
    """ParameterError, before anything is allocated, if a batch of ``num_envs``
    environments on ``num_threads`` threads would take more than half of the available
    memory (`uvms_pin.checks.check_memory`)."""
    check_memory(
        batch_bytes(rows, nq, nv, num_envs, num_threads),
        f"{num_envs} environments on {min(num_threads, num_envs)} threads "
        f"({rows} noise samples of {6 + 2 * nv} channels each)",
        "lower num_envs (or num_threads), or shorten the scenario's duration_s",
    )


def check_count(name: str, value: object) -> int:
    """``value`` as a positive int, or ParameterError naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value <= 0:
        raise ParameterError(f"{name} must be an integer >= 1, got {value!r}")
    return int(value)


def _noise_specs(sensors: SensorConfig) -> tuple:
    """The six channels in `SensorSuite`'s stream order."""
    return (sensors.force_noise, sensors.torque_noise, sensors.position_noise,
            sensors.orientation_noise, sensors.joint_noise, sensors.velocity_noise)  # fmt: skip


class BatchedPlant:
    """``num_envs`` copies of ``plant`` stepped together on ``num_threads`` threads.

    Args:
        plant: the plant (its compiled counterpart is copied per thread).
        settings: the control period, integrator and episode duration (noise tables).
        sensors: the sensors' noise.
        num_envs, num_threads: N >= 1, T >= 1 (T above N uses N threads).

    State, read-only views (N rows): ``q``, ``v``, ``q_measured``, ``v_measured``,
    ``wrench_measured`` (force N, torque N m, world axes, with noise), ``contact_world``
    (true), ``tau_applied``, ``tick`` (control periods since the reset), ``status``.
    """

    def __init__(
        self,
        plant: Plant,
        settings: SimulationSettings,
        sensors: SensorConfig,
        num_envs: int,
        num_threads: int = 1,
    ):
        num_envs = check_count("num_envs", num_envs)
        num_threads = check_count("num_threads", num_threads)
        if settings.control_period_s is None:
            raise ParameterError("the batched plant needs a sampled loop (control.period_s)")
        self.system = System(plant)
        # the prototype needs a placed contact: anchored here at q0, replaced at each reset
        nv = plant.uvms.nv
        self.system.start(self.system.initial_state(pin.neutral(plant.uvms.model), np.zeros(nv)))
        reason = why_not_compiled(RunParts(self.system, settings, sensors), Pipeline.BATCH)
        if reason is not None:
            raise ParameterError(f"the batched plant does not simulate {reason}")
        self.plant, self.settings, self.sensors = plant, settings, sensors
        self.period_s = float(settings.control_period_s)
        self._rows = math.ceil(settings.duration_s / sensors.sample_period_s) + 2
        check_batch_fits(self._rows, plant.uvms.nq, nv, num_envs, num_threads)
        self._specs = _noise_specs(sensors)
        self._widths = (3, 3, 3, 3, nv - 6, nv)
        threads = min(num_threads, num_envs)  # (the core takes a 32-bit count)
        self._core = batch_to_core(
            plant, settings.integrator, self.period_s, sensors.sample_period_s, self._rows,
            [spec.bound == 0.0 for spec in self._specs], num_envs, threads, core_module(),
        )  # fmt: skip
        self._stepping = np.ones(num_envs, dtype=bool)

    # ---- state ------------------------------------------------------------------------
    def __getattr__(self, name: str):
        if name in ("q", "v", "q_measured", "v_measured", "wrench_measured", "contact_world",
                    "tau_applied", "tick", "status", "num_envs", "num_threads"):  # fmt: skip
            return getattr(self.__dict__["_core"], name)
        raise AttributeError(name)

    def time_s(self) -> np.ndarray:
        """Each environment's time [s]: tick * period (as `ClosedLoop` counts it)."""
        return self._core.tick * self.period_s

    # ---- the episode -------------------------------------------------------------------
    def noise_tables(self, seed: int) -> list[np.ndarray]:
        """An episode's noise samples per channel (rows x width; empty for a silent one),
        drawn as `SensorSuite` draws them from ``seed``."""
        children = np.random.SeedSequence(seed).spawn(len(self._specs))
        tables = []
        for spec, width, child in zip(self._specs, self._widths, children, strict=True):
            if spec.bound == 0.0:
                tables.append(np.zeros((0, 0)))
            else:
                tables.append(spec.draw(np.random.default_rng(child), (self._rows, width)))
        return tables

    def reset(self, i: int, q0: np.ndarray, v0: np.ndarray, seed: int) -> None:
        """Environment ``i`` to t = 0 at (q0, v0) (the quaternion normalised), its contact
        anchored at its end-effector, its noise drawn from ``seed``."""
        model = self.plant.uvms.model
        q0, v0 = checked_start(model, q0, v0)
        contact = self.plant.contact
        if contact is not None:
            contact.attach(self.plant.ee_state(q0, np.zeros(model.nv))[0])
        self._core.reset(
            int(i), q0, v0, contact_to_core(contact, core_module()), self.noise_tables(seed)
        )

    def step(self, tau_commanded: np.ndarray, stepping: np.ndarray | None = None) -> None:
        """Advance the environments with ``stepping`` (all by default) one control period
        under ``tau_commanded`` (N, nv) [N, N m]; a diverged one keeps its state and gets
        ``status`` DIVERGED."""
        tau = np.ascontiguousarray(tau_commanded, dtype=float)
        mask = self._stepping if stepping is None else np.ascontiguousarray(stepping, dtype=bool)
        self._core.step(tau, mask)
