"""The seam to the compiled core: one Backend, each concept's counterpart with named fields (or
the reason it has none), the version and the signal layout defined in C++ only, and no
dispatch by exception."""

from __future__ import annotations

import ast
import itertools
import math
import re
import warnings

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT

import uvms_pin as up
from uvms_pin.control.ppc import PPCSignals, PrescribedPerformanceController
from uvms_pin.errors import CoreFallbackWarning, ParameterError
from uvms_pin.flow import AiryWave, GaussMarkovCurrent, IrregularSea, SumFlow, UniformCurrent
from uvms_pin.physics.compiled.backend import BACKENDS, Backend, Fallback, backend_named
from uvms_pin.physics.compiled.contact import contact_to_core
from uvms_pin.physics.compiled.disturbance import disturbance_to_core
from uvms_pin.physics.compiled.dynamics import hydro_bodies_to_core
from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.physics.compiled.flow import flow_to_core
from uvms_pin.physics.contact import CompliantPlane, LinearSpring
from uvms_pin.physics.disturbance import SinusoidalDisturbance
from uvms_pin.sim.compiled.integrator import integrator_to_core
from uvms_pin.sim.integrators import RK4, Adaptive, SemiImplicitEuler
from uvms_pin.sim.plant import Plant


@pytest.fixture(scope="module")
def core():
    return core_module()


def test_one_backend_object_names_the_two_implementations():
    assert BACKENDS == ("core", "python")
    assert backend_named("core").compiled and not backend_named("python").compiled
    assert backend_named(backend_named("core")) is backend_named("core")
    for bad in ("fortran", None, 1):
        with pytest.raises(ParameterError, match="backend must be one of"):
            backend_named(bad)
    fallback = Backend("python").counterpart(lambda core: pytest.fail("never built"))
    assert isinstance(fallback, Fallback) and fallback.asked
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fallback.warn("anything")  # asked for: nothing to say
    with pytest.warns(CoreFallbackWarning, match="the compiled core does not support a flow"):
        Fallback("a flow").warn("these dynamics")


def test_hydro_bodies_have_named_fields_equal_to_the_model(reference_uvms, core):
    uvms = reference_uvms
    bodies = hydro_bodies_to_core(uvms, core)
    assert bodies.water_density_kg_m3 == uvms.water_density_kg_m3
    np.testing.assert_array_equal(np.array(bodies.added_mass_per_joint), uvms.added_mass_per_joint)
    np.testing.assert_array_equal(bodies.volume_per_joint_m3, uvms.volume_per_joint_m3)
    np.testing.assert_array_equal(
        np.array(bodies.center_of_buoyancy_per_joint_m), uvms.center_of_buoyancy_per_joint_m
    )
    damped = uvms.hydro_bodies_with_damping
    assert [b.joint_id for b in bodies.damped_bodies] == [b.joint_id for b in damped]
    for compiled, body in zip(bodies.damped_bodies, damped, strict=True):
        np.testing.assert_array_equal(compiled.linear_damping, body.params.linear_damping)
        np.testing.assert_array_equal(compiled.quadratic_damping, body.params.quadratic_damping)
        np.testing.assert_array_equal(
            compiled.position_in_joint_m, body.placement_in_joint.translation
        )


def test_a_flow_is_one_field_of_current_and_waves_or_its_reason(core):
    current = UniformCurrent([0.2, -0.1, 0.0])
    wave = AiryWave(0.3, 5.0, heading_rad=0.4, water_depth_m=20.0)
    compiled = flow_to_core(SumFlow((current, wave, UniformCurrent([0.1, 0.0, 0.0]))), core)
    np.testing.assert_allclose(compiled.current_world_m_s, [0.3, -0.1, 0.0], rtol=0, atol=1e-15)
    assert compiled.water_depth_m == 20.0 and len(compiled.waves) == 1
    w, c = compiled.waves[0], wave.components
    assert (w.amplitude_m, w.heading_rad) == (c.amplitude_m[0], c.heading_rad[0])
    assert w.wavenumber_rad_m == c.wavenumber_rad_m[0]
    sea = flow_to_core(IrregularSea(0.5, 6.0, n_components=20, seed=3), core)
    assert len(sea.waves) == 20 and math.isinf(sea.water_depth_m)
    reason = flow_to_core(GaussMarkovCurrent([0.1, 0, 0], 0.05, 5.0, 0.1), core)
    assert isinstance(reason, Fallback) and "GaussMarkovCurrent" in reason.reason
    mixed = flow_to_core(AiryWave(0.1, 4.0, water_depth_m=5.0) + AiryWave(0.1, 4.0), core)
    assert isinstance(mixed, Fallback) and "different water depths" in mixed.reason


def test_contact_and_disturbance_counterparts(core):
    spring = LinearSpring([2.0, 3.0, 4.0])
    assert isinstance(contact_to_core(spring, core), Fallback)  # placed when a run starts
    spring.attach(np.array([1.0, 2.0, 3.0]))
    compiled = contact_to_core(spring, core)
    np.testing.assert_array_equal(compiled.anchor_world_m, [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(compiled.stiffness_N_m, [2.0, 3.0, 4.0])
    plane = CompliantPlane([0, 0, 2.0], 500.0, 3.0, point_world_m=[0, 0, -1.0])
    compiled = contact_to_core(plane, core)
    np.testing.assert_array_equal(compiled.normal_world, [0, 0, 1.0])
    assert (compiled.stiffness_N_m, compiled.damping_N_s_m) == (500.0, 3.0)
    assert isinstance(contact_to_core(None, core), core.NoContact)
    gust = SinusoidalDisturbance(np.arange(6.0), 4.0, 0.5)
    compiled = disturbance_to_core(gust, core)
    np.testing.assert_array_equal(compiled.amplitude, np.arange(6.0))
    assert (compiled.period_s, compiled.phase_rad) == (4.0, 0.5)
    assert disturbance_to_core(None, core) is None
    assert isinstance(disturbance_to_core(lambda t: np.zeros(6), core), Fallback)


class _StifferPlane(CompliantPlane):
    """A user's contact model: a compliant plane pushing twice as hard."""

    def wrench_on_environment_world(self, position_world_m, velocity_world_m_s):
        return 2.0 * super().wrench_on_environment_world(position_world_m, velocity_world_m_s)


class _QuietSpring(LinearSpring):
    """A user's subclass of the spring (its law unchanged, but its own)."""


def test_a_subclass_of_a_contact_model_has_no_counterpart(core, reference_uvms):
    """The core mirrors LinearSpring and CompliantPlane, not a user's subclass of them (whose
    law may differ): a Fallback naming it, and a plant with it runs its own law."""
    spring = _QuietSpring([2.0, 3.0, 4.0], anchor_world_m=[0.0, 0.0, 0.0])
    assert isinstance(contact_to_core(spring, core), Fallback)
    assert "_QuietSpring" in contact_to_core(spring, core).reason
    q, v = reference_uvms.neutral_configuration(), np.full(reference_uvms.nv, 0.1)
    data = reference_uvms.model.createData()
    pin.forwardKinematics(reference_uvms.model, data, q)
    tip = pin.updateFramePlacement(reference_uvms.model, data, reference_uvms.ee_frame_id)
    plane = _StifferPlane(
        [0, 0, 1.0], 500.0, 3.0, point_world_m=tip.translation + np.array([0, 0, 0.02])
    )
    assert isinstance(contact_to_core(plane, core), Fallback)
    expected = Plant(reference_uvms, contact=plane, backend="python")
    with pytest.warns(CoreFallbackWarning, match="_StifferPlane"):
        got = Plant(reference_uvms, contact=plane, backend="core").contact_wrench(q, v)
    assert np.linalg.norm(got) > 1.0
    np.testing.assert_array_equal(got, expected.contact_wrench(q, v))


def test_integrators_say_their_counterpart(core):
    compiled = integrator_to_core(RK4(2.5e-4), core)
    assert compiled.method == core.Method.rk4 and compiled.step_s == 2.5e-4
    euler = integrator_to_core(SemiImplicitEuler(1e-4), core)
    assert euler.method == core.Method.semi_implicit_euler
    assert isinstance(integrator_to_core(Adaptive(), core), Fallback)


def test_the_api_version_is_defined_in_cpp_only(core):
    header = (ROOT / "src" / "uvms_core" / "types.hpp").read_text()
    version = int(re.search(r"constexpr int kApiVersion = (\d+);", header).group(1))
    assert core.API_VERSION == version
    for path in (ROOT / "uvms_pin").rglob("*.py"):
        assert "API_VERSION =" not in path.read_text(), path


def test_the_ppc_signal_layout_comes_from_the_kernel(reference_uvms):
    model = reference_uvms.model
    frame = model.frames[reference_uvms.ee_frame_id].name
    kernel = PrescribedPerformanceController(model, frame)._kernel
    layout = kernel.kernel.signal_layout()
    spans = list(layout.values())
    assert spans[0][0] == 0 and all(a[1] == b[0] for a, b in itertools.pairwise(spans))
    assert spans[-1][1] == kernel.packed.size  # contiguous, covering the whole buffer
    assert list(layout)[:-1] == [
        f for f in PPCSignals.__dataclass_fields__ if f in layout
    ]  # the Python signals' order
    assert (
        layout["tau"][1] - layout["tau"][0] == model.nv and layout["margin"][1] - 1 == spans[-1][0]
    )


@pytest.mark.parametrize(
    ("value", "message"),
    [
        (None, r"q must have shape \(11,\), got a NoneType"),
        ("abc", r"q must have shape \(11,\), got a str"),
        (np.zeros((1, 11)), r"q must have shape \(11,\), got \(1, 11\)"),
        (np.zeros(3), r"q must have shape \(11,\), got \(3,\)"),
    ],
)
def test_compiled_calls_name_a_bad_vector(reference_uvms, value, message):
    with pytest.raises(ParameterError, match=message):
        up.mass_matrix(reference_uvms, value)


@pytest.mark.parametrize("backend", ["core", "python"])
def test_a_complex_array_is_refused_not_cast(reference_uvms, backend):
    """Casting would drop the imaginary part (numpy's ComplexWarning, or under -W error a
    'must have shape (11,), got (11,)'): both backends refuse it, naming the argument."""
    uvms = reference_uvms
    q, v = uvms.neutral_configuration(), np.zeros(uvms.nv)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no ComplexWarning on the way
        with pytest.raises(ParameterError, match=r"q must be 11 real numbers, got a complex"):
            up.forward_dynamics(uvms, q.astype(complex), v, v, backend=backend)
        with pytest.raises(ParameterError, match=r"tau must be 10 real numbers, got a complex"):
            up.forward_dynamics(uvms, q, v, v + 0j, backend=backend)


def test_compiled_calls_take_lists_and_other_dtypes(reference_uvms):
    q = reference_uvms.neutral_configuration()
    expected = up.mass_matrix(reference_uvms, q)
    np.testing.assert_array_equal(up.mass_matrix(reference_uvms, q.tolist()), expected)
    np.testing.assert_array_equal(up.mass_matrix(reference_uvms, q[::-1][::-1]), expected)
    v = np.zeros(reference_uvms.nv, dtype=np.int64)
    np.testing.assert_array_equal(
        up.bias_forces(reference_uvms, q, v), up.bias_forces(reference_uvms, q, v * 0.0)
    )


def test_no_dispatch_by_exception_on_the_seam():
    """No ``except TypeError`` left where Python meets the core: a failed conversion is the
    binding's to name (ParameterError), not a signal to try again another way."""
    for path in [
        *(ROOT / "uvms_pin" / "physics").rglob("*.py"),
        *(ROOT / "uvms_pin" / "control").rglob("*.py"),
        ROOT / "uvms_pin" / "sim" / "plant.py",
    ]:
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ExceptHandler) and isinstance(node.type, ast.Name):
                assert node.type.id != "TypeError", f"{path}:{node.lineno}"
