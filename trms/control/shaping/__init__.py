"""Command shaping: digital filters (thesis ch. 4) and the input shapers they relate to.

Modules
-------
filters      Butterworth / elliptic command filters (second-order sections) and the Prefilter protocol
vibration    residual vibration of a mode after an impulse train; the modes of a discrete model
continuous   ZV / ZVD input shapers (impulses at any time) and their convolution
sampled      input shapers on a sample grid (FIR taps that still cancel each mode exactly)
"""

from trms.control.shaping.continuous import InputShaper, shaper_for_modes, zv_shaper, zvd_shaper
from trms.control.shaping.filters import (
    CommandFilter,
    Prefilter,
    bands_around,
    butterworth_bandstop,
    butterworth_lowpass,
    elliptic_bandstop,
    multiband_bandstop,
    shape_command,
)
from trms.control.shaping.sampled import MAX_SHAPER_TAPS, SampledShaper, discrete_shaper
from trms.control.shaping.vibration import MAX_SHAPER_DAMPING, SHAPER_KINDS, model_modes

__all__ = [
    "CommandFilter",
    "Prefilter",
    "bands_around",
    "butterworth_bandstop",
    "butterworth_lowpass",
    "elliptic_bandstop",
    "multiband_bandstop",
    "shape_command",
    "MAX_SHAPER_DAMPING",
    "MAX_SHAPER_TAPS",
    "SHAPER_KINDS",
    "InputShaper",
    "discrete_shaper",
    "SampledShaper",
    "model_modes",
    "shaper_for_modes",
    "zv_shaper",
    "zvd_shaper",
]
