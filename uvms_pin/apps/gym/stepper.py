"""One control period of the plant at a time: the sampled closed loop of
`uvms_pin.sim.closed_loop.simulate_closed_loop`, opened at the controller.

The calls and their order are those of the simulator's sampled mode (measure at the tick,
apply the held input through the actuation, advance the plant by one control period
with `Plant.advance`, one compiled call when the core is built, check the state), so a policy that returns what a controller returns gives the
trajectory of ``uvms-pin run`` with the same seed.
"""

from __future__ import annotations

import numpy as np

from uvms_pin.control.measurement import Measurement
from uvms_pin.errors import SimulationError
from uvms_pin.sim.closed_loop import NUMERICAL_FAILURES, SimulationSettings, diverged
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.sensors import SensorConfig, SensorSuite


class PlantStepper:
    """The plant, its sensors and its integrator, advanced one control period per call.

    State: time ``time_s`` [s], configuration ``q`` (nq,), velocity ``v`` (nv,).
    """

    def __init__(self, plant: Plant, sensor_config: SensorConfig, settings: SimulationSettings):
        if settings.control_period_s is None:
            raise SimulationError("a stepped plant needs a control period (control.period_s)")
        self.plant = plant
        self.sensor_config = sensor_config
        self.settings = settings
        self.period_s = settings.control_period_s
        self.time_s = 0.0
        self.q = np.zeros(plant.uvms.nq)
        self.v = np.zeros(plant.uvms.nv)
        self._sensors: SensorSuite | None = None

    def reset(self, q0: np.ndarray, v0: np.ndarray, seed: int) -> None:
        """Start at (q0, v0), t = 0, with sensors seeded by ``seed`` (as the simulator's)."""
        model = self.plant.uvms.model
        self._sensors = SensorSuite(model, self.sensor_config, self.settings.duration_s, seed)
        self.q = np.asarray(q0, dtype=float).copy()
        self.q[3:7] /= np.linalg.norm(self.q[3:7])
        self.v = np.asarray(v0, dtype=float).copy()
        self.time_s = 0.0
        self.plant.attach(self.q)

    def measure(self) -> tuple[Measurement, np.ndarray]:
        """(the noisy measurement, the true contact wrench (6,) [N, N m] world axes) now."""
        self.plant.check_submerged(self.time_s, self.q)
        contact = self.plant.contact_wrench(self.q, self.v)
        return self._sensors.measure(self.time_s, self.q, self.v, contact), contact

    def advance(self, tau_commanded: np.ndarray) -> np.ndarray:
        """Hold ``tau_commanded`` through the actuation for one control period.

        Returns the applied tau (nv,). Raises SimulationError when the state diverges.
        """
        tau_applied = self.plant.actuation.apply(tau_commanded)
        t0, t1 = self.time_s, self.time_s + self.period_s
        plant = self.plant
        try:
            q, v = plant.advance(self.settings.integrator, t0, self.q, self.v, tau_applied, t1)
        except NUMERICAL_FAILURES as exc:
            raise SimulationError(
                f"simulation diverged between t = {t0:.6g} s and {t1:.6g} s "
                f"({type(exc).__name__}: {exc})"
            ) from exc
        if diverged(q, v):
            raise SimulationError(f"simulation diverged between t = {t0:.6g} s and {t1:.6g} s")
        self.q, self.v = q, v
        # the simulator's tick time, tick * period: no accumulated rounding
        self.time_s = round(t1 / self.period_s) * self.period_s
        return tau_applied
