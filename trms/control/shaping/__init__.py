"""Command shaping: digital filters (thesis ch. 4) and the input shapers they relate to."""

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
from trms.control.shaping.shapers import (
    MAX_SHAPER_DAMPING,
    SHAPER_KINDS,
    InputShaper,
    SampledShaper,
    discrete_shaper,
    model_modes,
    shaper_for_modes,
    zv_shaper,
    zvd_shaper,
)

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
    "SHAPER_KINDS",
    "InputShaper",
    "discrete_shaper",
    "SampledShaper",
    "model_modes",
    "shaper_for_modes",
    "zv_shaper",
    "zvd_shaper",
]
