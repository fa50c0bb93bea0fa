"""Chapter 4 on a plant: the doublet runs of Tables 4.2 and 4.3 (open-loop shaping) and ZV/ZVD input shapers.

Set-up (thesis ch. 4.4-4.5, with the choices it leaves open stated)
--------------------------------------------------------------------
* Command: a doublet of :data:`DOUBLET_AMPLITUDE` V and pulse width :data:`DOUBLET_PULSE_WIDTH` s
  from :data:`DOUBLET_START` s, on one input with the others at trim (the thesis prints neither
  amplitude nor pulse width).
* 1-DOF (Table 4.2): ``Ts = 0.2 s``, :data:`RECORD_LENGTH` s; Butterworth low-pass order 3 at
  0.1 Hz and band-stop order 3, 0.2-0.4 Hz, applied causally; ZV and ZVD shapers designed from a
  model's modes. 2-DOF (Table 4.3): ``Ts = 0.1 s``, :data:`RECORD_LENGTH_2DOF` s, Butterworth LPF
  0.05 Hz and elliptic Filter-1/2/3.
* Attenuation: Welch PSD of the output under the unshaped and the shaped doublet, compared at the
  thesis's mode frequencies (:func:`trms.control.metrics.mode_attenuation`).

:func:`shaping_1dof` and :func:`shaping_2dof` run a plant (the linear model or the twin). On a linear plant the PSD
ratio at a mode is the filter's own power gain there (``Y = G F U``) blurred by leakage; the rig's ambient vibration
puts a floor under any measured attenuation. The floor the tables' notes may invoke is measured here too, with its
own check: :func:`ambient_floors` reruns the doublets on the twin under its ambient excitation (rotor-wash
turbulence, :func:`ambient_twin`) scaled up to the most its calibration allows, the level whose hover pitch RMS
(:func:`hover_pitch_rms`, the calibration's hover protocol) reaches the top of the calibrated range
(:data:`trms.reference.HOVER_PITCH_RMS`). The tables (:mod:`trms.experiments.ch4_tables`) put both worlds beside the
thesis.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import control
import numpy as np

from trms.control.metrics import mode_attenuation
from trms.control.shaping import (
    CommandFilter,
    Prefilter,
    butterworth_bandstop,
    butterworth_lowpass,
    model_modes,
    multiband_bandstop,
    shaper_for_modes,
)
from trms.errors import check_in_range
from trms.measurement.protocol import HOVER_PROTOCOL, hover_rms
from trms.plant import Plant, simulate
from trms.record import Record
from trms.reference import (
    HOVER_PITCH_RMS,
    SAMPLE_TIME_1DOF,
    SAMPLE_TIME_2DOF,
    TABLE_4_2,
    TABLE_4_2_FILTERS,
    TABLE_4_3,
    TABLE_4_3_FILTERS,
)
from trms.signals import doublet

__all__ = [
    "DOUBLET_AMPLITUDE",
    "DOUBLET_PULSE_WIDTH",
    "DOUBLET_START",
    "RECORD_LENGTH",
    "PSD_SEGMENT",
    "shaping_filters",
    "filters_2dof",
    "shaped_runs",
    "Shaping",
    "response",
    "shaping_1dof",
    "shaping_2dof",
    "ambient_twin",
    "hover_pitch_rms",
    "Floor",
    "ambient_floors",
]

#: Doublet amplitude (V), pulse width (s), first edge (s) and record length (s): this project's choices.
DOUBLET_AMPLITUDE = 0.25
DOUBLET_PULSE_WIDTH = 2.0
DOUBLET_START = 2.0
RECORD_LENGTH = 60.0
#: Welch segment (samples).
PSD_SEGMENT = 128
#: Modes of Table 4.2 (Hz), as printed.
MODES = tuple(sorted({mode for _, mode in TABLE_4_2}))
#: 2-DOF doublet record length (s) and Welch segment (samples) at Ts = 0.1 s: the 0.1 Hz yaw mode
#: decays over tens of seconds, so the record and the segments are longer than in 1-DOF.
RECORD_LENGTH_2DOF = 120.0
PSD_SEGMENT_2DOF = 256
#: Only modes below this (Hz) with damping below 0.5 get an input shaper.
SHAPER_BAND = 1.0
#: Table 4.3 channels: input and output names of "u1->y1" etc.
CHANNELS = {"u1->y1": ("u1", "pitch"), "u1->y2": ("u1", "yaw"), "u2->y2": ("u2", "yaw")}


def shaping_filters(sample_time: float = SAMPLE_TIME_1DOF) -> dict[str, CommandFilter]:
    """The two filters of Table 4.2, designed at ``sample_time``."""
    out = {}
    for name, (kind, order, freqs) in TABLE_4_2_FILTERS.items():
        out[name] = (
            butterworth_lowpass(order, freqs[0], sample_time)
            if kind == "lowpass"
            else butterworth_bandstop(order, (freqs[0], freqs[1]), sample_time)
        )
    return out


def filters_2dof(sample_time: float = SAMPLE_TIME_2DOF) -> dict[str, CommandFilter]:
    """The four filters of Table 4.3, designed at ``sample_time``."""
    out = {}
    for name, (kind, order, bands) in TABLE_4_3_FILTERS.items():
        out[name] = (
            butterworth_lowpass(order, bands[0][0], sample_time)
            if kind == "lowpass"
            else multiband_bandstop(order, [(lo, hi) for lo, hi in bands], sample_time, kind="elliptic")
        )
    return out


def shaped_runs(
    plant: Plant,
    prefilters: Mapping[str, Prefilter],
    input_index: int = 0,
    pulse_width: float = DOUBLET_PULSE_WIDTH,
    duration: float = RECORD_LENGTH,
    disturbance_std: float = 0.0,
    seed: int = 0,
) -> dict[str, Record]:
    """Run ``plant`` with the unshaped doublet and each shaped one on one input (the others at trim).

    Parameters
    ----------
    plant : Plant
        Any plant; the doublet (:data:`DOUBLET_AMPLITUDE` V, first edge at :data:`DOUBLET_START` s)
        is added to its trim.
    prefilters : mapping of name to Prefilter
        Command filters or sampled input shapers, at the plant's sample time.
    input_index : int
        The input the doublet drives.
    pulse_width, duration : float
        Doublet half length and record length (s).
    disturbance_std : float
        Standard deviation (V) of a seeded white disturbance added to the driven input, standing
        for the rig's ambient excitation; each run draws its own (seeds ``seed``, ``seed + 1``, ...).
    seed : int
        First seed (also the plant's reset seed of each run).

    Returns
    -------
    dict of str to Record
        ``"unshaped"`` first, then one per prefilter.
    """
    ts = plant.sample_time
    std = check_in_range("disturbance_std", disturbance_std, 0.0, np.inf, unit=" V")
    u = doublet(ts, pulse_width, DOUBLET_AMPLITUDE, start=DOUBLET_START, duration=duration)
    commands = {"unshaped": u}
    commands.update({name: np.asarray(f.apply(u), float).reshape(u.shape) for name, f in prefilters.items()})
    op = plant.operating_point
    out = {}
    for i, (name, cmd) in enumerate(commands.items()):
        gust = std * np.random.default_rng(seed + i).standard_normal(cmd.shape)
        out[name] = simulate(plant, op.with_signal(cmd + gust, input_index), seed=seed + i, metadata={"command": name})
    return out


def ambient_twin(config: str, scale: float, seed: int = 0) -> Plant:
    """The twin with its rotor-wash turbulence ``scale`` times the shipped model's (both rotors), at the
    thesis's sample time of ``config``: the ambient excitation the ch. 4 notes vary.

    Examples
    --------
    >>> ambient_twin("1dof", 4.0).turbulence.std[0] > 3.9 * ambient_twin("1dof", 1.0).turbulence.std[0]
    True
    """
    from trms.twin.model import load_spec, turbulence
    from trms.worlds import make_plant

    main, tail = turbulence(load_spec()).std
    check_in_range("ambient scale", scale, 0.0, 100.0)
    return make_plant(
        "twin", config, seed=seed, parameters={"main_turbulence": scale * main, "tail_turbulence": scale * tail}
    )


# ------------------------------------------------------------------------------ on any plant
#: Residual vibration is measured from this time (s) to the end of the 1-DOF record: after the
#: doublet (2 + 2 x 2 s), the shapers' last impulse (one damped period, about 3 s) and the filters' tails.
RESIDUAL_FROM = 15.0


@dataclass
class Shaping:
    """Doublet runs of one plant and the attenuations read from them.

    Attributes
    ----------
    runs : dict of str to dict of str to Record
        Per driven input name, the runs by command name (``"unshaped"`` first).
    attenuation : dict of tuple to float
        dB, keyed ``(command, mode Hz)`` (1-DOF) or ``(channel, mode Hz, command)`` (2-DOF).
    residual_db : dict of str to float
        1-DOF: reduction (dB) of the RMS pitch after :data:`RESIDUAL_FROM` s, shaped vs unshaped.
    shaper_modes : list of (float, float)
        The (Hz, damping) modes the ZV/ZVD shapers were designed for (1-DOF).
    """

    runs: dict[str, dict[str, Record]]
    attenuation: dict[tuple, float]
    residual_db: dict[str, float]
    shaper_modes: list[tuple[float, float]]


def response(rec: Record, output: str) -> np.ndarray:
    """A run's ``output`` as its deviation from the trim (rad)."""
    return rec.deviations()[1][:, rec.output_names.index(output)]


def shaping_1dof(
    plant: Plant, design_model: control.LTI, seed: int = 0, disturbance_std: float = 0.0, shapers: bool = True
) -> Shaping:
    """Table 4.2 on a 1-DOF plant, plus ZV and ZVD shapers on the same doublet.

    Parameters
    ----------
    plant : Plant
        ``u1 -> pitch`` at 0.2 s.
    design_model : control.LTI
        Discrete model whose oscillatory modes below 1 Hz (damping < 0.5) the shapers cancel,
        e.g. the ARMAX identified on the same plant (ch. 3).
    seed : int
        First seed of the runs.
    disturbance_std : float
        Ambient input disturbance (V), see :func:`shaped_runs`.
    shapers : bool
        Run the ZV and ZVD shapers too (False: Table 4.2's filters only).
    """
    ts = plant.sample_time
    prefilters: dict[str, Prefilter] = dict(shaping_filters(ts))
    modes = [(f, z) for f, z in model_modes(design_model) if f < SHAPER_BAND and z < 0.5]
    for kind in ("zv", "zvd") if modes and shapers else ():
        prefilters[kind.upper()] = shaper_for_modes(modes, kind).at(ts)
    runs = shaped_runs(plant, prefilters, 0, disturbance_std=disturbance_std, seed=seed)
    y0 = response(runs["unshaped"], "pitch")
    keep = runs["unshaped"].time >= RESIDUAL_FROM
    att, resid = {}, {}
    for name, rec in runs.items():
        if name == "unshaped":
            continue
        y = response(rec, "pitch")
        for mode, value in zip(MODES, mode_attenuation(y0, y, ts, MODES, PSD_SEGMENT)):
            att[(name, mode)] = float(value)
        resid[name] = float(20 * np.log10(np.sqrt(np.mean(y0[keep] ** 2)) / np.sqrt(np.mean(y[keep] ** 2))))
    return Shaping({"u1": runs}, att, resid, modes)


def shaping_2dof(plant: Plant, seed: int = 0, disturbance_std: float = 0.0) -> Shaping:
    """Table 4.3 on a 2-DOF plant: the doublet on each input, shaped by the filters the table uses there.

    Parameters
    ----------
    plant : Plant
        Inputs u1, u2; outputs pitch, yaw; 0.1 s.
    seed : int
        First seed of the runs.
    disturbance_std : float
        Ambient input disturbance (V), see :func:`shaped_runs`.
    """
    ts = plant.sample_time
    filters = filters_2dof(ts)
    runs, att = {}, {}
    for j, name_in in enumerate(plant.input_names):
        used = sorted({f for (ch, _, f) in TABLE_4_3 if CHANNELS[ch][0] == name_in}, key=list(filters).index)
        runs[name_in] = shaped_runs(
            plant,
            {f: filters[f] for f in used},
            j,
            duration=RECORD_LENGTH_2DOF,
            disturbance_std=disturbance_std,
            seed=seed + 20 * j,
        )
    for ch, mode, fname in TABLE_4_3:
        name_in, name_out = CHANNELS[ch]
        r = runs[name_in]
        att[(ch, mode, fname)] = float(
            mode_attenuation(
                response(r["unshaped"], name_out), response(r[fname], name_out), ts, [mode], PSD_SEGMENT_2DOF
            )[0]
        )
    return Shaping(runs, att, {}, [])


def hover_pitch_rms(scale: float = 1.0, seed: int = 0) -> float:
    """The twin's hover pitch RMS (rad) with constant inputs under its ambient excitation scaled by ``scale``: the
    calibration's hover protocol (:data:`~trms.measurement.protocol.HOVER_PROTOCOL`, 2-DOF, 120 s at trim), whose
    calibrated range is :data:`trms.reference.HOVER_PITCH_RMS`.

    Examples
    --------
    >>> lo, hi = HOVER_PITCH_RMS
    >>> lo <= hover_pitch_rms() <= hi
    True
    """
    plant = ambient_twin(HOVER_PROTOCOL.config, scale, seed)
    n = int(round(HOVER_PROTOCOL.duration_s / plant.sample_time))
    record = simulate(plant, np.tile(plant.operating_point.inputs, (n, 1)), seed=seed, channels=False)
    return hover_rms([record], "pitch")


@dataclass
class Floor:
    """The twin's shaped doublets under the most ambient excitation its calibration allows (:func:`ambient_floors`).

    Attributes
    ----------
    scale : float
        The multiple of the calibrated ambient excitation: the top of :data:`~trms.reference.HOVER_PITCH_RMS` over
        the hover pitch RMS at the calibrated level (1 when that one is above it already).
    hover_rms : dict of float to float
        The hover pitch RMS (rad) measured at 1 and at ``scale`` (:func:`hover_pitch_rms`).
    shaping_1dof, shaping_2dof : Shaping or None
        :func:`shaping_1dof` (Table 4.2's filters) and :func:`shaping_2dof` on the twin at ``scale``.
    """

    scale: float
    hover_rms: dict[float, float]
    shaping_1dof: Shaping | None
    shaping_2dof: Shaping | None

    @property
    def admissible(self) -> bool:
        """Whether the hover pitch RMS at ``scale`` lies within the calibrated range: the floor's own check."""
        lo, hi = HOVER_PITCH_RMS
        return lo <= self.hover_rms[self.scale] <= hi


def ambient_floors(design_model: control.LTI, seed: int = 0, two_dof: bool = True) -> Floor:
    """The twin's doublets of Tables 4.2 (and 4.3, ``two_dof``) under the most ambient excitation its calibration
    allows: the scale whose hover pitch RMS reaches the top of the calibrated range (from the RMS at the calibrated
    level, proportional to the turbulence), measured again there (the check).

    Parameters
    ----------
    design_model : control.LTI
        As :func:`shaping_1dof` (the shapers are not run).
    seed : int
        Seed of every run.
    two_dof : bool
        Run Table 4.3's doublets too.

    Returns
    -------
    Floor
    """
    own = hover_pitch_rms(1.0, seed)
    scale = max(1.0, HOVER_PITCH_RMS[1] / own)
    rms = {1.0: own, scale: hover_pitch_rms(scale, seed) if scale != 1.0 else own}
    one = shaping_1dof(ambient_twin("1dof", scale, seed), design_model, seed, shapers=False)
    two = shaping_2dof(ambient_twin("2dof", scale, seed), seed) if two_dof else None
    return Floor(scale, rms, one, two)
