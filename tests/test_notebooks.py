"""The example notebooks execute from top to bottom (with a short duration)."""

from __future__ import annotations

import pytest
from conftest import ROOT

nbformat = pytest.importorskip("nbformat", reason="notebook tests need the dev extra")
nbclient = pytest.importorskip("nbclient", reason="notebook tests need the dev extra")

NOTEBOOK = ROOT / "notebooks" / "getting_started.ipynb"


def _with_parameters(nb, source: str):
    cells = [c for c in nb.cells if "parameters" in c.get("metadata", {}).get("tags", [])]
    assert len(cells) == 1, "the notebook needs exactly one cell tagged 'parameters'"
    cells[0].source = source
    return nb


SCRIPTING = ROOT / "notebooks" / "scripting.ipynb"


@pytest.mark.parametrize("path", [NOTEBOOK, SCRIPTING], ids=lambda p: p.name)
def test_notebook_is_committed_without_outputs(path):
    nb = nbformat.read(path, as_version=4)
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert code and all(not c.outputs and c.execution_count is None for c in code)


def test_getting_started_executes(tmp_path):
    nb = _with_parameters(nbformat.read(NOTEBOOK, as_version=4), "DURATION_S = 0.1")
    client = nbclient.NotebookClient(
        nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
    )
    client.execute()  # raises CellExecutionError naming the failing cell
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    text = "\n".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    assert "ok - simulated 0.10 s" in text
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) == 2  # rollout.plot("force") and figures["first_level"]
    tables = [o for o in outputs if "text/html" in o.get("data", {})]
    assert any("wrench_contact_world.fx_N" in o["data"]["text/html"] for o in tables)


def test_scripting_executes(tmp_path):
    nb = _with_parameters(nbformat.read(SCRIPTING, as_version=4), "DURATION_S = 3.0")
    client = nbclient.NotebookClient(
        nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
    )
    client.execute()
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    text = "\n".join(o.get("text", "") or o.get("data", {}).get("text/plain", "") for o in outputs)
    assert "task_position_error_rms_m" in text and "vehicle_excursion_max_m" in text
    assert "[task] has unknown key(s): radius" in text  # the misspelt key, named
    assert "'hold_error.x_m': 'm'" in text and "'arm_rates.j1_rad_s': 'rad/s'" in text
    assert len([o for o in outputs if "image/png" in o.get("data", {})]) == 1
