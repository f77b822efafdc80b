"""The scenario's controller re-sized for another arm: the vehicle's entries kept, k_zeta
scaled by the arm's mass matrix, the other arrays at the reference arm's median."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from uvms_pin.apps.arms.controller import controller_overrides
from uvms_pin.physics.dynamics import mass_matrix


def test_overrides_keep_the_vehicle_and_rescale_the_arm(reference_uvms):
    uvms = reference_uvms
    q = pin.neutral(uvms.model)
    k_zeta = [2.0, 1.0, 1.0, 1.0, 1.0, 0.2, 0.5, 0.5, 0.15, 0.03]
    raw = {
        "k_zeta": k_zeta,
        "velocity_weights": [1.0] * 6 + [1.0, 2.0, 3.0, 10.0],
        "rho_inf": [0.1, 0.2],  # not per velocity: left alone
        "null_space_target": [0.0, 0.0, 0.0, 0.0],
    }
    q0 = q.copy()
    q0[7:] = [0.1, 0.2, 0.3, 0.4]
    out = controller_overrides(raw, uvms, q, uvms, q0)
    assert set(out) == {
        "controller.k_zeta",
        "controller.velocity_weights",
        "controller.null_space_target",
    }
    assert out["controller.velocity_weights"] == [1.0] * 6 + [2.5] * 4
    assert out["controller.null_space_target"] == pytest.approx([0.1, 0.2, 0.3, 0.4])
    k_arm = np.asarray(out["controller.k_zeta"][6:])
    assert out["controller.k_zeta"][:6] == k_zeta[:6]
    m_ref = np.diag(mass_matrix(uvms, q))[6:]
    alpha = np.median(np.asarray(k_zeta[6:]) / m_ref)
    np.testing.assert_allclose(k_arm, alpha * np.diag(mass_matrix(uvms, q0))[6:])
