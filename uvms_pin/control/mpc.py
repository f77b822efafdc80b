"""Model-predictive control on the analytical derivatives: an OCP re-solved at a fixed rate.

At each re-plan (every 1 / rate_hz seconds) the controller sets the OCP's initial state to
the measured (q, v), warm-starts crocoddyl's (Box)FDDP from the previous solution shifted
by one node, runs at most ``iterations`` iterations (at most `COLD_START_ITERATIONS` for a
plan without a warm start, e.g. the first) and applies the first control,
tau = B_u u_0, held until the next re-plan. The OCP (`uvms_pin.ocp.problems`) is built once
on the model the controller believes in (it can be wrong on purpose, as for computed
torque: `uvms_pin.model.scaled.scaled_uvms`) and the water it is told about (a known
current; None: it plans in still water).

Tasks: "station" keeps the vehicle's body frame at a pose and the arm at its posture
(`problems.station_hold`); "end_effector" brings the end-effector to a pose and holds it
(`problems.point_to_point`, re-planned over a receding horizon).
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from uvms_pin.control.base import Controller
from uvms_pin.control.measurement import Measurement
from uvms_pin.errors import ParameterError
from uvms_pin.flow import FlowField
from uvms_pin.model.uvms import UVMS
from uvms_pin.ocp import problems

__all__ = ["MpcController"]

TASKS = ("station", "end_effector")
#: the iterations of a plan without a warm start (the first, or every one without warm_start)
COLD_START_ITERATIONS = 20


class MpcController(Controller):
    """Receding-horizon optimal control of a UVMS in water.

    Args:
        uvms: the model the controller believes in (a private copy of its Pinocchio model is
            used).
        task: "station" or "end_effector". target: the pose to hold (vehicle body frame, or
            end-effector), world frame.
        posture: the arm's and vehicle's reference configuration (nq,) for the state terms
            (x_ref = (posture, 0)).
        horizon_s, dt_s: the OCP's horizon and node length [s]. rate_hz: re-plans per second.
        iterations: solver iterations per re-plan. solver: "box_fddp" (bounds enforced) or
            "fddp".
        actuators: what u is and its bounds (`uvms_pin.ocp.problems.Actuators`).
        flow: the water the controller plans in. warm_start: shift the previous solution.
        pose_weights: of the target pose's error (x, y, z [m], rotation [rad]); None: the
            problem's default (`problems.station_hold`, `problems.point_to_point`).
    """

    def __init__(
        self,
        uvms: UVMS,
        *,
        task: str,
        target: pin.SE3,
        posture: np.ndarray,
        horizon_s: float = 1.0,
        dt_s: float = 0.02,
        rate_hz: float = 50.0,
        iterations: int = 3,
        solver: str = "box_fddp",
        actuators: problems.Actuators | None = None,
        flow: FlowField | None = None,
        warm_start: bool = True,
        pose_weights: np.ndarray | None = None,
        backend: str = "core",
    ):
        if task not in TASKS:
            raise ParameterError(f"mpc task must be one of {TASKS}, got '{task}'")
        if solver not in ("box_fddp", "fddp"):
            raise ParameterError(f"mpc solver must be 'box_fddp' or 'fddp', got '{solver}'")
        if not (rate_hz > 0.0 and math.isfinite(rate_hz)) or iterations < 1:
            raise ParameterError(
                f"mpc needs rate_hz > 0 and iterations >= 1, got {rate_hz}, {iterations}"
            )
        self.uvms = uvms.with_model(pin.Model(uvms.model))
        actuators = problems.Actuators() if actuators is None else actuators
        x_ref = np.r_[np.asarray(posture, float), np.zeros(uvms.nv)]
        build = problems.station_hold if task == "station" else problems.point_to_point
        weights = {} if pose_weights is None else {"pose_weights": pose_weights}
        self.problem = build(
            self.uvms,
            x_ref,
            target,
            horizon_s=horizon_s,
            dt_s=dt_s,
            actuators=actuators,
            flow=flow,
            backend=backend,
            **weights,
        )
        self.period_s = 1.0 / rate_hz
        self.iterations, self.bounded, self.warm_start = (
            iterations,
            solver == "box_fddp",
            warm_start,
        )
        self.input_matrix = (
            np.eye(uvms.nv) if actuators.input_matrix is None else actuators.input_matrix
        )
        self.reset()

    def reset(self) -> None:
        self._next_plan_s = -math.inf
        self._guess: tuple[list, list] | None = None
        self._tau = np.zeros(self.uvms.nv)
        self._signals: dict[str, np.ndarray] = {}

    def _initial_guess(self, x: np.ndarray) -> tuple[list, list]:
        nodes = self.problem.T
        if self._guess is None or not self.warm_start:
            return [x] * (nodes + 1), [np.zeros(self.problem.runningModels[0].nu)] * nodes
        xs, us = self._guess
        return [x, *xs[2:], xs[-1]], [*us[1:], us[-1]]

    def compute(self, time_s: float, measurement: Measurement) -> np.ndarray:
        if time_s < self._next_plan_s:
            return self._tau
        x = np.r_[measurement.q, measurement.v]
        self.problem.x0 = x
        cold = self._guess is None or not self.warm_start
        solver = problems.solve(
            self.problem,
            iterations=max(self.iterations, COLD_START_ITERATIONS) if cold else self.iterations,
            warm_start=self._initial_guess(x),
            bounded=self.bounded,
        )
        self._guess = (list(solver.xs), list(solver.us))
        u0 = np.array(solver.us[0])
        self._tau = self.input_matrix @ u0
        self._next_plan_s = time_s + self.period_s - 1e-12
        self._signals = {"mpc_cost": np.array([solver.cost]), "mpc_u": u0}
        return self._tau

    def signals(self) -> dict[str, np.ndarray]:
        return self._signals
