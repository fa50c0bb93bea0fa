"""The thesis's published models and tables, as data (the one place thesis numbers live).

Source: "Modelling and Control of a Twin Rotor MIMO System" (the thesis). Section,
equation and table numbers below are the thesis's.

Two realisations of the 1-DOF pitch model are printed:

* eq. (3.11), the identified ARMAX transfer function ``y1/u1`` at ``Ts = 0.2 s`` --
  strictly proper as eq. (3.2) requires. **This is the reference plant.**
* eq. (6.33), a state space used for the LQG design in ch. 6. It has the same poles,
  but ``D = 0.0097`` (the leading numerator coefficient): it realises ``z G(z)``, one
  sample ahead of (3.11). It is provided for comparison with the printed design.
"""

from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np

__all__ = [
    "SAMPLE_TIME_1DOF",
    "SAMPLE_TIME_2DOF",
    "VOLTAGE_LIMIT",
    "SAMPLE_TIME_RANGE",
    "CONFIGURATION_NAMES",
    "END_STOPS",
    "EQ_3_11_NUM",
    "EQ_3_11_DEN",
    "eq_3_11",
    "eq_6_33",
    "ReportedMode",
    "MODE_TABLE",
    "PSD_MODES_1DOF",
    "MAIN_MODE_HZ",
    "SLOW_MODE_HZ",
    "TABLE_3_1_MODES_HZ",
    "SIDE_PEAKS_1DOF_HZ",
    "TABLE_4_2",
    "TABLE_4_3",
    "TABLE_5_1",
    "TABLE_6_1",
    "LQG_WEIGHTS_R",
    "TABLE_4_2_FILTERS",
    "TABLE_6_1_PREFILTERS",
    "TABLE_4_3_FILTERS",
    "CHAPTER_7_PREFILTERS",
    "CHAPTER_7_OUTCOMES",
    "CHAPTER_7_PREFILTER_OUTCOMES",
    "PUSH_TIME_RANGE",
    "PUSH_WEIGHTS_R",
    "EQ_3_11_MODE",
    "EQ_3_11_DC_GAIN",
    "HOVER_PITCH_RMS",
    "PRINTED",
    "FROM_EQ_3_11",
    "FROM_TABLE_5_1",
    "LITERATURE",
    "CHOSEN_HERE",
    "SOURCES",
    "eq_3_11_text",
    "FILTER_2_BANDS",
]

#: Sample time of the 1-DOF model and controller (s), ch. 3.2.4 and ch. 6.
SAMPLE_TIME_1DOF = 0.2
#: Sample time of the 2-DOF data (s), ch. 3.4 (10 Hz).
SAMPLE_TIME_2DOF = 0.1
#: Motor input voltage limit (V), ch. 2.1: inputs are limited to +-10 V.
VOLTAGE_LIMIT = 10.0
#: The real-time kernel's sample period range and resolution (s), Appendix 1 (SetSampleTime).
SAMPLE_TIME_RANGE = (0.001, 32.767, 0.001)
#: The rig's configurations, ch. 2-3: yaw locked (1-DOF, u1 -> pitch), both axes free (2-DOF), pitch locked (yaw).
CONFIGURATION_NAMES = ("1dof", "2dof", "yaw")
#: The rig's end stops (rad), ``|angle|`` where the beam meets its stops; the shipped MJCF's pitch and yaw joint
#: ranges are these (checked by the model's tests), so records that pass them cannot come from the rig.
END_STOPS = {"pitch": 1.1, "yaw": 3.0}

#: Where a value a table sets beside the twin's comes from (the "source" column): printed in the thesis, derived from
#: eq. (3.11) or from Table 5.1 (computed here from the printed numbers), published elsewhere, or a target this project
#: chose where the thesis prints none.
PRINTED = "thesis (printed)"
FROM_EQ_3_11 = "from eq. 3.11"
FROM_TABLE_5_1 = "from Table 5.1"
LITERATURE = "literature"
CHOSEN_HERE = "target chosen here"
SOURCES = (PRINTED, FROM_EQ_3_11, FROM_TABLE_5_1, LITERATURE, CHOSEN_HERE)

#: Numerator of eq. (3.11), descending powers of z (y1 in rad, u1 in V).
EQ_3_11_NUM = (0.0097, -0.0086, 0.006, 0.0284)
#: Denominator of eq. (3.11), descending powers of z.
EQ_3_11_DEN = (1.0, -3.0077, 3.5001, -1.8096, 0.3407)


def eq_3_11() -> control.TransferFunction:
    """The identified 1-DOF pitch model, eq. (3.11): ``y1/u1`` at ``Ts = 0.2 s``.

    Returns
    -------
    control.TransferFunction
        Discrete, ``dt = 0.2`` s; input ``u1`` (V), output ``y1`` (rad).
    """
    return control.tf(
        list(EQ_3_11_NUM), list(EQ_3_11_DEN), SAMPLE_TIME_1DOF, inputs=["u1"], outputs=["pitch"], name="eq_3_11"
    )


def eq_3_11_text() -> str:
    """Eq. (3.11) as the thesis prints it: every coefficient at its printed precision, descending powers of z.

    Examples
    --------
    >>> eq_3_11_text()
    'G(z) = (0.0097 z^3 - 0.0086 z^2 + 0.006 z + 0.0284) / (z^4 - 3.0077 z^3 + 3.5001 z^2 - 1.8096 z + 0.3407)'
    """

    def poly(coefficients: tuple[float, ...]) -> str:
        n = len(coefficients) - 1
        terms = []
        for k, c in enumerate(coefficients):
            power = n - k
            z = "" if power == 0 else "z" if power == 1 else f"z^{power}"
            size = repr(abs(c)) if (abs(c) != 1.0 or not z) else ""
            body = f"{size} {z}".strip() if size else z
            terms.append(("- " if c < 0 else "+ ") + body)
        return " ".join(terms).removeprefix("+ ")

    return f"G(z) = ({poly(EQ_3_11_NUM)}) / ({poly(EQ_3_11_DEN)})"


def eq_6_33() -> control.StateSpace:
    """The state space printed as eq. (6.33), with its direct term ``D = 0.0097``.

    Same poles as (3.11) (observer canonical form, coefficients rounded as printed) but one
    sample ahead of it; see the module docstring.

    Returns
    -------
    control.StateSpace
        Discrete, ``dt = 0.2`` s.
    """
    A = np.array([[3.007, 1.0, 0.0, 0.0], [-3.5, 0.0, 1.0, 0.0], [1.8096, 0.0, 0.0, 1.0], [-0.341, 0.0, 0.0, 0.0]])
    B = np.array([[0.0205], [-0.0278], [0.0458], [-0.0033]])
    C = np.array([[1.0, 0.0, 0.0, 0.0]])
    D = np.array([[0.0097]])
    return control.ss(A, B, C, D, SAMPLE_TIME_1DOF, inputs=["u1"], outputs=["pitch"], name="eq_6_33")


@dataclass(frozen=True)
class ReportedMode:
    """A row of Table 3.1 / 4.1: the frequency of a mode the thesis reports for one channel.

    Not a :class:`trms.modes.Mode` (the thesis prints no damping for these): a table entry."""

    configuration: str  # "1dof" or "2dof"
    channel: str  # e.g. "u1->y1"
    frequency_hz: float


#: Table 3.1 / 4.1: modes by channel. The 2-DOF u2 -> y1 channel has none (low coherence, not modelled).
MODE_TABLE: tuple[ReportedMode, ...] = (
    ReportedMode("1dof", "u1->y1", 0.25),
    ReportedMode("1dof", "u1->y1", 0.34),
    ReportedMode("2dof", "u1->y1", 0.10),
    ReportedMode("2dof", "u1->y1", 0.34),
    ReportedMode("2dof", "u1->y2", 0.10),
    ReportedMode("2dof", "u2->y2", 0.10),
)
#: Peaks of the 1-DOF pitch PSD (ch. 3.3.1), Hz: 0.25 and 0.34, and a weaker 0.46.
PSD_MODES_1DOF = (0.25, 0.34, 0.46)
#: The rig's main resonance (Hz): the 1-DOF and 2-DOF u1 -> pitch mode of Table 3.1, eq. (3.11)'s pole pair.
MAIN_MODE_HZ = 0.34
#: The slow 2-DOF mode (Hz) of Table 3.1, on u1 -> pitch, u1 -> yaw and u2 -> yaw.
SLOW_MODE_HZ = 0.10
#: The two modes Table 3.1 gives the 2-DOF rig (Hz), slowest first.
TABLE_3_1_MODES_HZ = (SLOW_MODE_HZ, MAIN_MODE_HZ)
#: The 1-DOF pitch PSD's peaks beside the main one (Hz): 0.25 (also in Table 3.1) and the weaker 0.46.
SIDE_PEAKS_1DOF_HZ = tuple(f for f in PSD_MODES_1DOF if f != MAIN_MODE_HZ)

#: Table 4.2, 1-DOF, Ts = 0.2 s: attenuation (dB) of the pitch PSD at each mode vs the unshaped doublet.
#: LPF: Butterworth order 3, cut-off 0.1 Hz; BSF: Butterworth order 3, 0.2-0.4 Hz.
TABLE_4_2 = {
    ("LPF 0.1 Hz", 0.25): 5.83,
    ("LPF 0.1 Hz", 0.34): 7.0,
    ("BSF 0.2-0.4 Hz", 0.25): 0.83,
    ("BSF 0.2-0.4 Hz", 0.34): 1.83,
}

#: Table 4.3, 2-DOF, Ts = 0.1 s: attenuation (dB) by (channel, mode Hz, filter). Empty cells are absent.
#: Filter-1: elliptic band-stop order 2, 0.25-0.4 Hz; Filter-2: 0.05-0.15 and 0.25-0.4 Hz (the table
#: prints 0.01-0.15); Filter-3: 0.05-0.15 Hz; LPF: Butterworth order 3, 0.05 Hz.
TABLE_4_3 = {
    ("u1->y1", 0.10, "Filter-2"): 20.0,
    ("u1->y1", 0.10, "LPF 0.05 Hz"): 10.45,
    ("u1->y1", 0.34, "Filter-1"): 13.98,
    ("u1->y1", 0.34, "Filter-2"): 13.98,
    ("u1->y1", 0.34, "LPF 0.05 Hz"): 20.91,
    ("u1->y2", 0.10, "Filter-2"): 36.25,
    ("u1->y2", 0.10, "LPF 0.05 Hz"): 24.22,
    ("u2->y2", 0.10, "Filter-3"): 18.59,
    ("u2->y2", 0.10, "LPF 0.05 Hz"): 10.63,
}

#: Table 5.1: variance of residuals on the 1-DOF data.
TABLE_5_1 = {"linear ARMAX": 8.93e-06, "NARX-RBF": 6.42e-06}

#: Table 6.1 (simulation on the linear model): (R, case) -> (rise time s, settling time (lo, hi) s, control).
#: "high" means the control went beyond the actuator limit.
TABLE_6_1 = {
    (75.0, "SAS"): (3.0, (12.0, 12.0), "high"),
    (75.0, "CSAS LPF 0.2 Hz"): (4.5, (7.0, 8.0), "ok"),
    (75.0, "CSAS LPF 0.3 Hz"): (3.0, (10.0, 10.0), "ok"),
    (75.0, "CSAS BSF 0.25 & 0.34 Hz"): (4.0, (13.0, 13.0), "high"),
    (1.0, "SAS"): (1.0, (5.0, 6.0), "high"),
    (1.0, "CSAS LPF 0.2 Hz"): (2.5, (6.0, 7.0), "ok"),
    (1.0, "CSAS LPF 0.3 Hz"): (3.0, (5.5, 5.5), "high"),
    (1.0, "CSAS BSF 0.25 & 0.34 Hz"): (2.5, (12.0, 12.0), "high"),
}

#: The LQG control weights R used in ch. 6 and 7 (Q = I throughout).
LQG_WEIGHTS_R = (75.0, 1.0, 100.0, 125.0)


#: Ch. 4.4 (Table 4.2): the 1-DOF shaping filters of the doublet, as (kind, order, frequencies Hz).
#: Butterworth low-pass order 3 cut-off 0.1 Hz; Butterworth band-stop order 3, 0.2-0.4 Hz.
TABLE_4_2_FILTERS = {
    "LPF 0.1 Hz": ("lowpass", 3, (0.1,)),
    "BSF 0.2-0.4 Hz": ("bandstop", 3, (0.2, 0.4)),
}

#: Ch. 6.9 (Table 6.1): the CSAS command prefilters, as (kind, order, frequencies Hz, bandwidth Hz).
#: Butterworth low-pass order 2 at 0.2 and 0.3 Hz; Butterworth band-stop order 2 "centre frequency
#: 0.25 and 0.34 Hz with a bandwidth of 0.2 Hz" (one band per centre).
TABLE_6_1_PREFILTERS = {
    "CSAS LPF 0.2 Hz": ("lowpass", 2, (0.2,), None),
    "CSAS LPF 0.3 Hz": ("lowpass", 2, (0.3,), None),
    "CSAS BSF 0.25 & 0.34 Hz": ("bandstop", 2, (0.25, 0.34), 0.2),
}


#: Filter-2's first band as the thesis prints it twice (Hz): Table 4.3's header says 0.01-0.15, the text before it
#: ("ii) 0.05-0.15 Hz and 0.25-0.4 Hz") 0.05-0.15; :data:`TABLE_4_3_FILTERS` takes the text's.
FILTER_2_BANDS = {"table": (0.01, 0.15), "text": (0.05, 0.15)}

#: Ch. 4.6-4.7 (Table 4.3), 2-DOF, Ts = 0.1 s: the doublet's shaping filters, as (kind, order, bands Hz).
#: Elliptic band-stops of order 2 (Filter-2's first band read as 0.05-0.15 Hz; the table prints 0.01-0.15)
#: and a Butterworth low-pass of order 3 at 0.05 Hz.
TABLE_4_3_FILTERS = {
    "Filter-1": ("elliptic bandstop", 2, ((0.25, 0.4),)),
    "Filter-2": ("elliptic bandstop", 2, ((0.05, 0.15), (0.25, 0.4))),
    "Filter-3": ("elliptic bandstop", 2, ((0.05, 0.15),)),
    "LPF 0.05 Hz": ("lowpass", 3, ((0.05,),)),
}

#: Ch. 7.3.2 (on the rig): the extra CSAS prefilters, as (kind, order, frequencies Hz, bandwidth Hz):
#: a Butterworth order 2 low-pass at 0.1 Hz, and a Butterworth order 2 band-stop centred on 0.34 Hz,
#: 0.2 Hz wide (the ch. 6 band-stop had a second band at 0.25 Hz).
CHAPTER_7_PREFILTERS = {
    "CSAS LPF 0.1 Hz": ("lowpass", 2, (0.1,), None),
    "CSAS BSF 0.34 Hz": ("bandstop", 2, (0.34,), 0.2),
}

#: Ch. 7.3 and 7.4: what the rig did with each weight R (Q = I), in the thesis's words.
CHAPTER_7_OUTCOMES = {
    75.0: "SAS: significant overshoot, erratic settling, saturates; CSAS LPF 0.1/0.2 Hz good and smooth",
    1.0: "SAS: unstable on the rig (estimator too slow), not run further",
    100.0: "SAS: better than R = 75, slight saturation; CSAS LPF 0.1/0.2 Hz good and smooth",
    125.0: "SAS: best, hardly any overshoot, control near the limit and jerky; CSAS LPF 0.1/0.2 Hz good",
}

#: Ch. 7.3.2: what the rig did with each CSAS prefilter (R = 75, 100, 125).
CHAPTER_7_PREFILTER_OUTCOMES = {
    "CSAS LPF 0.1 Hz": "good tracking, slow rise, minimal control",
    "CSAS LPF 0.2 Hz": "best: rise, settling, overshoot and control all satisfactory",
    "CSAS LPF 0.3 Hz": "faster rise but overshoot and longer settling: excites flexible modes",
    "CSAS BSF 0.34 Hz": "poor: high overshoot, long settling, high control",
}

#: Ch. 7.4: a push on the beam at about 18-20 s (s), rejected by the R = 75, 100 and 125 controllers.
PUSH_TIME_RANGE = (18.0, 20.0)
PUSH_WEIGHTS_R = (75.0, 100.0, 125.0)

#: Derived from eq. (3.11) (not printed): its oscillatory mode (Hz, damping ratio) and DC gain (rad/V).
EQ_3_11_MODE = (0.342, 0.041)
EQ_3_11_DC_GAIN = 1.51

#: The rig's pitch RMS at hover with constant inputs (rad): "a minor oscillatory tendency even in steady state"
#: (ch. 7.3.1; the flat steady state before the push of figs. 7.17-7.19). The thesis prints no figure: this range is
#: this project's reading of its steady-state records, the level the twin's ambient excitation is calibrated to.
HOVER_PITCH_RMS = (0.003, 0.006)
