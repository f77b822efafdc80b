"""The generated MJCF against the Pinocchio model: inertias, kinematics, M, buoyancy, spring."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from conftest import body_urdf, hydro_xml

import uvms_pin as up
from uvms_pin.apps.export.mjcf import SPRING_TENDON, MjcfOptions, uvms_to_mjcf
from uvms_pin.apps.export.mujoco_state import qfrc_from_tau, qpos_from_q, qvel_from_v
from uvms_pin.errors import ModelError, ParameterError
from uvms_pin.model.mount.catalog import resolve_arm
from uvms_pin.model.mount.mount import mount_arm_detailed
from uvms_pin.model.mount.split import split_urdf
from uvms_pin.physics.contact import LinearSpring
from uvms_pin.sim.plant import Plant

mujoco = pytest.importorskip("mujoco")

ROOT = Path(__file__).resolve().parents[3]
REFERENCE_URDF = ROOT / "models" / "uvms_lbv150.urdf"
SYSTEMS = ["reference", "ur5", "panda"]


def _mounted(name: str, tmp: Path) -> tuple[up.UVMS, str]:
    """The reference system, or an example-robot-data arm on the reference vehicle."""
    if name == "reference":
        return up.load_uvms(REFERENCE_URDF), REFERENCE_URDF.read_text()
    split = split_urdf(REFERENCE_URDF, tmp)
    entry = resolve_arm(name)
    pose = (split.mount_pose.translation, np.array([np.pi, 0.0, 0.0]))  # as compare-arms
    mounted = mount_arm_detailed(
        split.vehicle_urdf, entry.urdf, pose, ee_link=entry.ee_link, allow_dry_links=True
    )
    return mounted.uvms, mounted.urdf_text


@pytest.fixture(scope="module", params=SYSTEMS)
def system(request, tmp_path_factory):
    uvms, urdf_text = _mounted(request.param, tmp_path_factory.mktemp(request.param))
    model = mujoco.MjModel.from_xml_string(uvms_to_mjcf(uvms, urdf_text))
    return uvms, model, mujoco.MjData(model)


def _random_q(uvms: up.UVMS, rng: np.random.Generator) -> np.ndarray:
    q = pin.randomConfiguration(uvms.model, -np.ones(uvms.nq), np.ones(uvms.nq))
    q[7:] = rng.uniform(-2.0, 2.0, size=uvms.n_arm_joints)
    return q


def _to_mujoco_matrix(q: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    """T^T M T with zeta = T qvel: the same kinetic energy in MuJoCo's velocities."""
    t = np.eye(matrix.shape[0])
    t[:3, :3] = pin.XYZQUATToSE3(q[:7]).rotation.T  # zeta = T qvel
    return t.T @ matrix @ t


def test_joints_and_dofs_in_pinocchio_order(system):
    uvms, model, _ = system
    assert (model.nq, model.nv) == (uvms.nq, uvms.nv)
    names = [model.joint(i).name for i in range(model.njnt)]
    assert names == list(uvms.model.names[1:])
    np.testing.assert_array_equal(model.dof_armature, uvms.model.armature)


def test_total_mass_and_each_body_inertia(system):
    uvms, model, _ = system
    assert abs(model.body_subtreemass[0] - uvms.mass_kg) < 1e-12 * uvms.mass_kg
    for j in range(1, uvms.model.njoints):
        body = model.joint(uvms.model.names[j]).bodyid[0]
        carriers = [
            b
            for b in range(model.nbody)
            if model.body_parentid[b] == body and not model.body_jntnum[b]
        ]
        total = np.zeros((6, 6))
        for b in [body, *carriers]:
            rotation = np.zeros(9)
            mujoco.mju_quat2Mat(rotation, model.body_iquat[b])
            rotation = rotation.reshape(3, 3)
            inertia = pin.Inertia(
                model.body_mass[b],
                model.body_ipos[b],
                rotation @ np.diag(model.body_inertia[b]) @ rotation.T,
            )
            if b != body:  # a carrier: from its frame to the joint body's frame
                inertia = pin.SE3(np.eye(3), model.body_pos[b]).act(inertia)
            total += inertia.matrix()
        expected = uvms.model.inertias[j].matrix()
        np.testing.assert_allclose(total, expected, rtol=0, atol=1e-12 * np.abs(expected).max())


def test_forward_kinematics_of_every_body_and_the_end_effector(system):
    uvms, model, data = system
    pin_data = uvms.model.createData()
    rng = np.random.default_rng(11)
    ee = uvms.model.frames[uvms.ee_frame_id]
    for _ in range(5):
        q = _random_q(uvms, rng)
        data.qpos[:] = qpos_from_q(q)
        mujoco.mj_kinematics(model, data)
        pin.framesForwardKinematics(uvms.model, pin_data, q)
        for j in range(1, uvms.model.njoints):
            body = model.joint(uvms.model.names[j]).bodyid[0]
            np.testing.assert_allclose(data.xpos[body], pin_data.oMi[j].translation, atol=1e-9)
            np.testing.assert_allclose(
                data.xmat[body].reshape(3, 3), pin_data.oMi[j].rotation, atol=1e-9
            )
        site = model.site(ee.name).id
        placement = pin_data.oMf[uvms.ee_frame_id]
        np.testing.assert_allclose(data.site_xpos[site], placement.translation, atol=1e-9)
        np.testing.assert_allclose(
            data.site_xmat[site].reshape(3, 3), placement.rotation, atol=1e-9
        )


def test_rigid_mass_matrix_at_random_configurations(system):
    uvms, model, data = system
    rng = np.random.default_rng(12)
    pin_data = uvms.model.createData()
    for _ in range(5):
        q = _random_q(uvms, rng)
        data.qpos[:] = qpos_from_q(q)
        mujoco.mj_forward(model, data)
        mass_mujoco = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, data, mass_mujoco)
        rigid = pin.crba(uvms.model, pin_data, q)  # armature included
        rigid = np.triu(rigid) + np.triu(rigid, 1).T
        expected = _to_mujoco_matrix(q, rigid)
        np.testing.assert_allclose(
            mass_mujoco, expected, rtol=0, atol=1e-9 * np.abs(expected).max()
        )


def test_gravity_and_buoyancy_at_rest(system):
    """At rest MuJoCo's qfrc_bias - qfrc_passive (gravity minus the carriers' lift; the fluid
    is still) is uvms-pin's h(q, 0) = g_RB - sum_i J_i^T w_buoyancy,i, mapped to MuJoCo."""
    uvms, model, data = system
    rng = np.random.default_rng(13)
    for _ in range(5):
        q = _random_q(uvms, rng)
        data.qpos[:] = qpos_from_q(q)
        data.qvel[:] = 0.0
        mujoco.mj_forward(model, data)
        generalized = data.qfrc_bias - data.qfrc_passive
        expected = qfrc_from_tau(q, up.bias_forces(uvms, q, np.zeros(uvms.nv)))
        scale = uvms.mass_kg * 9.81
        np.testing.assert_allclose(generalized, expected, rtol=0, atol=1e-10 * scale)
        np.testing.assert_array_equal(data.qfrc_fluid, 0.0)


def test_the_reference_model_floats_neutrally_in_mujoco():
    uvms = up.load_uvms(REFERENCE_URDF)
    model = mujoco.MjModel.from_xml_string(uvms_to_mjcf(uvms, REFERENCE_URDF.read_text()))
    data = mujoco.MjData(model)
    data.qpos[:] = qpos_from_q(uvms.neutral_configuration())
    mujoco.mj_forward(model, data)
    vertical = data.qfrc_passive[2] - data.qfrc_bias[2]  # world z force on the free body
    assert abs(vertical - uvms.net_buoyancy_N) < 1e-9
    assert abs(vertical) < 0.01 * uvms.mass_kg * 9.81  # trimmed: buoyancy ~ weight


def test_spring_tendon_is_the_papers_linear_spring():
    uvms = up.load_uvms(REFERENCE_URDF)
    rng = np.random.default_rng(14)
    q = _random_q(uvms, rng)
    spring = LinearSpring(np.full(3, 2.0), anchor_world_m=[0.3, -0.2, -1.0])
    options = MjcfOptions(spring_stiffness_N_m=2.0, spring_anchor_world_m=(0.3, -0.2, -1.0))
    text = REFERENCE_URDF.read_text()
    passive = []
    for opts in (options, MjcfOptions()):
        model = mujoco.MjModel.from_xml_string(uvms_to_mjcf(uvms, text, opts))
        data = mujoco.MjData(model)
        data.qpos[:] = qpos_from_q(q)
        mujoco.mj_forward(model, data)
        passive.append(data.qfrc_passive.copy())
    plant = Plant(uvms, contact=spring)
    position, _, _ = plant.ee_state(q, np.zeros(uvms.nv))
    wrench = spring.wrench_on_environment_world(position, np.zeros(3))
    tau_ext = up.frame_wrench_to_generalized(uvms, q, uvms.ee_frame_id, -wrench)
    expected = qfrc_from_tau(q, tau_ext)
    model = mujoco.MjModel.from_xml_string(uvms_to_mjcf(uvms, text, options))
    data = mujoco.MjData(model)
    data.qpos[:] = qpos_from_q(q)
    mujoco.mj_forward(model, data)
    length = data.ten_length[model.tendon(SPRING_TENDON).id]
    assert abs(length - np.linalg.norm(wrench[:3]) / 2.0) < 1e-12  # |p - p0| = |f| / k
    np.testing.assert_allclose(
        passive[0] - passive[1], expected, rtol=0, atol=1e-12 * np.abs(expected).max()
    )


def test_fluid_drags_and_moves_with_the_current():
    """MuJoCo's fluid opposes motion (negative power at random velocities) and vanishes for a
    body drifting with the current (opt.wind), which is how a current is set."""
    uvms = up.load_uvms(REFERENCE_URDF)
    model = mujoco.MjModel.from_xml_string(uvms_to_mjcf(uvms, REFERENCE_URDF.read_text()))
    data = mujoco.MjData(model)
    rng = np.random.default_rng(15)
    for _ in range(5):
        q = _random_q(uvms, rng)
        data.qpos[:] = qpos_from_q(q)
        data.qvel[:] = qvel_from_v(q, rng.normal(scale=0.5, size=uvms.nv))
        mujoco.mj_forward(model, data)
        assert data.qfrc_fluid @ data.qvel < 0.0
    current = np.array([0.3, -0.1, 0.05])
    model.opt.wind[:] = current
    data.qvel[:] = 0.0
    data.qvel[:3] = current
    mujoco.mj_forward(model, data)
    assert np.abs(data.qfrc_fluid).max() < 1e-9


def test_bad_input_raises_clear_errors():
    uvms = up.load_uvms(REFERENCE_URDF)
    with pytest.raises(ModelError, match="well-formed"):
        uvms_to_mjcf(uvms, "<robot")
    with pytest.raises(ParameterError, match="spring_anchor_world_m"):
        MjcfOptions(spring_stiffness_N_m=2.0)
    with pytest.raises(ParameterError, match="carrier_mass_fraction"):
        MjcfOptions(carrier_mass_fraction=1.0)
    with pytest.raises(ParameterError, match="5 finite fluid_coefficients"):  # written as nan
        MjcfOptions(fluid_coefficients=(np.nan, 0.25, 1.5, 1.0, 1.0))
    with pytest.raises(ParameterError, match="spring_stiffness_N_m"):
        MjcfOptions(spring_stiffness_N_m=np.inf, spring_anchor_world_m=(0.0, 0.0, -1.0))
    text = REFERENCE_URDF.read_text().replace(
        '<box size="0.53 0.245 0.254"/></geometry>\n    </collision>',
        '<capsule radius="0.1" length="0.2"/></geometry>\n    </collision>',
    )
    assert "capsule" in text
    with pytest.raises(ModelError, match="capsule"):
        uvms_to_mjcf(uvms, text)


def test_a_body_with_volume_but_no_mass_is_refused(write_urdf):
    text = body_urdf(mass=0.0, inertia=(0.0, 0.0, 0.0), hydro=hydro_xml(0.01))
    uvms = up.load_uvms(write_urdf(text), ee_frame="body", sensor_frame="body")
    with pytest.raises(ModelError, match=r"'body' displaces .* but has no mass"):
        uvms_to_mjcf(uvms, text)


def _hydrostatics_only(uvms: up.UVMS) -> up.UVMS:
    """The same bodies and volumes with no added mass and no damping."""
    return uvms.with_hydro(
        lambda body: up.HydroParams(
            body.params.volume_m3,
            body.params.center_of_buoyancy_m,
            np.zeros((6, 6)),
            np.zeros((6, 6)),
            np.zeros(6),
        )
    )


def test_same_motion_when_the_water_only_buoys(system):
    """With MuJoCo's fluid off and uvms-pin's added mass and damping off, the two simulators
    have the same rigid dynamics plus buoyancy: the accelerations at random moving states
    agree (MuJoCo's free-joint qacc is d/dt of the WORLD linear velocity: R (a + w x v))."""
    uvms, model, data = system
    dry = _hydrostatics_only(uvms)
    model.opt.density, model.opt.viscosity = 0.0, 0.0
    rng = np.random.default_rng(16)
    try:
        for _ in range(5):
            q = _random_q(uvms, rng)
            v = rng.normal(scale=0.5, size=uvms.nv)
            tau = rng.normal(size=uvms.nv)
            data.qpos[:], data.qvel[:] = qpos_from_q(q), qvel_from_v(q, v)
            data.qfrc_applied[:] = qfrc_from_tau(q, tau)
            mujoco.mj_forward(model, data)
            zeta_dot = up.forward_dynamics(dry, q, v, tau)
            expected = qvel_from_v(q, zeta_dot)
            expected[:3] += qvel_from_v(q, np.concatenate([np.cross(v[3:6], v[:3]), v[3:]]))[:3]
            scale = max(1.0, np.abs(expected).max())
            np.testing.assert_allclose(data.qacc, expected, rtol=0, atol=1e-8 * scale)
    finally:
        data.qfrc_applied[:] = 0.0
        model.opt.density, model.opt.viscosity = (
            uvms.water_density_kg_m3,
            MjcfOptions().viscosity_Pa_s,
        )


def test_a_model_without_an_end_effector_is_exported_without_sites(tmp_path):
    """A jaw rig (tests/jaw_helpers.py) has no end-effector or sensor frame: its twin has its
    bodies and joints and no site (the export used to index the frames with None)."""
    import mujoco
    from jaw_helpers import parallel_jaw_urdf

    path = parallel_jaw_urdf(tmp_path)
    uvms = up.load_uvms(path)
    assert uvms.ee_frame_id is None and uvms.sensor_frame_id is None
    twin = mujoco.MjModel.from_xml_string(uvms_to_mjcf(uvms, path.read_text()))
    assert twin.nsite == 0 and twin.njnt == 3 and twin.nv == uvms.nv
