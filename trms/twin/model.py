"""Loading the MJCF, the rig's configurations, and locking axes exactly.

A configuration names which axes are free, which voltages the plant takes and which
angles it measures. Locking deletes the joint (and every sensor that names it) from a
copy of the MjSpec, so the locked axis is exactly fixed -- no soft constraint.
"""

from __future__ import annotations

import os
import warnings
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from trms.errors import InputError, ModelFileError, check_choice
from trms.twin.disturbances import Turbulence
from trms.twin.mjcf_text import refuse_declarations_and_outside_includes, refuse_non_finite_numbers
from trms.twin.rotors import ThrustCurve

__all__ = [
    "DEFAULT_MODEL_PATH",
    "SCENE_PATH",
    "Configuration",
    "CONFIGURATIONS",
    "ROTORS",
    "load_spec",
    "build_model",
    "configure_spec",
    "thrust_curves",
    "input_delay",
    "MAX_INPUT_DELAY",
    "turbulence",
    "encoder_noise",
    "spin_dofs",
    "spinning",
    "check_actuators",
    "check_structure",
    "add_scene",
]

#: The shipped model (calibrated): the rig alone.
DEFAULT_MODEL_PATH = Path(__file__).resolve().parents[1] / "models" / "trms.xml"
#: The world around it (floor, light, cameras, skybox), which includes the rig: MuJoCo Menagerie's layout.
SCENE_PATH = DEFAULT_MODEL_PATH.with_name("scene.xml")

#: Actuator names of the two rotors, in input order (u1 main, u2 tail).
ROTORS = ("main_rotor", "tail_rotor")
#: Their spin motors and spin joints (optional in a user's MJCF: without them the rotors do not spin).
SPINS = ("main_spin", "tail_spin")
#: Their turbulence actuators (optional in a user's MJCF: without them the rig has no rotor-wash turbulence).
#: They come after the rotors and the spin motors in the actuator order.
WASHES = ("main_wash", "tail_wash")
_REQUIRED = {
    "joint": ("pitch", "yaw"),
    "actuator": ROTORS,
    "numeric": ("main_thrust_curve", "tail_thrust_curve"),
}


@dataclass(frozen=True)
class Configuration:
    """One way the rig is set up.

    Attributes
    ----------
    name : str
    locked : tuple of str
        Joints removed from the model (their axes are fixed at 0 rad).
    inputs : tuple of str
        Plant inputs, a subset of ``("u1", "u2")``; an absent rotor is held at 0 V.
    outputs : tuple of str
        Measured angles (joint names).
    trim_inputs : tuple of str
        Inputs whose hover voltage the trim solves for; the other inputs trim at 0 V.
    description : str
    """

    name: str
    locked: tuple[str, ...]
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    trim_inputs: tuple[str, ...]
    description: str


#: The rig's configurations (thesis ch. 2: either axis can be locked by its screw).
CONFIGURATIONS: dict[str, Configuration] = {
    "1dof": Configuration("1dof", ("yaw",), ("u1",), ("pitch",), ("u1",), "yaw locked: SISO main rotor u1 -> pitch"),
    "2dof": Configuration(
        "2dof", (), ("u1", "u2"), ("pitch", "yaw"), ("u1", "u2"), "both axes free: u1, u2 -> pitch, yaw"
    ),
    "yaw": Configuration(
        "yaw", ("pitch",), ("u1", "u2"), ("yaw",), ("u2",), "pitch locked flat: u1, u2 -> yaw (u1 trims at 0 V)"
    ),
}


def get_configuration(name: str) -> Configuration:
    """Look up a configuration by name, refusing unknown names with the list of allowed ones."""
    check_choice("configuration", name, tuple(CONFIGURATIONS))
    return CONFIGURATIONS[name]


def load_spec(path: str | os.PathLike[str] | None = None, allow_outside_includes: bool = False) -> mujoco.MjSpec:
    """Parse an MJCF into an MjSpec and check it has what the twin needs.

    Parameters
    ----------
    path : path-like, optional
        MJCF file; the shipped ``trms/models/trms.xml`` by default.
    allow_outside_includes : bool
        Accept ``<include>`` files outside the model's folder (refused by default: a model file should not
        read whatever path it names).

    Raises
    ------
    ModelFileError
        If the file is missing, is not valid MJCF, declares a DTD or entities, includes a file outside its
        folder (unless allowed), lacks a required joint, actuator or thrust-curve numeric, or has a structure
        the twin cannot drive (:func:`check_structure`).

    Examples
    --------
    >>> spec = load_spec()
    >>> [a.name for a in spec.actuators][:2]
    ['main_rotor', 'tail_rotor']
    """
    if path is not None and not isinstance(path, (str, os.PathLike)):
        raise InputError(f"model_path = {path!r} must be a path to an MJCF file (str or os.PathLike) or None")
    path = Path(path) if path is not None else DEFAULT_MODEL_PATH
    if not path.is_file():
        raise ModelFileError(f"model file {str(path)!r} does not exist")
    refuse_declarations_and_outside_includes(path, path.resolve().parent, allow_outside_includes, set())
    refuse_non_finite_numbers(path)
    try:
        spec = mujoco.MjSpec.from_file(str(path))
    except Exception as exc:  # mujoco raises ValueError with the parser's message
        raise ModelFileError(f"model file {str(path)!r} is not valid MJCF: {exc}") from exc
    have = {
        "joint": {j.name for j in spec.joints},
        "actuator": {a.name for a in spec.actuators},
        "numeric": {n.name for n in spec.numerics},
    }
    for kind, names in _REQUIRED.items():
        missing = [n for n in names if n not in have[kind]]
        if missing:
            raise ModelFileError(f"model file {str(path)!r} lacks required {kind}(s) {missing}")
    check_spec(spec, f"model file {str(path)!r}")
    _check_delays(spec, f"model file {str(path)!r}")
    return spec


def _check_delays(spec: mujoco.MjSpec, where: str) -> None:
    """Refuse an actuator ``delay`` outside the numeric's range, and say when one differs from the numeric.

    The ``input_delay`` numeric sets every motor-driven actuator's delay when the twin is built: a value written on
    an actuator is not used. One outside ``[0, 5]`` s is an error; another value than the numeric's (a file whose
    numeric was edited, its derived attributes not yet rewritten) is said once, in a warning.
    """
    lag = input_delay(spec)
    for act in spec.actuators:
        if act.name in WASHES:  # the air acts at once
            continue
        value = float(act.delay)
        if not (np.isfinite(value) and 0.0 <= value <= MAX_INPUT_DELAY):
            raise ModelFileError(
                f"{where}: actuator {act.name!r} delay = {value:g} s; allowed: 0 to {MAX_INPUT_DELAY:g} s (the "
                f"input_delay numeric, {lag:g} s, sets every rotor's transport delay: edit it to change the delay)"
            )
        if value != 0 and abs(value - lag) > 1e-6 * max(lag, 1e-3):
            warnings.warn(
                f"{where}: actuator {act.name!r} delay = {value:g} s differs from the input_delay numeric ({lag:g} s), "
                "which sets every rotor's transport delay: the numeric's is used",
                stacklevel=3,
            )


def check_actuators(spec: mujoco.MjSpec, where: str = "model") -> None:
    """Refuse an actuator list the twin cannot drive: it must be, in order, the rotors' thrust actuators
    (``main_rotor``, ``tail_rotor``), optionally their spin motors (``main_spin``, ``tail_spin``), then
    optionally their turbulence actuators (``main_wash``, ``tail_wash``), and nothing else.

    Raises
    ------
    ModelFileError
    """
    names = tuple(a.name for a in spec.actuators)
    allowed = [ROTORS + extra + wash for extra in ((), SPINS) for wash in ((), WASHES)]
    if names not in allowed:
        raise ModelFileError(
            f"{where}: actuators {list(names)}; allowed, in this order: {list(ROTORS)}, optionally "
            f"{list(SPINS)}, then optionally {list(WASHES)}"
        )


#: Where each actuator acts: a rotor's thrust and its turbulence on the rotor's hub site, a spin motor on the
#: joint of its own name.
_TRANSMISSION = {
    "main_rotor": (mujoco.mjtTrn.mjTRN_SITE, "main_hub"),
    "tail_rotor": (mujoco.mjtTrn.mjTRN_SITE, "tail_hub"),
    "main_wash": (mujoco.mjtTrn.mjTRN_SITE, "main_hub"),
    "tail_wash": (mujoco.mjtTrn.mjTRN_SITE, "tail_hub"),
    "main_spin": (mujoco.mjtTrn.mjTRN_JOINT, "main_spin"),
    "tail_spin": (mujoco.mjtTrn.mjTRN_JOINT, "tail_spin"),
}
#: The axis each rotor's thrust must mainly turn (the main rotor lifts the beam, the tail rotor turns it).
_DRIVES = {"main_rotor": "pitch", "tail_rotor": "yaw"}


def check_structure(spec: mujoco.MjSpec, where: str = "model") -> None:
    """Refuse a model whose structure the twin would drive wrongly: the pitch and yaw joints (and each spinning
    rotor's joint) must be hinges, each actuator must act where its name says (:data:`_TRANSMISSION`), and each
    rotor's thrust must mainly turn its own axis (the main rotor pitch, the tail rotor yaw, at the model's
    reference pose): a model with its rotors' names or hubs swapped is refused, not flown. The pitch and yaw
    joints must have end stops around 0 rad (a range ``LO < 0 < HI``), as the rig has.

    Raises
    ------
    ModelFileError

    Examples
    --------
    >>> spec = load_spec()
    >>> spec.joint("pitch").type = mujoco.mjtJoint.mjJNT_SLIDE
    >>> try:
    ...     check_structure(spec)
    ... except ModelFileError as e:
    ...     print(e)
    model: joint 'pitch' is a slide joint; allowed: a hinge
    """
    names = {a.name for a in spec.actuators}
    joints = {j.name: j for j in spec.joints}
    hinges = ["pitch", "yaw"] + [n for n in SPINS if n in names]
    for name in hinges:
        joint = joints.get(name)
        if joint is None:
            raise ModelFileError(f"{where}: no joint {name!r}; the actuator or axis of that name needs one (a hinge)")
        if joint.type != mujoco.mjtJoint.mjJNT_HINGE:
            kind = str(joint.type).rsplit("_", 1)[-1].lower()
            raise ModelFileError(f"{where}: joint {name!r} is a {kind} joint; allowed: a hinge")
    for act in spec.actuators:
        trn, target = _TRANSMISSION[act.name]
        if act.trntype != trn or act.target != target:
            kind = "site" if trn == mujoco.mjtTrn.mjTRN_SITE else "joint"
            raise ModelFileError(
                f"{where}: actuator {act.name!r} acts on {act.target!r}; allowed: the {kind} {target!r}"
            )
    try:
        model = spec.copy().compile()
    except Exception as exc:
        raise ModelFileError(f"{where}: does not compile: {exc}") from exc
    # The rig's beam hits end stops on both axes, and the twin's end-stop channel, the tasks' angle bounds and the
    # rig-data checks all read them from the joints' ranges: a free axis without limits (MuJoCo reads range="0 0"
    # as none) would swing through stops the rig has, so it is refused rather than flown.
    for axis in ("pitch", "yaw"):
        j = model.joint(axis).id
        lo, hi = (float(v) for v in model.jnt_range[j])
        if not (model.jnt_limited[j] and lo < 0.0 < hi):
            raise ModelFileError(
                f'{where}: joint {axis!r} has no end stops (range="{lo:g} {hi:g}" rad, limited: '
                f"{bool(model.jnt_limited[j])}); allowed: a range LO < 0 < HI rad, the rig's end stops "
                '(range="0 0" means no limits)'
            )
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    dof = {a: int(model.jnt_dofadr[model.joint(a).id]) for a in ("pitch", "yaw")}
    jac = np.zeros((3, model.nv))
    for rotor, axis in _DRIVES.items():
        act = model.actuator(rotor)
        site = int(act.trnid[0])
        mujoco.mj_jacSite(model, data, jac, None, site)
        force = data.site_xmat[site].reshape(3, 3) @ np.asarray(act.gear[:3], float)  # thrust direction, world
        moment = {a: abs(float(jac[:, i] @ force)) for a, i in dof.items()}
        other = "yaw" if axis == "pitch" else "pitch"
        if not moment[axis] > moment[other]:
            raise ModelFileError(
                f"{where}: actuator {rotor!r} turns {other} ({moment[other]:.3g} N m per N) more than {axis} "
                f"({moment[axis]:.3g} N m per N); allowed: the main rotor mainly pitches the beam, the tail rotor "
                "mainly yaws it (are the rotors' names or hubs swapped?)"
            )


def spinning(model: mujoco.MjModel) -> bool:
    """Whether ``model`` has the rotors' spin motors (its rotor bodies spin)."""
    names = {model.actuator(i).name for i in range(model.nu)}
    return all(n in names for n in SPINS)


def check_spec(spec: mujoco.MjSpec, where: str = "model") -> None:
    """Refuse physically meaningless values MuJoCo compiles silently: non-finite or negative joint
    damping, stiffness or armature, a motor lag (the rotors' filter time constant ``dynprm[0]``) <= 0,
    and gravity that does not point down (the counterweight and the thrust balance against it at hover).

    Raises
    ------
    ModelFileError
    """
    gravity = np.asarray(spec.option.gravity, float)
    if not (np.all(np.isfinite(gravity)) and gravity[2] < 0):
        raise ModelFileError(
            f"{where}: gravity = {gravity.tolist()} m/s^2; allowed: finite and pointing down (a negative z "
            "component, e.g. [0, 0, -9.81]): the rig hovers against it"
        )
    for joint in spec.joints:
        for attr in ("damping", "stiffness", "armature"):
            vals = np.atleast_1d(np.asarray(getattr(joint, attr), float))
            if not np.all(np.isfinite(vals)) or np.any(vals < 0):
                raise ModelFileError(f"{where}: joint {joint.name!r} {attr} = {vals.tolist()}; allowed: finite, >= 0")
    check_actuators(spec, where)
    check_structure(spec, where)
    for name in ROTORS:
        act = spec.actuator(name)
        if act is None:
            continue
        lag = float(np.asarray(act.dynprm, float)[0])
        if act.dyntype in (mujoco.mjtDyn.mjDYN_FILTER, mujoco.mjtDyn.mjDYN_FILTEREXACT) and not (
            np.isfinite(lag) and lag > 0
        ):
            raise ModelFileError(f"{where}: actuator {name!r} motor lag dynprm[0] = {lag!r} s; allowed: finite, > 0 s")


def thrust_curves(spec: mujoco.MjSpec) -> tuple[ThrustCurve, ThrustCurve]:
    """The main and tail thrust curves stored in the spec's custom numerics."""
    main, tail = (ThrustCurve.from_array(spec.numeric(f"{r.split('_')[0]}_thrust_curve").data) for r in ROTORS)
    return main, tail


def fixed_tendon_coefficients(tendon: mujoco.MjsTendon) -> dict[str, float]:
    """Joint name -> coefficient of a fixed tendon."""
    return {w.target.name: float(w.coef) for w in tendon.path}


def rebuild_fixed_tendon(spec: mujoco.MjSpec, tendon: mujoco.MjsTendon, coefficients: dict[str, float]) -> None:
    """Replace a fixed tendon by one with the same name and spring but new joint coefficients.

    MuJoCo's spec does not allow editing a wrap's coefficient, so the tendon is rebuilt;
    with no coefficient left, it is removed.
    """
    props = {k: np.array(getattr(tendon, k)) for k in ("stiffness", "damping", "springlength")}
    name = tendon.name
    spec.delete(tendon)
    if coefficients:
        new = spec.add_tendon(name=name)
        for key, value in props.items():
            setattr(new, key, value)
        for joint, coef in coefficients.items():
            new.wrap_joint(joint, coef)


def _drop_joint_from_tendon(spec: mujoco.MjSpec, tendon: mujoco.MjsTendon, joint_name: str) -> None:
    """Rebuild a fixed tendon without ``joint_name`` (the spring keeps acting on the other joints)."""
    coefs = fixed_tendon_coefficients(tendon)
    if joint_name in coefs:
        rebuild_fixed_tendon(spec, tendon, {j: c for j, c in coefs.items() if j != joint_name})


#: Longest transport delay (s) a model may hold (its ``input_delay`` numeric, or an actuator's ``delay``).
MAX_INPUT_DELAY = 5.0


def input_delay(spec: mujoco.MjSpec) -> float:
    """The rotors' transport delay (s): the custom numeric ``input_delay``, 0 when the model has none."""
    try:
        numeric = spec.numeric("input_delay")
    except (KeyError, ValueError):
        numeric = None
    if numeric is None:
        return 0.0
    value = float(np.ravel(numeric.data)[0])
    if not np.isfinite(value) or value < 0 or value > MAX_INPUT_DELAY:
        raise ModelFileError(f"input_delay = {value!r} s is outside [0, {MAX_INPUT_DELAY:g}] s")
    return value


def encoder_noise(spec: mujoco.MjSpec) -> tuple[float, float]:
    """The rig's electronics noise on the pitch and the yaw measurement (rad): the custom numeric
    ``encoder_noise``, none when the model has none.

    Examples
    --------
    >>> pitch, yaw = encoder_noise(load_spec())
    >>> 0 < pitch < 0.01
    True
    """
    try:
        numeric = spec.numeric("encoder_noise")
    except (KeyError, ValueError):
        numeric = None
    if numeric is None:
        return 0.0, 0.0
    value = np.ravel(np.asarray(numeric.data, float))
    if value.shape != (2,) or not np.all(np.isfinite(value)) or np.any(value < 0) or np.any(value > 1):
        raise ModelFileError(
            f"custom numeric encoder_noise = {value.tolist()} rad; allowed: two numbers (pitch, yaw) in [0, 1] rad"
        )
    return float(value[0]), float(value[1])


def turbulence(spec: mujoco.MjSpec) -> Turbulence:
    """The rig's rotor-wash turbulence: the custom numeric ``rotor_turbulence``, none when the model lacks it
    (or lacks the turbulence actuators that apply it).

    Examples
    --------
    >>> t = turbulence(load_spec())
    >>> t.active
    True
    """
    names = {a.name for a in spec.actuators}
    try:
        numeric = spec.numeric("rotor_turbulence")
    except (KeyError, ValueError):
        numeric = None
    if numeric is None or not all(w in names for w in WASHES):
        return Turbulence()
    try:
        return Turbulence.from_array(numeric.data)
    except ValueError as exc:
        raise ModelFileError(f"custom numeric rotor_turbulence: {exc}") from exc


def spin_dofs(model: mujoco.MjModel) -> np.ndarray:
    """DOF indices of the rotors' spin joints (empty for a model without spinning rotors)."""
    names = {model.joint(i).name for i in range(model.njnt)}
    return np.array([model.jnt_dofadr[model.joint(s).id] for s in SPINS if s in names], dtype=int)


def add_scene(spec: mujoco.MjSpec) -> None:
    """Add the world of ``scene.xml`` (floor, light, cameras, skybox, visual settings) to a rig's ``spec``, in place.

    The world has no joint, mass or collision, so it changes nothing in the physics; it is what the
    renderer draws around the rig. A spec that already has the scene's cameras is left as it is.
    """
    root = ET.parse(SCENE_PATH).getroot()
    for include in root.findall("include"):
        root.remove(include)
    world = mujoco.MjSpec.from_string(ET.tostring(root, encoding="unicode"))
    have = {c.name for c in spec.cameras}
    if {c.name for c in world.cameras} <= have:
        return
    for group in ("global_", "quality", "map", "headlight"):
        src, dst = getattr(world.visual, group), getattr(spec.visual, group)
        for name in dir(src):
            if not name.startswith("_"):
                try:
                    setattr(dst, name, getattr(src, name))
                except (AttributeError, TypeError):
                    pass
    prefix = "scene_"
    spec.attach(world, frame=spec.worldbody.add_frame(), prefix=prefix)
    for element in (*spec.cameras, *spec.lights):  # the renderer and users name cameras as scene.xml does
        if element.name.startswith(prefix):
            element.name = element.name[len(prefix) :]


def build_model(
    spec: mujoco.MjSpec,
    configuration: Configuration,
    voltage_limit: float = 10.0,
    delay: bool = True,
    scene: bool = True,
    timestep: float | None = None,
) -> mujoco.MjModel:
    """Compile a model of one configuration from a copy of ``spec``.

    Locked joints and the sensors that name them are deleted from the copy (fixed tendons
    lose that joint and keep acting on the others); the file's keyframes are dropped (the twin
    starts at its trim with :meth:`Twin.put_at_trim <trms.twin.Twin.put_at_trim>`); each rotor's
    control range is set to the thrust its curve gives at ``-voltage_limit`` and ``+voltage_limit``,
    each spin motor's to the rotor speeds there. Every rotor actuator gets the model's :func:`input_delay`
    as its native transport delay, and each spin motor the gain that makes its rotor's speed lag like its
    thrust (``kv = spin inertia / motor lag``).

    Parameters
    ----------
    spec : mujoco.MjSpec
        The parsed MJCF (not modified).
    configuration : Configuration
    voltage_limit : float
        Motor voltage limit (V).
    delay : bool
        Apply the transport delay (``False`` for linearisation, which adds it exactly).
    scene : bool
        Add the world of ``scene.xml`` around the rig (:func:`add_scene`; no effect on the physics).
    timestep : float, optional
        Physics step (s) replacing the file's (:func:`physics_timestep` chooses a twin's).

    Returns
    -------
    mujoco.MjModel
    """
    s = configure_spec(spec, configuration, voltage_limit, delay, scene, timestep)
    try:
        model = s.compile()
    except Exception as exc:
        raise ModelFileError(f"model does not compile in configuration {configuration.name!r}: {exc}") from exc
    _tune_spin_motors(model)
    return model


def configure_spec(
    spec: mujoco.MjSpec,
    configuration: Configuration,
    voltage_limit: float = 10.0,
    delay: bool = True,
    scene: bool = False,
    timestep: float | None = None,
) -> mujoco.MjSpec:
    """The uncompiled spec of one configuration: a copy of ``spec`` as :func:`build_model` compiles it.

    Parameters
    ----------
    spec : mujoco.MjSpec
        The parsed MJCF (not modified).
    configuration : Configuration
    voltage_limit : float
        Motor voltage limit (V).
    delay : bool
        Apply the transport delay.
    scene : bool
        Add the world of ``scene.xml`` (:func:`add_scene`; no effect on the physics).
    timestep : float, optional
        Physics step (s) replacing the file's; the delay lines are sized for it.

    Returns
    -------
    mujoco.MjSpec
    """
    check_spec(spec)
    s = spec.copy()
    if timestep is not None:
        s.option.timestep = float(timestep)
    for joint_name in configuration.locked:
        for sensor in list(s.sensors):
            if sensor.objname == joint_name or sensor.name in (joint_name, f"{joint_name}_rate"):
                s.delete(sensor)
        for tendon in list(s.tendons):
            _drop_joint_from_tendon(s, tendon, joint_name)
        s.delete(s.joint(joint_name))
    for key in list(s.keys):  # made for the file's own joints; the twin starts at its trim by Twin.put_at_trim
        s.delete(key)
    curves = thrust_curves(s)
    names = {a.name for a in s.actuators}
    for actuator, spin, curve in zip(ROTORS, SPINS, curves):
        act = s.actuator(actuator)
        act.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
        act.ctrlrange = np.sort(curve.thrust(np.array([-voltage_limit, voltage_limit])))
        speeds = np.sort(np.asarray(curve.speed(np.array([-voltage_limit, voltage_limit])), float))
        if spin in names and speeds[1] > speeds[0]:
            motor = s.actuator(spin)
            motor.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
            motor.ctrlrange = speeds
    if scene:
        add_scene(s)
    lag = input_delay(s) if delay else 0.0
    for act in s.actuators:
        if act.name in WASHES:  # the air acts at once: only the motor commands are delayed
            continue
        act.delay = lag
        act.nsample = int(np.ceil(lag / s.option.timestep)) + 2 if lag > 0 else 0
    return s


def _tune_spin_motors(model: mujoco.MjModel) -> None:
    """Set each spin motor's velocity gain to (spin inertia) / (its rotor's motor lag)."""
    names = {model.actuator(i).name for i in range(model.nu)}
    if not all(n in names for n in SPINS):
        return
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    full = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, full)
    for rotor, spin in zip(ROTORS, SPINS):
        a = model.actuator(spin).id
        dof = model.jnt_dofadr[model.actuator_trnid[a, 0]]
        kv = full[dof, dof] / float(model.actuator_dynprm[model.actuator(rotor).id, 0])
        model.actuator_gainprm[a, 0] = kv
        model.actuator_biasprm[a, 2] = -kv
