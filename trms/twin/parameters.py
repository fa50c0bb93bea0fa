"""The twin's named physical parameters: read, changed on a spec copy, written back into the MJCF.

Each :class:`Parameter` is one physical quantity with a unit, physical bounds and one
place in the MJCF. Calibration fits them; robustness studies spread them. Values are
changed on a *copy* of an ``MjSpec`` (the caller's spec is never modified) and written
back into the MJCF text by editing attributes in place, so the file's comments (the
sources of every value) survive.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from trms.errors import InputError, ModelFileError, check_in_range
from trms.files import atomic_write
from trms.twin.model import fixed_tendon_coefficients, rebuild_fixed_tendon

__all__ = [
    "Parameter",
    "PARAMETERS",
    "ROLES",
    "SOURCES",
    "published_parameters",
    "read_parameters",
    "with_parameters",
    "write_parameters",
    "model_key",
]


#: What a parameter is: the quantity its name says, or a knob that carries what the model has no element for.
ROLES = ("physical", "lumped")
#: Where a published value comes from: the MJCF's source legend (its header comment cites each in full).
SOURCES: dict[str, str] = {
    "F": "Feedback's TRMS manual parameter table",
    "S": "Feedback's simplified nonlinear model",
    "R": "Rotondo, Nejjari and Puig 2013",
    "T": "Tastemirov et al. 2017",
    "A": "an assumption of this model",
}


@dataclass(frozen=True)
class Parameter:
    """One physical parameter of the twin.

    Attributes
    ----------
    name : str
    unit : str
    bounds : tuple of float
        Physically plausible range.
    description : str
    kind : str
        MJCF element kind: ``geom``, ``joint``, ``tendon``, ``actuator``, ``numeric`` or
        ``joint_class`` (every joint of a default class).
    element : str
        Element (or default class) name.
    attribute : str
        MJCF attribute (``coef:JOINT`` for a fixed tendon's coefficient on a joint; ``axis:lean`` for the tangent
        ``x / z`` of a joint axis leaning in its body's x-z plane, written as ``axis="t 0 1"``: MuJoCo normalises
        an axis, so its x component alone is not the lean).
    index : int
        Position inside a vector attribute.
    published : float
        The uncalibrated physical value (the published parameter sets, or the stated
        assumption, cited in the MJCF), where calibration starts from.
    source : str
        Where ``published`` comes from, as the MJCF's source legend cites it: ``F`` (Feedback's manual table),
        ``S`` (Feedback's simplified model), ``R``, ``T`` (the published identifications) or ``A`` (an
        assumption of this model).
    role : {"physical", "lumped"}
        ``physical``: the quantity its name says, to be read against ``published`` (the departure shows how far
        the calibration moved it). ``lumped``: a knob that carries effects the model has no element for;
        ``stands_for`` says which.
    stands_for : str
        What a lumped parameter stands for (empty for a physical one).

    Examples
    --------
    >>> gain = PARAMETERS["main_motor_gain"]
    >>> gain.role, gain.source, round(gain.departure(2.2), 2)
    ('lumped', 'S', 1.0)
    >>> PARAMETERS["counterweight_mass"].role
    'physical'
    """

    name: str
    unit: str
    bounds: tuple[float, float]
    description: str
    kind: str
    element: str
    attribute: str
    index: int = 0
    published: float = float("nan")
    source: str = "A"
    role: str = "physical"
    stands_for: str = ""

    def __post_init__(self) -> None:
        if self.role not in ROLES:
            raise ValueError(f"parameter {self.name!r}: role {self.role!r} must be one of {ROLES}")
        if (self.role == "lumped") != bool(self.stands_for):
            raise ValueError(f"parameter {self.name!r}: a lumped parameter says what it stands for, a physical one not")
        if self.source not in SOURCES:
            raise ValueError(f"parameter {self.name!r}: source {self.source!r} must be one of {tuple(SOURCES)}")

    def departure(self, value: float) -> float:
        """``value``'s relative departure from the published value, ``value / published - 1`` (NaN when the
        published value is 0: no relative departure from nothing)."""
        return float(value) / self.published - 1.0 if self.published else float("nan")

    # ------------------------------------------------------------- spec side
    def _targets(self, spec: mujoco.MjSpec) -> list:
        try:
            if self.kind == "joint_class":
                found = [j for j in spec.joints if j.classname.name == self.element]
            else:
                getter = {
                    "geom": spec.geom,
                    "joint": spec.joint,
                    "tendon": spec.tendon,
                    "actuator": spec.actuator,
                    "numeric": spec.numeric,
                }[self.kind]
                found = [getter(self.element)]
        except (KeyError, ValueError):
            found = []
        if not found or any(f is None for f in found):
            raise ModelFileError(f"model lacks {self.kind} {self.element!r} needed by parameter {self.name!r}")
        return found

    def get(self, spec: mujoco.MjSpec) -> float:
        """The parameter's value in ``spec``."""
        target = self._targets(spec)[0]
        if self.attribute.startswith("coef:"):
            return fixed_tendon_coefficients(target).get(self.attribute.split(":", 1)[1], 0.0)
        if self.attribute == "axis:lean":
            axis = np.asarray(target.axis, float)
            return float(axis[0] / axis[2])
        value = getattr(target, self.attribute)
        return float(np.atleast_1d(np.asarray(value, float))[self.index])

    def set(self, spec: mujoco.MjSpec, value: float) -> None:
        """Set the value in ``spec`` (in place; use :func:`with_parameters` for a copy)."""
        v = self.check(value)
        for target in self._targets(spec):
            if self.attribute.startswith("coef:"):
                joint = self.attribute.split(":", 1)[1]
                coefs = fixed_tendon_coefficients(target)
                if joint not in coefs:
                    raise ModelFileError(f"tendon {self.element!r} has no joint {joint!r} for parameter {self.name!r}")
                rebuild_fixed_tendon(spec, target, {**coefs, joint: v})
                continue
            if self.attribute == "axis:lean":
                target.axis = np.array([v, 0.0, 1.0])
                continue
            current = getattr(target, self.attribute)
            if np.ndim(current) == 0:
                setattr(target, self.attribute, v)
            else:
                arr = np.array(current, float)
                arr[self.index] = v
                setattr(target, self.attribute, arr)

    def check(self, value: float) -> float:
        """Return ``float(value)`` if it lies within the bounds, else raise :class:`InputError`."""
        return check_in_range(
            self.name, value, self.bounds[0], self.bounds[1], unit=f" {self.unit}" if self.unit else ""
        )

    # -------------------------------------------------------------- XML side
    def write_xml(self, text: str, value: float) -> str:
        """Return MJCF ``text`` with this parameter's attribute set to ``value`` (comments untouched)."""
        v = self.check(value)
        tag = {"geom": "geom", "joint": "joint", "tendon": "fixed", "actuator": "general", "numeric": "numeric"}
        if self.kind == "joint_class":
            block = re.search(rf'<default class="{re.escape(self.element)}">\s*<joint\b[^>]*>', text)
            if block is None:
                raise ModelFileError(f"MJCF has no default class {self.element!r} with a joint")
            start, end = block.span()
            element = text[start:end]
            element = element[element.index("<joint") :]
            offset = start + block.group(0).index("<joint")
        elif self.attribute.startswith("coef:"):
            joint = self.attribute.split(":", 1)[1]
            tendon = re.search(rf'<fixed name="{re.escape(self.element)}"[^>]*>(.*?)</fixed>', text, re.S)
            if tendon is None:
                raise ModelFileError(f"MJCF has no fixed tendon {self.element!r}")
            inner = re.search(rf'<joint joint="{re.escape(joint)}"[^>]*/>', tendon.group(1))
            if inner is None:
                raise ModelFileError(f"tendon {self.element!r} has no joint {joint!r}")
            offset = tendon.start(1) + inner.start()
            element = inner.group(0)
        else:
            found = re.search(rf'<{tag[self.kind]} name="{re.escape(self.element)}"[^>]*>', text)
            if found is None:
                raise ModelFileError(f"MJCF has no {tag[self.kind]} named {self.element!r}")
            offset, element = found.start(), found.group(0)
        attr = "coef" if self.attribute.startswith("coef:") else self.attribute.split(":", 1)[0]
        match = re.search(rf'\b{attr}="([^"]*)"', element)
        if match is None:
            raise ModelFileError(f"MJCF element for {self.name!r} has no attribute {attr!r} to write")
        values = match.group(1).split()
        if self.attribute == "axis:lean":
            values = [f"{v:.6g}", "0", "1"]
        else:
            values[self.index] = f"{v:.6g}"
        new_element = element[: match.start(1)] + " ".join(values) + element[match.end(1) :]
        return text[:offset] + new_element + text[offset + len(element) :]


#: The parameters calibration may fit and robustness studies spread.
PARAMETERS: dict[str, Parameter] = {
    p.name: p
    for p in (
        Parameter(
            "counterweight_mass",
            "kg",
            (0.02, 0.30),
            "counterweight at the end of its 0.26 m arm: the pitch pendulum",
            "geom",
            "counterweight",
            "mass",
            published=0.068,
            source="F",
        ),
        Parameter(
            "pitch_damping",
            "N m s/rad",
            (1e-4, 0.05),
            "viscous friction of the pitch axis",
            "joint",
            "pitch",
            "damping",
            published=0.006,
            source="S",
        ),
        Parameter(
            "yaw_damping",
            "N m s/rad",
            (1e-4, 0.05),
            "viscous friction of the yaw axis",
            "joint",
            "yaw",
            "damping",
            published=0.003,
            source="A",
        ),
        Parameter(
            "cable_stiffness",
            "N m/rad",
            (0.002, 0.2),
            "yaw return spring of the cable",
            "tendon",
            "yaw_cable",
            "stiffness",
            published=0.0215,
            source="A",
        ),
        Parameter(
            "main_shield_mass",
            "kg",
            (0.15, 0.35),
            "main rotor shield: with the counterweight, the beam's rest pose and pitch pendulum",
            "geom",
            "main_shield",
            "mass",
            published=0.225,
            source="F",
        ),
        Parameter(
            "main_rotor_tilt",
            "",
            (-0.5, 0.5),
            "tangent of the main rotor spin axis's lean towards the beam: how much "
            "of the rotor's angular momentum yaw rate turns into pitch torque",
            "joint",
            "main_spin",
            "axis:lean",
            0,
            published=0.0,
            source="A",
            role="lumped",
            stands_for=(
                "Feedback's empirical gyroscopic coupling (Kgy: yaw rate into pitch torque): a rotor axis "
                "normal to the flat beam gives the rig none, so the lean carries it"
            ),
        ),
        Parameter(
            "main_rotor_inertia_radius",
            "m",
            (0.08, 0.25),
            "radius of the 0.01 kg sphere that carries the main rotor's "
            "spin inertia (J = 0.004 r^2 kg m2: 2.6e-5 to 2.5e-4, a propeller and motor armature)",
            "geom",
            "main_rotor_inertia",
            "size",
            0,
            published=0.12,
            source="A",
            role="lumped",
            stands_for=(
                "the main rotor's angular momentum that, with the lean, carries Feedback's Kgy: the "
                "propeller's and the motor armature's spin inertia is not published"
            ),
        ),
        Parameter(
            "main_turbulence",
            "N",
            (0.0, 0.2),
            "stationary standard deviation of the main rotor's thrust turbulence (rotor wash): the rig's "
            "ambient excitation of pitch",
            "numeric",
            "rotor_turbulence",
            "data",
            0,
            published=0.0,
            source="A",
            role="lumped",
            stands_for=(
                "whatever moves the rig's pitch at rest (air currents, rotor wash, vibration) as one thrust "
                "fluctuation of the main rotor, sized to the rig's hover pitch RMS and Table 5.1's residual "
                "variance"
            ),
        ),
        Parameter(
            "tail_turbulence",
            "N",
            (0.0, 0.2),
            "stationary standard deviation of the tail rotor's thrust turbulence: the rig's ambient excitation of yaw",
            "numeric",
            "rotor_turbulence",
            "data",
            1,
            published=0.0,
            source="A",
            role="lumped",
            stands_for=("whatever moves the rig's yaw at rest as one thrust fluctuation of the tail rotor"),
        ),
        Parameter(
            "turbulence_time",
            "s",
            (0.05, 10.0),
            "correlation time of the rotors' thrust turbulence",
            "numeric",
            "rotor_turbulence",
            "data",
            2,
            published=1.0,
            source="A",
            role="lumped",
            stands_for=("the bandwidth of the rig's ambient excitation, which the thesis does not measure"),
        ),
        Parameter(
            "pitch_encoder_noise",
            "rad",
            (0.0, 0.01),
            "standard deviation of the electronics noise on the pitch measurement (before quantisation)",
            "numeric",
            "encoder_noise",
            "data",
            0,
            published=0.0,
            source="A",
            role="lumped",
            stands_for=(
                "the pitch measurement's noise beyond the encoder's quantisation (electronics, the I/O card), "
                "sized with the turbulence to Table 5.1's residual variance"
            ),
        ),
        Parameter(
            "yaw_encoder_noise",
            "rad",
            (0.0, 0.01),
            "standard deviation of the electronics noise on the yaw measurement (before quantisation)",
            "numeric",
            "encoder_noise",
            "data",
            1,
            published=0.0,
            source="A",
            role="lumped",
            stands_for=("the yaw measurement's noise beyond the encoder's quantisation"),
        ),
        Parameter(
            "input_delay",
            "s",
            (0.0, 1.5),
            "transport delay of both rotors' commands (native actuator delay)",
            "numeric",
            "input_delay",
            "data",
            0,
            published=0.0,
            source="A",
            role="lumped",
            stands_for=(
                "the dead time of the rig's step (thesis fig. 3.3): the I/O chain and the motor and rotor "
                "dynamics beyond Feedback's first-order lag, which has none"
            ),
        ),
        Parameter(
            "beam_stiffness",
            "N m/rad",
            (5.0, 5000.0),
            "stiffness of each elastic hinge of the beam",
            "joint_class",
            "flex",
            "stiffness",
            published=460.0,
            source="A",
        ),
        Parameter(
            "beam_damping",
            "N m s/rad",
            (1e-3, 5.0),
            "damping of each elastic hinge of the beam",
            "joint_class",
            "flex",
            "damping",
            published=0.14,
            source="A",
        ),
        Parameter(
            "main_motor_gain",
            "1/V",
            (0.3, 5.0),
            "main rotor state per volt (k1/T10): scales the thrust curve's input",
            "numeric",
            "main_thrust_curve",
            "data",
            0,
            published=1.1,
            source="S",
            role="lumped",
            stands_for=(
                "Feedback's k1/T10 times the gain between the logged volts and the motor (the amplifier): the "
                "thesis's DC gain in rad per logged volt, with the published thrust curve's coefficients kept"
            ),
        ),
        Parameter(
            "main_motor_lag",
            "s",
            (0.2, 3.0),
            "main DC motor and rotor time constant",
            "actuator",
            "main_rotor",
            "dynprm",
            0,
            published=1.1,
            source="S",
        ),
        Parameter(
            "main_reaction",
            "m",
            (0.0, 0.3),
            "main rotor reaction torque per newton of thrust",
            "actuator",
            "main_rotor",
            "gear",
            5,
            published=0.03,
            source="A",
            role="lumped",
            stands_for=(
                "the yaw torque per newton of main thrust: the propeller's drag torque together with "
                "Feedback's lead-lag reaction term (kc), fitted to the 2-DOF u1 -> yaw spectra"
            ),
        ),
        Parameter(
            "tail_motor_gain",
            "1/V",
            (0.3, 5.0),
            "tail rotor state per volt (k2/T20)",
            "numeric",
            "tail_thrust_curve",
            "data",
            0,
            published=0.8,
            source="S",
        ),
        Parameter(
            "tail_motor_lag",
            "s",
            (0.2, 3.0),
            "tail DC motor and rotor time constant",
            "actuator",
            "tail_rotor",
            "dynprm",
            0,
            published=1.0,
            source="S",
        ),
        Parameter(
            "tail_reaction",
            "m",
            (0.0, 0.1),
            "tail rotor reaction torque per newton of thrust (acts on pitch)",
            "actuator",
            "tail_rotor",
            "gear",
            5,
            published=0.005,
            source="A",
            role="lumped",
            stands_for=(
                "the pitch torque per newton of tail thrust that the rig's weak u2 -> pitch coupling allows: "
                "the tail propeller's drag torque and any offset of its thrust line"
            ),
        ),
    )
}


def _lookup(names: Iterable[str]) -> list[Parameter]:
    out = []
    for n in names:
        if n not in PARAMETERS:
            raise InputError(f"unknown parameter {n!r}; known: {', '.join(PARAMETERS)}")
        out.append(PARAMETERS[n])
    return out


def published_parameters() -> dict[str, float]:
    """The uncalibrated physical value of every parameter (where calibration starts)."""
    return {p.name: p.published for p in PARAMETERS.values()}


def read_parameters(spec: mujoco.MjSpec, names: Iterable[str] | None = None) -> dict[str, float]:
    """Current values of ``names`` (default: all parameters) in ``spec``."""
    return {p.name: p.get(spec) for p in _lookup(names if names is not None else PARAMETERS)}


def model_key(spec: mujoco.MjSpec) -> str:
    """A key of what a model is: its MJCF text and every parameter's exact value.

    ``MjSpec.to_xml`` writes numbers with 6 significant digits, so two models apart only in a later digit (a fit's
    last steps) have the same text; the parameters' exact values tell them apart.

    Examples
    --------
    >>> from trms.twin import load_spec
    >>> lag = read_parameters(load_spec(), ["main_motor_lag"])["main_motor_lag"]  # the shipped value
    >>> a = with_parameters(load_spec(), {"main_motor_lag": lag})
    >>> b = with_parameters(load_spec(), {"main_motor_lag": lag + 1e-8})
    >>> a.to_xml() == b.to_xml(), model_key(a) == model_key(b), model_key(a) == model_key(load_spec())
    (True, False, True)
    """
    return spec.to_xml() + repr(sorted(read_parameters(spec).items()))


def with_parameters(spec: mujoco.MjSpec, values: Mapping[str, float]) -> mujoco.MjSpec:
    """A copy of ``spec`` with ``values`` set; every value is checked before anything changes."""
    params = _lookup(values)
    checked = [p.check(values[p.name]) for p in params]
    out = spec.copy()
    for p, v in zip(params, checked):
        p.set(out, v)
    return out


def write_parameters(path: str | os.PathLike[str], values: Mapping[str, float]) -> Path:
    """Write ``values`` into the MJCF file at ``path``, in place and atomically, keeping its comments.

    The result is parsed by MuJoCo before it replaces the file. Only the parameters are written: the values derived
    from them (control ranges, the hover keyframe) are refreshed by :func:`trms.twin.model_files.write_derived`, and
    :func:`trms.twin.model_files.write_model` does both.
    """
    path = Path(path)
    text = path.read_text()
    for p in _lookup(values):
        text = p.write_xml(text, values[p.name])
    spec = mujoco.MjSpec.from_string(text)
    for p in _lookup(values):
        if not np.isclose(p.get(spec), float(f"{p.check(values[p.name]):.6g}"), rtol=1e-9, atol=0):
            raise ModelFileError(f"writing {p.name} into {str(path)!r} did not take effect")
    mode = path.stat().st_mode & 0o777
    atomic_write(path, lambda fh: fh.write(text), binary=False)
    os.chmod(path, mode)
    return path
