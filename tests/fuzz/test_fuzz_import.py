"""``uvms-pin import`` (`import_model`) given mutated Gazebo files (the importer's test data:
uuv_simulator's RexROV, gz-sim's LRAUV, a world including the LRAUV by merge): a result
written to ``out``, or a `ModelError` naming the file with nothing written."""

from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET

from fuzz_bounds import examples, outcome
from fuzz_documents import ROOT
from fuzz_xml import mutated
from hypothesis import given, settings

from uvms_pin.errors import UvmsPinWarning
from uvms_pin.model.importer.convert import import_model

DATA = ROOT / "tests" / "model" / "importer" / "data"
SOURCES = {p.name: p.read_text() for p in sorted(DATA.iterdir()) if p.suffix in (".sdf", ".urdf")}
# the LRAUV as gz-sim's tutorial world holds it: a model directory included with merge="true"
_LRAUV = ET.fromstring(SOURCES["lrauv_hydrodynamics.sdf"]).find("world/model")
INCLUDED_MODEL = f'<sdf version="1.9">{ET.tostring(_LRAUV, encoding="unicode")}</sdf>'
SOURCES["include_world.sdf"] = (
    '<sdf version="1.9"><world name="w"><plugin filename="gz-sim-buoyancy-system" '
    'name="gz::sim::systems::Buoyancy"/><model name="auv"><include merge="true">'
    "<pose>0 0 0 0 0 3.14</pose><uri>included_lrauv</uri></include></model></world></sdf>"
)


@settings(max_examples=examples(300))
@given(mutated(SOURCES))
def test_an_import_writes_or_is_refused_naming_the_file(tmp_path, named_text):
    name, text = named_text
    (tmp_path / "included_lrauv").mkdir(exist_ok=True)
    (tmp_path / "included_lrauv" / "model.sdf").write_text(INCLUDED_MODEL, encoding="utf-8")
    source = tmp_path / f"fuzzed{'.sdf' if name.endswith('.sdf') else '.urdf'}"
    source.write_text(text, encoding="utf-8")
    out = tmp_path / "out" / "vehicle.urdf"
    out.parent.mkdir(exist_ok=True)
    for old in out.parent.iterdir():
        old.unlink()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UvmsPinWarning)
        result = outcome(lambda: import_model(source, out), f"{name} mutated", named=(source.name,))
    if result is None:
        assert not any(out.parent.iterdir()), "a refused import wrote files"
    else:
        assert out.is_file()
