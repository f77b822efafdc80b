"""The centre-of-buoyancy fit: from Kolano's published hull centre of buoyancy it finds the
correction the shipped trial model carries (models/README.md section 9)."""

from __future__ import annotations

import re

import numpy as np
from conftest import ROOT

from uvms_pin.apps.validation.identify import HULL, main, with_cob
from uvms_pin.apps.validation.pool import trial_uvms

DATA = ROOT / "data" / "hinsdale2023"
KOLANO_COB_M = (0.0074, 0.0, 0.02)  # K23's hull centre of buoyancy, before the correction


def _hull_cob(uvms) -> np.ndarray:
    (hull,) = [b for b in uvms.hydro_bodies if b.name == HULL]
    return hull.params.center_of_buoyancy_m


def test_with_cob_moves_only_the_hull_centre_of_buoyancy():
    shipped = trial_uvms()
    moved = with_cob(shipped, KOLANO_COB_M)
    np.testing.assert_array_equal(_hull_cob(moved), KOLANO_COB_M)
    others = [b.params for b in shipped.hydro_bodies if b.name != HULL]
    assert [b.params for b in moved.hydro_bodies if b.name != HULL] == others


def test_from_kolanos_centre_of_buoyancy_the_fit_finds_the_shipped_correction(capsys):
    assert main([str(DATA), "--cob", *map(str, KOLANO_COB_M)]) == 0
    printed = capsys.readouterr().out
    found = re.search(r"dr_B = \[([^\]]+)\] m", printed)
    offset_m = np.array(found.group(1).split(), dtype=float)
    shipped_correction_m = _hull_cob(trial_uvms()) - np.array(KOLANO_COB_M)
    assert np.linalg.norm(shipped_correction_m) > 4e-3  # a real correction, not ~0
    np.testing.assert_allclose(offset_m, shipped_correction_m, atol=2e-6)
    assert "= (0.31, 0.55, 4.21) mm" in printed
