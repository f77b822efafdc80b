"""``uvms-pin import`` (`import_model`) given mutated Gazebo files (the importer's test data:
uuv_simulator's RexROV, gz-sim's LRAUV): a result written to ``out``, or a `ModelError`
naming the file with nothing written."""

from __future__ import annotations

import warnings

from fuzz_bounds import examples, outcome
from fuzz_documents import ROOT
from fuzz_xml import mutated
from hypothesis import given, settings

from uvms_pin.errors import UvmsPinWarning
from uvms_pin.model.importer.convert import import_model

DATA = ROOT / "tests" / "model" / "importer" / "data"
SOURCES = {p.name: p.read_text() for p in sorted(DATA.iterdir()) if p.suffix in (".sdf", ".urdf")}


@settings(max_examples=examples(300))
@given(mutated(SOURCES))
def test_an_import_writes_or_is_refused_naming_the_file(tmp_path, named_text):
    name, text = named_text
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
