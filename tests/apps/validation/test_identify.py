"""The trial vehicle's identified centre-of-buoyancy shift, derived again from the trials.

The shift is an input of ``models/derive_bluerov_alpha5.py`` (``TRIAL_COB_CORRECTION_M``),
fitted once by ``python -m uvms_pin.apps.validation.identify data/hinsdale2023`` on the
file without it (models/README.md, section 9); here the same fit runs again, through the
library and through the command line's ``--cob`` (from Kolano's published hull centre of
buoyancy, as docs/validation.md shows it).
"""

from __future__ import annotations

import importlib.util
import re

import numpy as np
from conftest import ROOT

from uvms_pin.apps.validation.identify import (
    HULL,
    IDENTIFICATION_TRIALS,
    fit_centre_of_buoyancy,
    main,
    with_cob,
    with_cob_offset,
)
from uvms_pin.apps.validation.pool import trial_uvms
from uvms_pin.apps.validation.trials import find_trials

DATA = ROOT / "data" / "hinsdale2023"
KOLANO_COB_M = (0.0074, 0.0, 0.02)  # K23's hull centre of buoyancy, before the correction


def _derivation():
    """models/derive_bluerov_alpha5.py as a module (it is a script, not a package)."""
    path = ROOT / "models" / "derive_bluerov_alpha5.py"
    spec = importlib.util.spec_from_file_location("derive_bluerov_alpha5", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _hull_cob(uvms) -> np.ndarray:
    (hull,) = [b for b in uvms.hydro_bodies if b.name == HULL]
    return hull.params.center_of_buoyancy_m


def test_the_shipped_cob_shift_is_the_fit_on_the_identification_trials():
    """From the trial vehicle without the shift (K23's centre of buoyancy), the least-squares
    fit on the identification trials (families 001 and 008, every 10th IMU sample) gives the
    shipped shift back, to the 6 decimals it is written with (|fit - written| <= 0.5e-6 m,
    plus 2e-8 m for the solver's own tolerance), and nearly halves the quasi-static roll
    and pitch error (0.91, 0.99 deg RMS -> 0.50, 0.52 deg)."""
    derivation = _derivation()
    shift = np.array(derivation.TRIAL_COB_CORRECTION_M)
    uvms = trial_uvms()
    np.testing.assert_allclose(_hull_cob(uvms), np.add(derivation.TRIAL_COB_M, shift), atol=1e-12)
    trials = {p.stem: p for p in find_trials(DATA)}
    identification = [trials[name] for name in IDENTIFICATION_TRIALS]
    assert len(identification) == 6
    fitted, before, after = fit_centre_of_buoyancy(with_cob_offset(uvms, -shift), identification)
    np.testing.assert_allclose(fitted, shift, rtol=0, atol=0.5e-6 + 2e-8)
    rms_before, rms_after = np.sqrt(np.mean(before**2, axis=0)), np.sqrt(np.mean(after**2, axis=0))
    assert np.all(rms_after < 0.6 * rms_before), (np.degrees(rms_before), np.degrees(rms_after))


def test_with_cob_moves_only_the_hull_centre_of_buoyancy():
    shipped = trial_uvms()
    moved = with_cob(shipped, KOLANO_COB_M)
    np.testing.assert_array_equal(_hull_cob(moved), KOLANO_COB_M)
    others = [b.params for b in shipped.hydro_bodies if b.name != HULL]
    assert [b.params for b in moved.hydro_bodies if b.name != HULL] == others


def test_from_kolanos_centre_of_buoyancy_the_cli_finds_the_shipped_correction(capsys):
    assert main([str(DATA), "--cob", *map(str, KOLANO_COB_M)]) == 0
    printed = capsys.readouterr().out
    found = re.search(r"dr_B = \[([^\]]+)\] m", printed)
    offset_m = np.array(found.group(1).split(), dtype=float)
    shipped_correction_m = _hull_cob(trial_uvms()) - np.array(KOLANO_COB_M)
    assert np.linalg.norm(shipped_correction_m) > 4e-3  # a real correction, not ~0
    np.testing.assert_allclose(offset_m, shipped_correction_m, atol=2e-6)
    assert "= (0.31, 0.55, 4.21) mm" in printed
