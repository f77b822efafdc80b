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

MODELS = {
    p.name: p.read_text()
    for p in sorted((ROOT / "models").glob("*.urdf"), key=lambda p: p.stat().st_size)
}


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
