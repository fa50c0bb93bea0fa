"""What the MJCF files carry that is derived from the model: control ranges, the hover keyframe, the README.

``trms.xml`` (the rig) holds, besides its physical parameters, values computed from them:

* ``ctrlrange`` on every actuator: the thrust (N) and rotor speed (rad/s) the thrust curves give at
  -10 V and +10 V (what :func:`~trms.twin.model.build_model` sets for the twin);
* ``delay`` and ``nsample`` on every motor-driven actuator (the rotors' thrust and spin motors): the transport
  delay the ``input_delay`` numeric holds, as MuJoCo's native actuator delay, and ``kv`` on each spin motor
  (its rotor's spin inertia over its motor lag), so that ``mujoco.MjModel.from_xml_path`` alone gives the
  twin's physics (the thrust curves, voltage to thrust, stay in their numerics: MuJoCo has no actuator
  quadratic in its control);
* a ``hover`` keyframe: the twin's hover trim with both axes free (joint angles and rates, lagged
  thrusts, controls), for users of the file in MuJoCo directly (``mj_resetDataKeyframe``; the
  actuators' delay lines, which a keyframe does not hold, start empty there: fill them with
  ``mj_initCtrlHistory``, as :meth:`Twin.put_at_trim <trms.twin.Twin.put_at_trim>` does).

:func:`write_derived` recomputes and writes them in place (comments kept); :func:`model_readme`
generates ``trms/models/README.md`` (every parameter's value, provenance and the calibration stage
that set it) from :data:`trms.twin.parameters.PARAMETERS` and the file. Writing calibrated values
with :func:`trms.twin.parameters.write_parameters` refreshes both, and a test checks that the
shipped files match a fresh computation.
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from pathlib import Path

import mujoco
import numpy as np

from trms.errors import ModelFileError
from trms.files import atomic_write
from trms.reference import VOLTAGE_LIMIT
from trms.twin.model import CONFIGURATIONS, DEFAULT_MODEL_PATH, SPINS, build_model, check_spec, load_spec

__all__ = ["KEYFRAME", "derived_values", "write_derived", "write_model", "model_readme", "write_readme", "README_PATH"]

#: Name of the hover keyframe.
KEYFRAME = "hover"
#: The model's README, beside the shipped MJCF.
README_PATH = DEFAULT_MODEL_PATH.with_name("README.md")
_TAGS = ("general", "velocity", "motor", "position")


def _fmt(values: np.ndarray) -> str:
    return " ".join(f"{float(v):.10g}" for v in np.ravel(values))


def _spec(path: str | os.PathLike[str]) -> mujoco.MjSpec:
    """The checked spec of a rig file whatever its name (a calibration writes a temporary ``*.copy`` first)."""
    path = Path(path)
    if path.suffix.lower() == ".xml":
        return load_spec(path)
    try:
        spec = mujoco.MjSpec.from_string(path.read_text())
    except Exception as exc:
        raise ModelFileError(f"model file {str(path)!r} is not valid MJCF: {exc}") from exc
    check_spec(spec, f"model file {str(path)!r}")
    return spec


def derived_values(path: str | os.PathLike[str] = DEFAULT_MODEL_PATH) -> dict[str, dict[str, np.ndarray]]:
    """The control ranges (by actuator name), the delays and spin-motor gains, and the hover keyframe of a rig file.

    ``ctrlrange`` maps each limited actuator to its range; ``delay`` each delayed actuator to ``[delay (s),
    nsample]``; ``kv`` each spin motor to its velocity gain (N m s/rad); the keyframe holds ``qpos``,
    ``qvel``, ``act`` and ``ctrl``.

    Examples
    --------
    >>> d = derived_values()
    >>> sorted(d["ctrlrange"])
    ['main_rotor', 'main_spin', 'tail_rotor', 'tail_spin']
    >>> sorted(d["delay"]) == sorted(d["ctrlrange"])
    True
    """
    from trms.twin.twin import Twin

    spec = _spec(path)
    model = build_model(spec, CONFIGURATIONS["2dof"], VOLTAGE_LIMIT, scene=False)
    ranges = {
        model.actuator(i).name: model.actuator_ctrlrange[i].copy()
        for i in range(model.nu)
        if model.actuator_ctrllimited[i]
    }
    delays = {
        model.actuator(i).name: np.array([model.actuator_delay[i], model.actuator_history[i, 0]])
        for i in range(model.nu)
        if model.actuator_history[i, 0] > 0
    }
    gains = {name: np.array([model.actuator(name).gainprm[0]]) for name in SPINS if name in ranges}
    trim = Twin("2dof", spec=spec).trim
    return {
        "ctrlrange": ranges,
        "delay": delays,
        "kv": gains,
        "keyframe": {"qpos": trim.qpos, "qvel": trim.qvel, "act": trim.act, "ctrl": trim.ctrl},
    }


def _set_attribute(text: str, tag_name: str, attribute: str, value: str) -> str:
    found = re.search(rf'<(?:{"|".join(_TAGS)}) name="{re.escape(tag_name)}"[^>]*?/?>', text)
    if found is None:
        raise ModelFileError(f"MJCF has no actuator named {tag_name!r}")
    element = found.group(0)
    attr = re.search(rf'\s{attribute}="[^"]*"', element)
    if attr is not None:
        new = element[: attr.start()] + f' {attribute}="{value}"' + element[attr.end() :]
    else:
        end = -2 if element.endswith("/>") else -1
        new = element[:end] + f' {attribute}="{value}"' + element[end:]
    return text[: found.start()] + new + text[found.end() :]


def write_derived(path: str | os.PathLike[str] = DEFAULT_MODEL_PATH) -> Path:
    """Recompute the derived values (:func:`derived_values`) of the rig file at ``path`` and write them in place.

    The rest of the file (comments included) is untouched; the result is parsed by MuJoCo before it
    replaces the file (atomically).
    """
    path = Path(path)
    values = derived_values(path)
    text = path.read_text()
    for name, rng in values["ctrlrange"].items():
        text = _set_attribute(text, name, "ctrlrange", _fmt(rng))
    for name, (lag, nsample) in values["delay"].items():
        text = _set_attribute(text, name, "delay", _fmt(np.array([lag])))
        text = _set_attribute(text, name, "nsample", str(int(nsample)))
    for name, kv in values["kv"].items():
        text = _set_attribute(text, name, "kv", _fmt(kv))
    key = values["keyframe"]
    block = (
        "  <keyframe>\n"
        "    <!-- The hover trim with both axes free, written by trms.twin.model_files.write_derived. -->\n"
        f'    <key name="{KEYFRAME}" ' + " ".join(f'{k}="{_fmt(v)}"' for k, v in key.items()) + "/>\n  </keyframe>\n"
    )
    if "<keyframe>" in text:
        text = re.sub(r"  <keyframe>.*?</keyframe>\n", lambda _: block, text, flags=re.S)
    else:
        text = text.replace("</mujoco>", block + "</mujoco>")
    try:
        mujoco.MjModel.from_xml_string(text) if "<include" not in text else None
    except Exception as exc:
        raise ModelFileError(f"writing the derived values into {str(path)!r} broke the model: {exc}") from exc
    mode = path.stat().st_mode & 0o777
    atomic_write(path, lambda fh: fh.write(text), binary=False)
    os.chmod(path, mode)
    return path


def _sources(text: str) -> list[str]:
    """The source legend ([F], [S] ...) of the rig file's header comment."""
    header = text.split("-->", 1)[0]
    lines, current = [], ""
    for line in header.splitlines():
        stripped = line.strip()
        if re.match(r"^\[[A-Z]\]", stripped):
            if current:
                lines.append(current)
            current = stripped
        elif current and stripped and not stripped.endswith(":") and not re.match(r"^[A-Z][a-z]+:", stripped):
            current += " " + stripped
        else:
            if current:
                lines.append(current)
            current = ""
    if current:
        lines.append(current)
    return lines


def model_readme(path: str | os.PathLike[str] = DEFAULT_MODEL_PATH, set_by: Mapping[str, str] | None = None) -> str:
    """The README of the rig file at ``path``: files, actuators, keyframe, every parameter's value and provenance.

    Parameters
    ----------
    path : path-like
        The rig's MJCF.
    set_by : mapping, optional
        For the parameters a calibration sets, what sets each (the README's *set by* column; the calibration's
        own mapping is :data:`trms.calibration.model_update.SET_BY`); every other parameter reads "published
        value", or "edited" where the file's value differs from the published one.

    Returns
    -------
    str
        Markdown.

    Examples
    --------
    >>> text = model_readme(set_by={"pitch_damping": "a fit"})
    >>> text.startswith("# TRMS model (MJCF)"), "| a fit |" in text
    (True, True)
    """
    from trms.twin.parameters import PARAMETERS, read_parameters

    stages = dict(set_by or {})

    path = Path(path)
    text = path.read_text()
    values = read_parameters(_spec(path))
    derived = derived_values(path)
    out = [
        "# TRMS model (MJCF)",
        "",
        "<!-- Generated by trms.twin.model_files.write_readme from trms.xml and trms.twin.parameters; "
        "a test checks it matches. -->",
        "",
        "A MuJoCo model of the Twin Rotor MIMO System (Feedback Instruments 33-220 / 33-949), laid out the way",
        "MuJoCo Menagerie lays out its models:",
        "",
        "- `trms.xml`: the rig (beam, rotors, joints, actuators, cable, sensors) and the `hover` keyframe;",
        "- `scene.xml`: the world around it (floor, light, cameras, skybox), which includes `trms.xml`;",
        "  it adds nothing that moves or collides, so the physics is that of `trms.xml` alone;",
        "- `LICENSE`: MIT, as the package.",
        "",
        "Units are SI. The actuators take thrust (N) and rotor speed (rad/s); the motor voltage (V), the unit",
        "of every Python interface of `trms`, passes through the thrust curves held in the `main_thrust_curve`",
        "and `tail_thrust_curve` numerics (`trms.twin.rotors.rotor_controls`). Both rotors' commands are",
        "delayed by the `input_delay` numeric (s), written on each motor-driven actuator as MuJoCo's native",
        "`delay` (with its `nsample`), and the spin motors' `kv` is written as the twin builds it: loading the file",
        "with `mujoco.MjModel.from_xml_path` alone gives the twin's physics.",
        "",
        f"## Actuators (control ranges at -{VOLTAGE_LIMIT:g} V and +{VOLTAGE_LIMIT:g} V)",
        "",
        "| actuator | control | ctrlrange | delay (s) |",
        "|---|---|---|---|",
    ]
    for name, rng in derived["ctrlrange"].items():
        unit = "thrust (N)" if name.endswith("rotor") else "rotor speed (rad/s)"
        lag = derived["delay"].get(name)
        out.append(f"| `{name}` | {unit} | {rng[0]:.6g} to {rng[1]:.6g} | {0.0 if lag is None else lag[0]:.6g} |")
    key = derived["keyframe"]
    out += [
        "",
        f"## Keyframe `{KEYFRAME}`",
        "",
        "The hover trim with both axes free (the beam flat, zero yaw): controls "
        + ", ".join(f"{c:.6g}" for c in key["ctrl"])
        + " (thrusts in N, rotor speeds in rad/s). A keyframe holds no delay lines: after",
        "`mujoco.mj_resetDataKeyframe`, fill each delayed actuator's with the keyframe's control",
        "(`mujoco.mj_initCtrlHistory(m, d, i, None, np.full((m.actuator_history[i, 0], 1), d.ctrl[i]))`), as",
        "`trms.twin.Twin.put_at_trim` does; otherwise the first `input_delay` seconds apply no thrust.",
        "",
        "## Parameters",
        "",
        "The physical parameters that calibration fits and robustness studies spread (`trms.twin.parameters`).",
        "*Set by*: the stage of `trms calibrate` that fits it (against the thesis's spectra, step response and",
        "eq. (3.11)), or the published value (or stated assumption) it keeps. *Role*: physical, the quantity its",
        "name says, read against its published value (source as in the legend below; the departure is the value",
        "over the published one, less 1); or lumped, a knob that carries what the model has no element for (the",
        "description says what it stands for).",
        "",
        "| parameter | role | value | unit | published | departure | MJCF | set by | description |",
        "|---|---|---:|---|---:|---:|---|---|---|",
    ]
    for p in PARAMETERS.values():
        if p.name in stages:
            by = stages[p.name]
        elif np.isclose(values[p.name], p.published, rtol=1e-6, atol=0):
            by = "published value"
        else:
            by = "edited (differs from the published value)"
        attribute = "axis (its lean x/z)" if p.attribute == "axis:lean" else p.attribute
        where = f"{p.kind} `{p.element}` {attribute}" + (f"[{p.index}]" if p.index else "")
        departure = p.departure(values[p.name])
        moved = "-" if not np.isfinite(departure) else f"{100 * departure:+.0f} %"
        what = p.description + (f"; lumped: {p.stands_for}" if p.role == "lumped" else "")
        out.append(
            f"| `{p.name}` | {p.role} | {values[p.name]:.6g} | {p.unit or '-'} | {p.published:.6g} [{p.source}] | "
            f"{moved} | {where} | {by} | {what} |"
        )
    out += ["", "## Sources", "", "Each value in `trms.xml` cites its source in a comment beside it:", ""]
    out += [f"- {line}" for line in _sources(text)]
    return "\n".join(out) + "\n"


def write_readme(
    path: str | os.PathLike[str] = DEFAULT_MODEL_PATH,
    readme: str | os.PathLike[str] = README_PATH,
    set_by: Mapping[str, str] | None = None,
) -> Path:
    """Write :func:`model_readme` of the rig at ``path`` (``set_by`` as there) to ``readme``, atomically."""
    content = model_readme(path, set_by)
    return atomic_write(Path(readme), lambda fh: fh.write(content), binary=False)


def write_model(path: str | os.PathLike[str], values: Mapping[str, float]) -> Path:
    """Write parameter ``values`` into the rig file at ``path``, then the values derived from them.

    :func:`~trms.twin.parameters.write_parameters` writes the parameters;
    :func:`write_derived` then refreshes the control ranges and the hover keyframe, so the file is whole again.
    Each step replaces the file atomically.

    Parameters
    ----------
    path : path-like
        The MJCF to change in place.
    values : mapping
        Parameter name -> value (units of :data:`~trms.twin.parameters.PARAMETERS`).

    Returns
    -------
    pathlib.Path

    Examples
    --------
    >>> import shutil, tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> _ = shutil.copy(DEFAULT_MODEL_PATH, folder / "rig.xml")
    >>> _ = write_model(folder / "rig.xml", {"main_reaction": 0.05})
    >>> key = derived_values(folder / "rig.xml")["keyframe"]["ctrl"]
    >>> bool(abs(key[0] - derived_values()["keyframe"]["ctrl"][0]) > 0)
    True
    """
    from trms.twin.parameters import write_parameters

    write_parameters(path, values)
    return write_derived(path)
