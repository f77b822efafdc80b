"""Flow fields: the undisturbed water velocity u(t, p) and its material acceleration Du/Dt.

Every field evaluates at arrays of world points (n, 3) [m] and returns world-frame
velocities [m/s] and accelerations [m/s^2]. World z is up and z = 0 is the mean free
surface. Fields add up: ``UniformCurrent(...) + AiryWave(...)`` is a field too.
"""

from uvms_pin.flow.airy import AiryWave, wavenumber
from uvms_pin.flow.base import FlowField, SumFlow, as_points
from uvms_pin.flow.components import Waves
from uvms_pin.flow.gauss_markov import GaussMarkovCurrent
from uvms_pin.flow.irregular import IrregularSea
from uvms_pin.flow.profile import DepthProfileCurrent
from uvms_pin.flow.record import flow_from_record
from uvms_pin.flow.spectrum import jonswap_spectrum, pierson_moskowitz_spectrum
from uvms_pin.flow.uniform import UniformCurrent

__all__ = [
    "AiryWave",
    "DepthProfileCurrent",
    "FlowField",
    "GaussMarkovCurrent",
    "IrregularSea",
    "SumFlow",
    "UniformCurrent",
    "Waves",
    "as_points",
    "flow_from_record",
    "jonswap_spectrum",
    "pierson_moskowitz_spectrum",
    "wavenumber",
]
