"""URDF loading given mutated shipped models (`fuzz_xml`): a `UVMS` whose mass matrix at the
neutral configuration is finite, or a `ModelError` naming the file."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
from fuzz_bounds import copied_tree, examples, outcome
from fuzz_documents import ROOT
from fuzz_xml import mutated
from hypothesis import given, settings

from uvms_pin.errors import UvmsPinWarning
from uvms_pin.model.urdf.load import load_uvms
from uvms_pin.physics.dynamics import mass_matrix
from uvms_pin.physics.fins import fin_generalized_force, fin_wrenches_world

MODELS = {
    p.name: p.read_text()
    for p in sorted((ROOT / "models").glob("*.urdf"), key=lambda p: p.stat().st_size)
}
#: every <lift_drag> child (docs/physics.md) on the LBV150's vehicle, its first joint the control
FIN = (
    '<lift_drag><area value="0.02"/><fluid_density value="1025"/><cla value="4.1"/>'
    '<cda value="0.2"/><cma value="0.1"/><alpha_stall value="0.17"/><cla_stall value="-1.1"/>'
    '<cda_stall value="0.03"/><cma_stall value="0"/><a0 value="0.01"/><cp xyz="-0.3 0 0"/>'
    '<forward xyz="1 0 0"/><upward xyz="0 0 1"/><radial_symmetry value="false"/>'
    '<reversible value="true"/><control_joint name="{joint}" rad_to_cl="4" cm_delta="0.1"/>'
    "</lift_drag></link>"
)
_LBV = MODELS["uvms_lbv150.urdf"]
MODELS["uvms_lbv150_fin.urdf"] = _LBV.replace(
    "</link>", FIN.format(joint=_LBV.split('<joint name="')[1].split('"')[0]), 1
)


@settings(max_examples=examples(500))
@given(mutated(MODELS))
def test_a_urdf_loads_or_is_refused_naming_the_file(named_text):
    name, text = named_text
    path = copied_tree() / "models" / "fuzzed.urdf"
    path.write_text(text, encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UvmsPinWarning)
        uvms = outcome(lambda: load_uvms(path), f"{name} mutated", named=("fuzzed.urdf",))
    if uvms is not None:
        q = pin.neutral(uvms.model)
        masses = outcome(lambda: mass_matrix(uvms, q), f"{name} mutated: M(q0)")
        assert masses is None or np.all(np.isfinite(masses))
        v = np.linspace(-1.0, 1.0, uvms.nv)
        data = uvms.model.createData()
        fins = fin_generalized_force(uvms, data, q, fin_wrenches_world(uvms, data, q, v))
        assert np.all(np.isfinite(fins))
