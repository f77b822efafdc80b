"""``[controller] type = "ppc"``: the paper's prescribed-performance law; omitted keys keep
the paper's values (`uvms_pin.control.ppc.PPCParams`)."""

from __future__ import annotations

import dataclasses
from typing import Any

from uvms_pin.control.ppc import PPCParams, PrescribedPerformanceController
from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.compiled.backend import BACKENDS
from uvms_pin.scenario.controller_parts import (
    checked_spec,
    desired_force_profile,
    ee_frame_name,
    plain,
)
from uvms_pin.scenario.schema import Table
from uvms_pin.sim.run import ControllerSpec

FIRST_LEVEL_KEYS = ("k_x", "rho0_x", "rho_inf_x", "l_x_per_s")  # 6 components
SECOND_LEVEL_KEYS = ("k_zeta", "rho0_zeta", "rho_inf_zeta", "l_zeta_per_s", "velocity_weights")


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
    desired_force, force_raw = desired_force_profile(t)
    t.finish()
    try:
        params = PPCParams(desired_rpy=desired_rpy, **fields).sized(uvms.nv)
    except ParameterError as exc:
        raise t.fail(str(exc)) from exc
    parameters = {k: plain(v) for k, v in dataclasses.asdict(params).items()}
    recorded = {"ee_frame": ee_frame, "desired_force": force_raw, "backend": backend, **parameters}

    def build(u: UVMS) -> PrescribedPerformanceController:
        return PrescribedPerformanceController(
            u.model, ee_frame, params, desired_force, backend=backend
        )

    return checked_spec(t, uvms, "ppc", recorded, build)
