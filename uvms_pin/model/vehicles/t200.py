"""Blue Robotics T200 thruster: the published bollard thrust at 16 V.

Source: Blue Robotics, "T200 Public Performance Data 10-20V (September 2019)" workbook
(https://cad.bluerobotics.com/T200-Public-Performance-Data-10-20V-September-2019.xlsx), sheet
"16 V", columns "PWM (us)" and "Force (Kg f)": one T200 on a Basic ESC R3 (BLHeli_S 16.6),
static water, ESC PWM input from 1100 to 1900 us in steps of 4 us, each point the mean of 20
samples; rotation below 300 RPM is reported as zero thrust, which is the deadband (1472 to
1528 us). 16 V is the supply the BlueROV2's 4S battery gives. 1500 us is neutral; the
command u of uvms-pin is (PWM - 1500 us) / 400 us, in [-1, 1].
"""

from __future__ import annotations

import numpy as np

from uvms_pin.model.thrust_curve import TabulatedThrustCurve

__all__ = ["T200_16V_PWM_US", "T200_16V_THRUST_KGF", "STANDARD_GRAVITY_M_S2", "t200_16v_curve"]

#: g_n [m/s^2]: kilogram-force to newton.
STANDARD_GRAVITY_M_S2 = 9.80665

#: ESC input [us], 1100..1900 in steps of 4.
T200_16V_PWM_US = np.arange(1100, 1901, 4, dtype=float)

#: Bollard thrust [kgf] at each PWM of `T200_16V_PWM_US` (the sheet's values).
T200_16V_THRUST_KGF = np.array(
    [
    -4.07, -4.05, -4.02, -3.96, -3.90, -3.87, -3.82, -3.80, -3.75, -3.71,
    -3.66, -3.59, -3.52, -3.45, -3.40, -3.31, -3.25, -3.20, -3.11, -3.04,
    -2.99, -2.94, -2.86, -2.82, -2.77, -2.71, -2.66, -2.58, -2.55, -2.51,
    -2.45, -2.38, -2.35, -2.28, -2.24, -2.20, -2.12, -2.08, -2.02, -1.98,
    -1.94, -1.86, -1.81, -1.76, -1.70, -1.67, -1.61, -1.56, -1.51, -1.49,
    -1.44, -1.40, -1.35, -1.30, -1.26, -1.20, -1.16, -1.12, -1.10, -1.05,
    -1.02, -0.98, -0.94, -0.90, -0.87, -0.82, -0.78, -0.74, -0.72, -0.68,
    -0.65, -0.62, -0.58, -0.54, -0.51, -0.48, -0.44, -0.42, -0.39, -0.35,
    -0.32, -0.29, -0.26, -0.24, -0.21, -0.18, -0.15, -0.13, -0.10, -0.09,
    -0.07, -0.05, -0.04, 0.00, 0.00, 0.00, 0.00, 0.00, 0.00, 0.00,
    0.00, 0.00, 0.00, 0.00, 0.00, 0.00, 0.00, 0.00, 0.04, 0.05,
    0.08, 0.10, 0.13, 0.15, 0.18, 0.22, 0.25, 0.29, 0.32, 0.36,
    0.40, 0.44, 0.47, 0.51, 0.56, 0.60, 0.64, 0.68, 0.72, 0.78,
    0.82, 0.87, 0.91, 0.95, 0.99, 1.03, 1.10, 1.14, 1.18, 1.24,
    1.28, 1.33, 1.39, 1.44, 1.48, 1.54, 1.59, 1.65, 1.69, 1.76,
    1.82, 1.88, 1.93, 1.99, 2.05, 2.12, 2.18, 2.22, 2.28, 2.38,
    2.43, 2.52, 2.58, 2.65, 2.73, 2.76, 2.84, 2.89, 2.98, 3.05,
    3.11, 3.17, 3.22, 3.30, 3.37, 3.42, 3.51, 3.61, 3.68, 3.74,
    3.82, 3.89, 3.96, 4.06, 4.15, 4.25, 4.30, 4.38, 4.51, 4.53,
    4.65, 4.71, 4.79, 4.84, 4.93, 5.01, 5.08, 5.14, 5.18, 5.22,
    5.25,
    ]
)


def t200_16v_curve() -> TabulatedThrustCurve:
    """The T200's thrust [N] against the command u = (PWM - 1500) / 400, at 16 V:
    5.25 kgf (51.5 N) forward and 4.07 kgf (39.9 N) reverse at full command."""
    return TabulatedThrustCurve(
        (T200_16V_PWM_US - 1500.0) / 400.0,
        T200_16V_THRUST_KGF * STANDARD_GRAVITY_M_S2,
        name="T200 at 16 V (Blue Robotics, 2019)",
    )
