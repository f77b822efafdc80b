"""``[controller] type = "ppc"``: the paper's prescribed-performance law; omitted keys keep
the paper's values (`uvms_pin.control.ppc.PPCParams`)."""

from __future__ import annotations

import dataclasses
from typing import Any

from uvms_pin.control.ppc import PPCParams, PrescribedPerformanceController
from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.compiled.backend import BACKENDS
from uvms_pin.scenario.profiles import plain, sine_profile
from uvms_pin.scenario.schema import Table
from uvms_pin.sim.run import ControllerSpec

FIRST_LEVEL_KEYS = ("k_x", "rho0_x", "rho_inf_x", "l_x_per_s")  # 6 components
SECOND_LEVEL_KEYS = ("k_zeta", "rho0_zeta", "rho_inf_zeta", "l_zeta_per_s", "velocity_weights")


def ee_frame_name(t: Table, uvms: UVMS, kind: str) -> str:
    """The table's ``ee_frame``, else the model's end-effector frame."""
    if t.has("ee_frame"):
        return t.string("ee_frame")
    ee_id = uvms.require_ee_frame(f"[controller] type = '{kind}'")
    return uvms.model.frames[ee_id].name


def build_ppc(t: Table, uvms: UVMS) -> ControllerSpec:
    ee_frame = ee_frame_name(t, uvms, "ppc")
    fields: dict[str, Any] = {}
    for keys, size in ((FIRST_LEVEL_KEYS, 6), (SECOND_LEVEL_KEYS, uvms.nv)):
        for key in keys:
            if t.has(key):
                fields[key] = t.vector(key, size)
    for key in ("null_space_gain_per_s", "pinv_relative_cutoff"):
        if t.has(key):
            fields[key] = t.number(key, nonneg=True)
    if t.has("null_space_target"):
        fields["null_space_target"] = t.vector("null_space_target", uvms.n_arm_joints)
    desired_rpy = t.vector("desired_rpy", 3, [0.0, 0.0, 0.0])
    # "core": the compiled law (Python reference on the calls it declines); "python": the reference
    backend = t.string("backend", "core", BACKENDS)
    force_table = t.table("desired_force")
    force_raw = {} if force_table is None else force_table.data
    desired_force = sine_profile(force_table, 3)
    t.finish()
    try:
        params = PPCParams(desired_rpy=desired_rpy, **fields).sized(uvms.nv)
        PrescribedPerformanceController(
            uvms.model, ee_frame, params, desired_force, backend=backend
        )
    except ParameterError as exc:
        raise t.fail(str(exc)) from exc
    recorded = {
        "ee_frame": ee_frame,
        "desired_force": force_raw,
        "backend": backend,
        **{k: plain(v) for k, v in dataclasses.asdict(params).items()},
    }
    return ControllerSpec(
        "ppc",
        recorded,
        lambda u: PrescribedPerformanceController(
            u.model, ee_frame, params, desired_force, backend=backend
        ),
    )
