"""The controller of scenarios/visual_approach.toml: image-based visual servoing of the vehicle
that brings the end-effector onto a marked object, seen only by the camera ``camera`` (in
the loop: ``measurement.images``).

Features (Chaumette and Hutchinson, "Visual servo control, Part I", IEEE RAM 2006): the
centroid (x, y) of the target's pixels in normalised image coordinates and the depth Z of
its nearest pixel. Their goal: the target's centre seen where the end-effector is, one
radius behind it, x* = c_x / c_z, y* = c_y / c_z with c = p_ee + r p_ee / |p_ee| (camera
frame, from the arm's measured joints), and Z* = p_ee,z - ``standoff_m``. For a point at
depth Z_c, with the camera translating at v (no rotation),

    d/dt [x, y, Z] = L v,   L = [[-1/Z_c, 0, x/Z_c], [0, -1/Z_c, y/Z_c], [0, 0, -1]],

so v = -lambda L^-1 e (e the features' error, |v| <= ``max_speed_m_s``) makes e decay at
rate lambda. The vehicle tracks v (body axes) and holds a level attitude and heading; the
arm holds its posture; gravity and buoyancy h(q, 0) are compensated:

    tau = h(q, 0) + [K_v (v_d - v_b); -K_R log(R) - K_w w; K_p (q_a* - q_a) - K_d qdot_a]

Without the target in view the vehicle holds still. It is a scenario's own controller
(``type = "visual_servo:VisualServo"``).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from object_push import arm_pd

from uvms_pin.checks import finite_parameters
from uvms_pin.control.base import Controller
from uvms_pin.physics.dynamics import bias_forces


class VisualServo(Controller):
    def __init__(
        self,
        uvms,
        camera: str,
        target: str,
        target_radius_m: float,
        width: int,
        height: int,
        horizontal_fov_rad: float,
        camera_position_m: list[float],
        camera_rpy_rad: list[float],
        arm_target_rad: list[float],
        gain_per_s: float = 0.4,
        max_speed_m_s: float = 0.15,
        standoff_m: float = 0.0,
        velocity_gain_N_s_m: float = 60.0,
        attitude_gains: list[float] = (40.0, 15.0),
        kp_Nm_rad: list[float] = (2.0, 10.0, 8.0, 0.5),
        kd_Nm_s_rad: list[float] = (0.3, 1.0, 0.8, 0.02),
    ):
        finite_parameters("visual_servo", locals())  # inf or nan: refused now, by name
        if not 0.0 < horizontal_fov_rad < np.pi:  # its focal length from it: finite, > 0
            raise ValueError(f"horizontal_fov_rad must be in (0, pi), got {horizontal_fov_rad}")
        for name, pixels in (("width", width), ("height", height)):
            if not (isinstance(pixels, int) and pixels >= 1):
                raise ValueError(f"{name} must be a whole number of pixels >= 1, got {pixels}")
        self.uvms, self.nv = uvms, uvms.nv
        self.camera, self.target, self.radius = camera, target, float(target_radius_m)
        self.focal = 0.5 * width / np.tan(0.5 * horizontal_fov_rad)
        self.centre = np.array([0.5 * width, 0.5 * height])
        self.body_camera = pin.SE3(
            pin.rpy.rpyToMatrix(np.asarray(camera_rpy_rad, dtype=float)),
            np.asarray(camera_position_m, dtype=float),
        )
        self.arm_target, self.kp, self.kd = arm_pd(uvms.nv, arm_target_rad, kp_Nm_rad, kd_Nm_s_rad)
        self.gain, self.max_speed, self.standoff = gain_per_s, max_speed_m_s, standoff_m
        self.kv = velocity_gain_N_s_m
        self.k_rotation, self.k_rate = attitude_gains
        self.data = uvms.model.createData()
        self.error = np.zeros(3)
        self.heading: np.ndarray | None = None

    def reset(self) -> None:
        self.error = np.zeros(3)
        self.heading = None

    def _goal(self, q: np.ndarray) -> np.ndarray:
        """(x*, y*, Z*): where the target should be seen, from the arm's joints."""
        body = q.copy()
        body[:7] = [0, 0, 0, 0, 0, 0, 1]  # the end-effector in the vehicle's frame
        pin.framesForwardKinematics(self.uvms.model, self.data, body)
        ee = self.body_camera.actInv(self.data.oMf[self.uvms.ee_frame_id].translation)
        centre = ee + self.radius * ee / np.linalg.norm(ee)
        return np.array([centre[0] / centre[2], centre[1] / centre[2], ee[2] - self.standoff])

    def _camera_velocity(self, image, goal: np.ndarray) -> np.ndarray | None:
        """v (3,) in the camera's frame, None without the target in view."""
        if self.target not in image.label_names:
            return None
        seen = image.label == image.label_names.index(self.target) + 1
        if not np.any(seen):
            return None
        rows, cols = np.nonzero(seen)
        x, y = (np.array([cols.mean(), rows.mean()]) + 0.5 - self.centre) / self.focal
        depths = image.depth_m[seen]
        nearest, mean = float(np.min(depths)), float(np.mean(depths))
        self.error = np.array([x, y, nearest]) - goal
        interaction = np.array(
            [[-1.0 / mean, 0.0, x / mean], [0.0, -1.0 / mean, y / mean], [0.0, 0.0, -1.0]]
        )
        velocity = -self.gain * np.linalg.solve(interaction, self.error)
        speed = np.linalg.norm(velocity)
        return velocity * min(1.0, self.max_speed / speed) if speed > 0 else velocity

    def compute(self, time_s, measurement):
        q, v = measurement.q, measurement.v
        rotation = pin.Quaternion(q[3:7]).toRotationMatrix()
        if self.heading is None:
            self.heading = pin.rpy.matrixToRpy(rotation)[2]
        image = measurement.images.get(self.camera)
        velocity = None if image is None else self._camera_velocity(image, self._goal(q))
        wanted = np.zeros(3) if velocity is None else self.body_camera.rotation @ velocity
        level = pin.rpy.rpyToMatrix(0.0, 0.0, self.heading)
        tau = bias_forces(self.uvms, q, np.zeros(self.nv))
        tau[:3] += self.kv * (wanted - v[:3])
        tau[3:6] += -self.k_rotation * pin.log3(level.T @ rotation) - self.k_rate * v[3:6]
        tau[6:] += self.kp * (self.arm_target - q[7:]) - self.kd * v[6:]
        return tau

    def signals(self) -> dict[str, np.ndarray]:
        """``visual_error``: the features' error [x, y (normalised), Z (m)]."""
        return {"visual_error": self.error.copy()}
