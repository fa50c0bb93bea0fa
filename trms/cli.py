"""The ``trms`` command.

Subcommands
-----------
reproduce
    The main job: every experiment of the thesis on the linear model and on the twin, written as a
    report folder (Markdown, HTML, PNG figures, a GIF render, tables as JSON).
simulate
    A configuration and an input signal (generated or read from a file) -> a Record.
identify
    A Record -> an ARMAX model (JSON), residual tests, spectra and validation figures.
design
    Integral LQG gains, estimator and prefilter for given weights (JSON).
run
    A closed loop (SAS/CSAS, or the 2-DOF autopilot) on the twin or the linear model.
render
    A twin Record -> PNG (last frame), GIF or MP4.
robustness
    Monte Carlo of the closed loops under a spread of the twin's parameters, as Dask tasks.
import
    A rig's CSV export (time column, named columns, degrees or radians) -> a Record with its operating point.
calibrate
    Fit the twin's physical parameters to the thesis's targets, or to your rig's records in the time
    domain, and write them into a new MJCF.
demo
    Trim the rig at hover, print its modes, excite it with a small PRBS, write a record and renders.

Every subcommand writes files, prints a summary, and exits with status 2 and a one-line message
on stderr on any failure (a missing file, a wrong shape, an unknown option, a simulation that
diverged); ``--debug`` shows the traceback instead. Output files are written only once the work
has succeeded, each atomically (:mod:`trms.files`). Durations and amplitudes are capped
(:data:`MAX_DURATION`, :data:`MAX_AMPLITUDE_V`, :data:`MAX_AMPLITUDE_RAD`); ``--max-duration`` and
``--max-amplitude`` raise the caps.
"""

from __future__ import annotations

import argparse
import contextlib
import errno
import json
import os
import sys
import traceback
import warnings
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn

import numpy as np

from trms import reference
from trms.errors import ConfigurationError, InputError, TrmsError, check_in_range
from trms.files import atomic_group, atomic_write

if TYPE_CHECKING:
    from trms.plant import Plant

__all__ = ["main", "MAX_DURATION", "MAX_AMPLITUDE_V", "MAX_AMPLITUDE_RAD", "DEMO_AMPLITUDE"]

_FMT = argparse.RawDescriptionHelpFormatter

#: Longest run (s) a command accepts unless ``--max-duration`` raises it: one hour of rig time.
MAX_DURATION = 3600.0
#: Largest signal amplitude (V) around hover: twice the motor limit; anything wider only saturates.
MAX_AMPLITUDE_V = 2.0 * reference.VOLTAGE_LIMIT
#: Largest reference amplitude (rad) of ``trms run``: pitch's end stop (1.1 rad) in the shipped model.
MAX_AMPLITUDE_RAD = 1.1
#: PRBS amplitude (V) of ``trms demo``: a small excitation. The yaw axis (0.1 Hz, damping 0.04) is the one
#: it swings most: 2-DOF, 60 s, 2 Hz, seeds 0-9 reach at most 42 deg of yaw (0.2 V swung it to the +-172 deg stops).
DEMO_AMPLITUDE = 0.02


class _UsageError(Exception):
    """A command line argparse refused (reported as one line, exit 2)."""


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser whose errors become one line on stderr (through :func:`main`), not usage + message."""

    def error(self, message: str) -> NoReturn:
        raise _UsageError(f"{self.prog}: error: {' '.join(message.split())} (see {self.prog} --help)")


def _caps(args: argparse.Namespace, amplitude_cap: float, unit: str) -> None:
    """Refuse a duration or amplitude beyond the stated caps (or the user's ``--max-*``)."""
    max_d = check_in_range("--max-duration", args.max_duration, 0.0, np.inf, unit=" s", low_open=True)
    max_a = (
        amplitude_cap
        if args.max_amplitude is None
        else check_in_range("--max-amplitude", args.max_amplitude, 0.0, np.inf, unit=unit)
    )
    try:
        check_in_range("--duration", args.duration, 0.0, max_d, unit=" s", low_open=True)
    except InputError as exc:
        raise InputError(f"{exc} (a longer run needs --max-duration)") from None
    try:
        check_in_range("--amplitude", args.amplitude, 0.0, max_a, unit=unit)
    except InputError as exc:
        raise InputError(f"{exc} (a larger amplitude needs --max-amplitude)") from None


def _two_samples(args: argparse.Namespace, sample_time: float) -> None:
    """Refuse a ``--duration`` shorter than two samples (a run of one sample is a hold, not a response)."""
    try:
        check_in_range("--duration", args.duration, 2.0 * sample_time, float(args.max_duration), unit=" s")
    except InputError as exc:
        raise InputError(f"{exc} (a run needs at least two samples of {sample_time:g} s)") from None


def _cap_options(p: argparse.ArgumentParser, unit: str, default: float) -> None:
    p.add_argument(
        "--max-duration",
        type=float,
        default=MAX_DURATION,
        help=f"cap on --duration in s (default {MAX_DURATION:g}: one hour)",
    )
    p.add_argument(
        "--max-amplitude", type=float, default=None, help=f"cap on --amplitude in {unit} (default {default:g})"
    )


# ------------------------------------------------------------------------------------------ helpers
def _plant(args: argparse.Namespace, **kwargs: Any) -> Plant:
    from trms.worlds import make_plant

    return make_plant(
        args.plant,
        args.config,
        args.sample_time,
        seed=args.seed,
        noise_std=args.noise,
        gusts=getattr(args, "gusts", False),
        **kwargs,
    )


def _read_inputs(path: str, n_inputs: int) -> np.ndarray:
    """Input samples (V) from ``.npy``, ``.csv``/``.txt`` (one row per sample, optional header) or a Record ``.npz``."""
    from trms.errors import as_finite_array
    from trms.record import Record

    p = Path(path)
    if not p.is_file():
        raise InputError(f"input file {path!r} does not exist")
    if p.suffix == ".npz":
        data = Record.load(p).inputs
    elif p.suffix == ".npy":
        try:
            data = np.load(p, allow_pickle=False)
        except ValueError as exc:
            if "allow_pickle" not in str(exc):
                raise InputError(f"input file {path!r} is not a numpy array file: {exc}") from None
            raise InputError(
                f"input file {path!r} holds Python objects, which are never loaded (they could run code); "
                "allowed: an .npy of numbers (np.save of a float array)"
            ) from None
    else:
        from trms.rigdata import decode_export

        text, _ = decode_export(p.read_bytes(), p)  # refuses binary data in one line; UTF-8, else Latin-1
        lines = [ln for ln in text.splitlines() if ln.strip()]
        try:
            float(lines[0].replace(",", " ").split()[0])
        except (ValueError, IndexError):
            lines = lines[1:]
        try:
            data = np.array([[float(x) for x in ln.replace(",", " ").split()] for ln in lines])
        except ValueError as exc:
            raise InputError(f"input file {path!r} holds a non-numeric value: {exc}") from exc
    label = f"inputs in {path!r} (one column per input, {n_inputs} expected)"
    arr = as_finite_array(label, data)
    if arr.ndim == 1 and n_inputs == 1:
        arr = arr[:, None]
    arr = as_finite_array(label, arr, (None, n_inputs))
    from trms.rigdata import MAX_INPUT_V

    worst = float(np.max(np.abs(arr), initial=0.0))
    if worst > MAX_INPUT_V:
        raise InputError(
            f"{label}: {worst:.6g} V is beyond the plausible +-{MAX_INPUT_V:g} V of a motor voltage "
            "(the drives saturate at +-10 V): is the file in volts?"
        )
    if arr.shape[0] == 0:
        raise InputError(f"input file {path!r} holds no samples; allowed: at least 1 row")
    return arr


def _signal(args: argparse.Namespace, ts: float) -> np.ndarray:
    from trms.identification import doublet, multistep_3211, random_binary, square_wave, uniform_noise

    kind, d, a, b, seed = args.signal, args.duration, args.amplitude, args.bandwidth, args.seed
    if kind == "prbs":
        return random_binary(d, ts, b, a, seed=seed)
    if kind == "uniform":
        return uniform_noise(d, ts, b, a, seed=seed)
    if kind == "3211":
        return multistep_3211(ts, args.step, a, start=args.start, duration=d)
    if kind == "doublet":
        return doublet(ts, args.step, a, start=args.start, duration=d)
    if kind == "square":
        return square_wave(d, ts, args.period, a)
    return np.zeros(int(round(d / ts)))


def _ranges(rec) -> str:
    """One line: each output's range (rad) and the number of saturated samples."""
    y = rec.outputs
    if len(rec) == 0:
        return "no samples"
    return (
        ", ".join(f"{n} in [{y[:, i].min():+.4f}, {y[:, i].max():+.4f}] rad" for i, n in enumerate(rec.output_names))
        + f"; saturated samples: {int(rec.extras['saturated'].any(axis=1).sum())}"
        + (
            f"; samples at an end stop: {int(rec.extras['at_stop'].any(axis=1).sum())}"
            if "at_stop" in rec.extras
            else ""
        )
    )


def _load_record(path: str):
    """A Record file, with a warning when its angles pass the rig's end stops (with the rig reader's margin)."""
    from trms.record import Record
    from trms.rigdata import beyond_end_stops

    rec = Record.load(path)
    beyond = beyond_end_stops(rec)
    if beyond:
        warnings.warn(
            f"record {path!r}: {beyond}, beyond the rig's end stops: no rig moves there (angles not in rad?)",
            stacklevel=2,
        )
    return rec


def _say(line: str) -> None:
    print(line, flush=True)


# -------------------------------------------------------------------------------------- subcommands
def _simulate(args: argparse.Namespace) -> int:
    from trms.plant import simulate

    _caps(args, MAX_AMPLITUDE_V, " V")
    plant = _plant(args)
    n_in = len(plant.input_names)
    op = plant.operating_point
    if args.input:
        u = _read_inputs(args.input, n_in)
        if args.deviation:
            u = op.absolute_input(u)
    else:
        _two_samples(args, plant.sample_time)
        sig = _signal(args, plant.sample_time)
        if args.channel not in plant.input_names:
            raise InputError(f"unknown input channel {args.channel!r}; this plant has {', '.join(plant.input_names)}")
        u = op.with_signal(sig, args.channel)
    rec = simulate(plant, u, seed=args.seed, metadata={"config": args.config, "world": args.plant})
    if args.plant != "twin":
        from trms.rigdata import beyond_end_stops

        beyond = beyond_end_stops(rec, margin=0.0)
        if beyond:  # the twin has the stops; the linear model runs through them
            warnings.warn(
                f"{beyond}: past the rig's end stops, where the linear model is not valid (the twin, --plant twin, "
                "has the stops; a smaller --amplitude stays within them)",
                stacklevel=1,
            )
    with atomic_group():  # written only now that the run succeeded: both files, or neither (old ones kept)
        out = rec.save(args.out)
        csv = rec.to_csv(out.with_suffix(".csv")) if args.csv else None
    print(
        f"{args.plant} {args.config}: {len(rec)} samples at {plant.sample_time} s; hover "
        + ", ".join(f"{n} = {v:.3f} V" for n, v in zip(plant.input_names, op.inputs))
    )
    print(_ranges(rec))
    print(f"wrote {out}")
    if csv is not None:
        print(f"wrote {csv}")
    return 0


def _identify(args: argparse.Namespace) -> int:
    from trms.identification import armax, compare, find_modes, psd, residual_tests, siso_data
    from trms.modes import oscillatory, real_poles
    from trms.present.figures import plot_correlation_tests, plot_series, plot_spectra, save_figure

    rec = _load_record(args.record)
    d = siso_data(rec, input=args.input, output=args.output)
    na, nb, nc, nk = args.orders
    model = armax(d.y, d.u, na, nb, nc, nk, sample_time=d.sample_time, input=d.input_name, output=d.output_name)
    tests = residual_tests(model, d.y, d.u, nonlinear=False)
    f, p = psd(d.y, d.sample_time)
    _, pm = psd(model.simulate(d.u, d.y), d.sample_time)
    peaks = find_modes(f, p, (0.03, min(2.0, f[-1])), n=3)
    summary = {
        "input": d.input_name,
        "output": d.output_name,
        "sample_time": d.sample_time,
        "orders": [na, nb, nc, nk],
        "A": model.A.tolist(),
        "B": model.B.tolist(),
        "C": model.C.tolist(),
        "noise_variance": model.noise_variance,
        "dc_gain": model.dc_gain(),
        "modes": [
            {"frequency_hz": m.frequency_hz, "damping": m.damping}
            for m in oscillatory(model.modes(), model.sample_time)
        ],
        "psd_peaks_hz": [pk.frequency for pk in peaks],
        "residual_tests": {t.name: {"passed": t.passed, "outside": t.n_outside} for t in tests},
    }
    val = c = None
    if args.validate:
        val = _load_record(args.validate)
        _same_configuration(rec, val, args.record, args.validate)
        dv = siso_data(val, input=d.input_name, output=d.output_name)
        c = compare(model, dv.y, dv.u)
        summary["validation_fit_percent"] = c.fit
    # Every number is computed: only now are files written.
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    files = [
        save_figure(
            plot_correlation_tests(tests, f"{d.input_name} -> {d.output_name}: residual tests"), out / "residuals.png"
        ),
        save_figure(
            plot_spectra(
                {"measured": (f, p), "model": (f, pm)},
                "Output PSD, measured and model",
                (),
                {"measured": peaks},
                fmax=min(2.0, float(f[-1])),
            ),
            out / "psd.png",
        ),
    ]
    if val is not None and c is not None:
        files.append(
            save_figure(
                plot_series(
                    val.time,
                    {"measured": c.y, f"model (fit {c.fit:.1f} %)": c.yhat},
                    "Free-run validation",
                    f"{d.output_name}, deviation from the operating point (rad)",
                ),
                out / "validation.png",
            )
        )
    js = atomic_write(out / "model.json", lambda fh: fh.write(json.dumps(summary, indent=1)), binary=False)
    print(
        f"ARMAX({na},{nb},{nc},{nk}) {d.input_name} -> {d.output_name} on {len(d)} samples: DC gain "
        f"{model.dc_gain():.4g}, noise variance {model.noise_variance:.3g}"
    )
    for m in oscillatory(model.modes(), model.sample_time):
        print(f"  mode {m.frequency_hz:.4f} Hz, damping {m.damping:.3f}")
    real = real_poles(model.modes(), model.sample_time)
    if real:
        print("  real poles and poles near Nyquist (not modes): " + ", ".join(f"{m.frequency_hz:.3g} Hz" for m in real))
    print("  residual tests: " + ", ".join(f"phi_{t.name} {'pass' if t.passed else 'fail'}" for t in tests))
    if "validation_fit_percent" in summary:
        print(f"  validation fit {summary['validation_fit_percent']:.1f} %")
    for path in (js, *files):
        print(f"wrote {path}")
    return 0


def _same_configuration(rec, other, name: str, other_name: str) -> None:
    """Refuse a second record of another configuration (other channels, or another ``config``)."""
    a, b = rec.metadata.get("config"), other.metadata.get("config")
    if (rec.input_names, rec.output_names) != (other.input_names, other.output_names) or (a and b and a != b):
        raise InputError(
            f"{other_name!r} is a {b or 'unknown'} record with inputs ({', '.join(other.input_names)}) and outputs "
            f"({', '.join(other.output_names)}); {name!r} is a {a or 'unknown'} record with inputs "
            f"({', '.join(rec.input_names)}) and outputs ({', '.join(rec.output_names)}): they must match"
        )


def _design_parts(args: argparse.Namespace):
    from trms.control.lqg import design_lqg
    from trms.experiments.ch67_lqg import ESTIMATOR_QE, ESTIMATOR_RE, prefilters
    from trms.worlds import design_model

    model = design_model(args.config)
    design = design_lqg(model, Q=args.q, R=args.r, Qe=ESTIMATOR_QE, Re=ESTIMATOR_RE)
    filt = None
    if args.case != "SAS":
        table = prefilters(model.dt)
        if args.case not in table:
            raise InputError(f"unknown case {args.case!r}; allowed: {', '.join(repr(c) for c in table)}")
        filt = table[args.case]
    return model, design, filt


def _design(args: argparse.Namespace) -> int:
    model, design, filt = _design_parts(args)
    out = Path(args.out)
    z = lambda v: [[float(c.real), float(c.imag)] for c in v]  # noqa: E731
    data = {
        "config": args.config,
        "sample_time": design.sample_time,
        "Q": float(args.q),
        "R": float(args.r),
        "design_model": {
            "A": np.asarray(model.A).tolist(),
            "B": np.asarray(model.B).tolist(),
            "C": np.asarray(model.C).tolist(),
            "states": list(model.state_labels),
        },
        "K": design.K.tolist(),
        "Lc": design.Lc.tolist(),
        "regulator_poles": z(design.regulator_poles),
        "estimator_poles": z(design.estimator_poles),
        "estimator_faster": design.estimator_faster,
        "prefilter": None if filt is None else {"name": filt.name, "sos": filt.sos.tolist()},
    }
    atomic_write(out, lambda fh: fh.write(json.dumps(data, indent=1)), binary=False)
    mag = lambda v: ", ".join(f"{abs(c):.3f}" for c in v)  # noqa: E731
    print(
        f"integral LQG on the {args.config} design model ({model.nstates} states, Ts = {design.sample_time} s), "
        f"Q = {args.q:g} I, R = {args.r:g}"
    )
    print(f"  K = {np.array2string(design.K, precision=4)}")
    print(f"  |regulator poles| {mag(design.regulator_poles)}")
    print(f"  |estimator poles| {mag(design.estimator_poles)} (faster than the regulator: {design.estimator_faster})")
    print(f"  prefilter: {'none (SAS)' if filt is None else filt.name}")
    print(f"wrote {out}")
    return 0


def _run(args: argparse.Namespace) -> int:
    from trms.control.loop import deviation_limits
    from trms.control.plots import plot_closed_loop
    from trms.present.figures import save_figure

    _caps(args, MAX_AMPLITUDE_RAD, " rad")
    if args.config != "1dof" and args.r is not None:
        raise InputError(
            f"--r {args.r:g} sets the 1-DOF loop's R; the {args.config} autopilot's controllers have their own "
            "weights (--controller): leave --r out"
        )
    r = 125.0 if args.r is None else args.r
    out = Path(args.out)
    pushes = []
    if args.push_impulse:
        if args.plant != "twin":
            raise InputError("--push-impulse needs --plant twin (the linear model has no torque input)")
        from trms.experiments.ch8_mimo_lqg import DURATION
        from trms.twin import Push

        length = args.duration if args.config == "1dof" else DURATION  # the autopilot's scenarios have their own
        try:
            check_in_range("--push-time", args.push_time, 0.0, length, unit=" s")
        except InputError as exc:
            raise InputError(f"{exc} (the push must come within the {length:g} s run)") from None

        pushes = [Push.impulse(args.push_time, args.push_impulse, 0.2, "pitch")]
    plant = _plant(args, pushes=pushes)
    meta_extra = {"config": args.config, "world": args.plant}
    if args.config == "1dof":
        from trms.experiments.ch67_lqg import NARROW_BAND, WIDE_BAND, judge, run_case, square_wave_metrics
        from trms.worlds import design_model

        rec, steps = run_case(
            plant, r, args.case, args.amplitude, args.period, args.duration, args.seed, model=design_model("1dof")
        )
        wide = square_wave_metrics(rec, band=WIDE_BAND)
        status = judge(rec, wide)
        if status == "settled":
            status = f"settled within the {100 * WIDE_BAND:g} % band"
        title = f"{args.case}, Q = I, R = {r:g} ({args.plant})"
        lines = [_step_line(m, w, NARROW_BAND, WIDE_BAND) for m, w in zip(steps, wide)]
        fig = plot_closed_loop(rec, title, deviation_limits(plant), output=0)
    else:
        from trms.control.loop import closed_loop
        from trms.experiments.ch8_mimo_lqg import SCENARIOS, _measures, controllers, scenario_reference
        from trms.worlds import design_model

        if args.scenario not in SCENARIOS:
            raise InputError(f"unknown scenario {args.scenario!r}; allowed: {', '.join(repr(s) for s in SCENARIOS)}")
        ctrl = controllers(design_model("2dof"), limits=deviation_limits(plant))[args.controller]
        rec = closed_loop(plant, ctrl, scenario_reference(args.scenario, plant.sample_time), seed=args.seed)
        tracked = SCENARIOS[args.scenario][0]
        m = _measures(rec, tracked)
        settled = np.isfinite(m["TS"])
        status = f"{'settled' if settled else 'not settled'} within the 2 % band ({rec.output_names[tracked]} tracked)"
        title = f"{args.controller}, {args.scenario} ({args.plant})"
        lines = [_autopilot_line(m, rec.output_names[1 - tracked])]
        fig = _plot_autopilot(rec, title, deviation_limits(plant))
    rec.metadata.update(meta_extra)
    out.mkdir(parents=True, exist_ok=True)
    npz = rec.save(out / "record.npz")
    png = save_figure(fig, out / "response.png")
    print(f"{title}: {status}")
    for ln in lines:
        print(ln)
    print(f"wrote {npz}\nwrote {png}")
    return 0


def _seconds(value: float, missing: str) -> str:
    return f"{value:.2f} s" if np.isfinite(value) else missing


def _step_line(m, wide, narrow_band: float, wide_band: float) -> str:
    """One step of a 1-DOF run: rise, settling (in the narrow band, else the wide one, else not settled), overshoot."""
    nb, wb = f"{100 * narrow_band:g} %", f"{100 * wide_band:g} %"
    if np.isfinite(m.settling_time):
        ts = f"TS ({nb}) {m.settling_time:.2f} s"
    elif np.isfinite(wide.settling_time):
        ts = f"TS ({nb}) not settled, TS ({wb}) {wide.settling_time:.2f} s"
    else:
        ts = f"TS not settled within {wb}"
    over = f"{m.overshoot:.1f} %" if np.isfinite(m.overshoot) else "not measured"
    return (
        f"  step at {m.start_time:5.1f} s: TR {_seconds(m.rise_time, 'not reached')}, {ts}, overshoot {over}, "
        f"peak |u| {m.peak_control:.2f} V"
    )


def _autopilot_line(m: dict[str, float], other: str) -> str:
    """The 2-DOF measures with their units; a step that never settled is said, not printed as nan."""
    return (
        f"  TR {_seconds(m['TR'], 'not reached')}, TS (2 %) {_seconds(m['TS'], 'not settled')}, "
        f"overshoot {m['overshoot']:.1f} %, {other} excursion {m['cross']:.3g} rad, "
        f"RMS u1 {m['rms u1']:.3g} V, RMS u2 {m['rms u2']:.3g} V, total variation of u {m['TV']:.3g} V"
    )


def _plot_autopilot(rec, title: str, limits: tuple[np.ndarray, np.ndarray]):
    """A 2-DOF closed loop: one panel per output (pitch and yaw, rad), the controls with each input's own limits."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from trms.control.plots import plot_closed_loop

    n = len(rec.output_names)
    fig = Figure(figsize=(8.0, 2.4 * (n + 1) + 0.5), dpi=100)
    FigureCanvasAgg(fig)
    axes = fig.subplots(n + 1, 1, sharex=True)
    plot_closed_loop(rec, title, None, output=0, ax=(axes[0], axes[-1]))  # the first output and every control
    _, dy = rec.deviations()
    for i in range(1, n):
        axes[i].plot(rec.time, rec.extras["reference"][:, i], "k:", lw=1.0, label="command")
        axes[i].plot(rec.time, dy[:, i], "b", lw=1.2, label=f"{rec.output_names[i]} (deviation)")
        axes[i].legend(loc="upper right", fontsize=8)
        axes[i].grid(True, alpha=0.3)
    for i, name in enumerate(rec.output_names):
        axes[i].set_ylabel(f"{name} (rad)")
    ctrl = axes[-1]
    lo, hi = ctrl.get_ylim()
    text = []
    for j, name in enumerate(rec.input_names):
        pair = (float(limits[0][j]), float(limits[1][j]))
        inside = [v for v in pair if lo <= v <= hi]
        for v in inside:
            ctrl.axhline(v, color=ctrl.get_lines()[j].get_color(), ls="--", lw=0.8)
        text.append(f"{name} {pair[0]:+.3g} / {pair[1]:+.3g} V" + ("" if len(inside) == 2 else " (outside the view)"))
    ctrl.set_ylim(lo, hi)
    ctrl.text(0.01, 0.95, "actuator limits: " + "; ".join(text), transform=ctrl.transAxes, fontsize=7, va="top")
    return fig


def _render(args: argparse.Namespace) -> int:
    from trms.twin import Twin
    from trms.twin.render import render_record

    rec = _load_record(args.record)
    recorded = rec.metadata.get("config")
    config = args.config or recorded
    if config is None:
        raise InputError(f"record {args.record!r} does not say its configuration; pass --config")
    if recorded is not None and config != recorded:
        raise ConfigurationError(
            f"--config {config} does not match record {args.record!r}, recorded in "
            f"configuration {recorded!r}: pass the --config it was recorded with ({recorded}) or leave it out"
        )
    if len(rec) == 0:
        raise InputError(f"record {args.record!r} holds 0 samples; allowed: at least 1 to render")
    rec.sample_time  # noqa: B018 -- refuses a record whose sample time is not > 0 before anything is drawn
    model = Twin(config, 0.1).model
    if "qpos" in rec.extras and rec.extras["qpos"].shape[1] != model.nq:
        raise InputError(
            f"record {args.record!r} has {rec.extras['qpos'].shape[1]} joint positions per sample; the "
            f"{config} twin has {model.nq}: pass the --config it was recorded with"
        )
    path = render_record(
        model, rec, args.out, camera=args.camera, every=args.every, width=args.width, height=args.height
    )
    print(f"rendered {len(rec)} samples ({config}, camera {args.camera})\nwrote {path}")
    return 0


def _import(args: argparse.Namespace) -> int:
    from trms.rigdata import load_records

    rec = load_records([args.csv], args, saved=False)[0]
    out = rec.save(args.out)  # before anything is printed: a closed pipe cannot lose the Record
    src = rec.metadata.get("operating_point_source")
    if src is None:
        _say("operating point: unknown (no --hover segment); identification refuses this record until it is detrended")
    else:
        op = rec.operating_point
        _say(
            f"operating point ({src}): inputs {np.round(op.inputs, 4).tolist()} V, "
            f"outputs {np.round(op.outputs, 5).tolist()} rad"
        )
    _say(
        f"{len(rec)} samples at {rec.sample_time:g} s, inputs {', '.join(rec.input_names)}, outputs "
        f"{', '.join(rec.output_names)} (rad); wrote {out}"
    )
    return 0


def _reproduce(args: argparse.Namespace) -> int:
    from trms.report import reproduce

    report = reproduce(args.out, quick=args.quick, seed=args.seed, workers=args.workers, progress=_say)
    print()
    for line in report.sections[0].paragraphs[:2]:  # the twin at a glance: hover voltages and modes per configuration
        print(line)
    print()
    print(report.headline.to_markdown())
    print(f"wall time {report.seconds:.1f} s ({'quick' if args.quick else 'full'} run)")
    for path in report.files.values():
        print(f"wrote {path}")
    missing = report.missing()
    if missing:
        print("incomplete cells: " + "; ".join(missing), file=sys.stderr)
        return 1
    return 0


def _demo(args: argparse.Namespace) -> int:
    from trms.signals import random_binary
    from trms.twin import Twin
    from trms.twin.render import render_record

    _caps(args, MAX_AMPLITUDE_V, " V")
    check_in_range("--modes", args.modes, 1, 100)
    out = Path(args.out)
    twin = Twin(args.config, args.sample_time, seed=args.seed)
    _two_samples(args, twin.sample_time)
    hover = twin.operating_point.inputs
    print(f"TRMS twin, configuration {twin.configuration.name} ({twin.configuration.description})")
    print("hover voltages: " + ", ".join(f"{n} = {v:.4f} V" for n, v in zip(twin.input_names, hover)))
    print("modes at hover (linearised):")
    for mode in twin.modes()[: args.modes]:
        print(f"  {mode.frequency_hz:8.4f} Hz  damping {mode.damping:6.4f}  ({mode.dominant})")
    n_in = len(twin.input_names)
    inputs = np.column_stack(
        [
            random_binary(
                args.duration,
                twin.sample_time,
                args.bandwidth,
                args.amplitude,
                offset=float(hover[i]),
                seed=args.seed + i,
            )
            for i in range(n_in)
        ]
    )
    record = twin.run(inputs)
    out.mkdir(parents=True, exist_ok=True)
    npz = record.save(out / "record.npz")
    csv = record.to_csv(out / "record.csv")
    png = render_record(twin.model, record, out / "rig.png", camera="oblique", width=480, height=360)
    every = max(1, int(round(0.5 / twin.sample_time)))
    gif = render_record(twin.model, record, out / "rig.gif", camera="oblique", every=every, width=320, height=240)
    print(f"simulated {record.time[-1] + twin.sample_time:.1f} s at {twin.sample_time} s: " + _ranges(record))
    excursion = np.degrees(np.max(np.abs(record.deviations()[1]), axis=0))
    print(
        f"PRBS of +-{args.amplitude:g} V around hover; largest excursion from hover: "
        + ", ".join(f"{n} {e:.1f} deg" for n, e in zip(record.output_names, excursion))
    )
    for path in (npz, csv, png, gif):
        print(f"wrote {path}")
    return 0


# ------------------------------------------------------------------------------------------- parser
def _plant_options(p: argparse.ArgumentParser, configs: Sequence[str] = ("1dof", "2dof", "yaw")) -> None:
    p.add_argument(
        "--plant",
        default="twin",
        choices=["twin", "linear"],
        help="the MuJoCo twin or the linear model (eq. 3.11 for 1dof, the twin's linearisation otherwise)",
    )
    p.add_argument("--config", default="1dof", choices=list(configs), help="rig configuration (default 1dof)")
    p.add_argument("--sample-time", type=float, default=None, help="s (default: 0.2 for 1dof, 0.1 otherwise)")
    p.add_argument("--seed", type=int, default=0, help="seed of the signal, noise and gusts (default 0)")
    p.add_argument(
        "--noise", type=float, default=1e-3, help="measurement noise standard deviation in rad (default 1e-3)"
    )


_EPILOGS = {
    "import": """examples:
  trms import rig.csv --time t --inputs Vmain --outputs pitch_deg --units deg --hover 0:10 --config 1dof --out rig.npz
  trms import rig.csv --time t --inputs V1 V2 --outputs pitch yaw --units rad --hover 0:5 --config 2dof
  trms import log.txt --time t_ms --time-unit ms --inputs V1 --outputs pitch --units deg --hover 0:10
  trms import run.mat --time 'log(:,1)' --inputs 'log(:,2)' --outputs 'log(:,3)' --units rad --hover 0:10
  trms import run.mat --time data.time --inputs data.u1 data.u2 --outputs data.pitch data.yaw --units deg

Text exports may be comma, semicolon, tab or whitespace delimited, UTF-8 or Latin-1; lines starting with
'#' and title lines before the header are skipped (and named). A .mat file (MATLAB v5/v7; save v7.3 files
as v7) names its columns as variables, struct fields or matrix columns (1-based). The time column must
increase with one sample time inside the rig's 0.001..32.767 s: jitter up to 5 % of a sample is snapped
to a uniform grid, more is refused unless --resample interpolates it. The angles are checked against the
rig's end stops and speed (degrees labelled radians are refused) and converted to radians. The operating
point is the mean of the --hover segment [T0, T1) (printed, and stored in the Record); without it the
Record has none and `trms identify` refuses it. What the reader did is printed as warnings.
""",
    "simulate": """examples:
  trms simulate --config 1dof --signal prbs --amplitude 0.1 --duration 60 --out prbs.npz
  trms simulate --plant linear --signal doublet --step 2 --amplitude 0.25 --out doublet.npz --csv
  trms simulate --config 2dof --channel u2 --signal uniform --bandwidth 2 --out yaw.npz
  trms simulate --config 1dof --input volts.csv --out mine.npz        # one column per input, absolute V
""",
    "identify": """examples:
  trms identify prbs.npz --out ident
  trms identify prbs.npz --validate doublet.npz --orders 4 4 4 1 --out ident
  trms identify yaw.npz --input u2 --output yaw --out ident_yaw
""",
    "design": """examples:
  trms design --r 125 --out lqg.json
  trms design --r 75 --case "CSAS LPF 0.2 Hz" --out lqg75.json
  trms design --config 2dof --r 10 --out autopilot.json
""",
    "run": """examples:
  trms run --r 125 --case "CSAS LPF 0.2 Hz" --gusts --out run125
  trms run --plant linear --r 1 --case SAS --out run1
  trms run --r 125 --case SAS --duration 40 --amplitude 0 --push-impulse 0.02 --out push
  trms run --config 2dof --controller "MIMO LQG" --scenario "pitch square wave" --out autopilot
""",
    "render": """examples:
  trms render run125/record.npz --out run125/rig.gif --every 2
  trms render prbs.npz --out last.png --camera front
  trms render run125/record.npz --out run125/rig.mp4
""",
    "reproduce": """examples:
  trms reproduce                       # full report into ./report
  trms reproduce --quick --out /tmp/r  # reduced run, under a minute
""",
    "robustness": """examples:
  trms robustness --n 100 --out robustness               # 100 parameter samples on a local Dask cluster
  trms robustness --n 400 --workers 4 --spread 0.3 --out wide
  trms robustness --n 1000 --scheduler tcp://host:8786 --out big
  trms render robustness/worst_1_dof_csas_r_125_lpf_0_2_hz_1_sample17.npz --out worst.gif  # a worst case it wrote
""",
    "demo": """examples:
  trms demo --out out
  trms demo --config 1dof --duration 30 --amplitude 0.3 --seed 2 --out out/1dof
""",
}


def _sub(
    sub: argparse._SubParsersAction, name: str, help_: str, description: str, func: Callable[[argparse.Namespace], int]
) -> argparse.ArgumentParser:
    p = sub.add_parser(name, help=help_, description=description, epilog=_EPILOGS.get(name), formatter_class=_FMT)
    p.set_defaults(func=func)
    _debug_option(p)
    return p


def _debug_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--debug",
        action="store_true",
        default=argparse.SUPPRESS,
        help="on failure, show the Python traceback instead of the one-line message",
    )


def _parser() -> argparse.ArgumentParser:
    from trms.experiments.ch8_mimo_lqg import CONTROLLERS, SCENARIOS
    from trms.experiments.ch67_lqg import ALL_CASES

    parser = _Parser(
        prog="trms",
        description="TRMS digital twin: the thesis's experiments on the "
        "linear model and on the MuJoCo twin; simulate, identify, control, render.",
    )
    _debug_option(parser)
    from trms import __version__

    parser.add_argument("--version", action="version", version=f"trms {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = _sub(
        sub,
        "reproduce",
        "run every experiment and write the report (the main job)",
        "Run every experiment of the thesis on the linear model and on the twin and write a report folder: "
        "report.md and report.html (thesis | linear model | twin | notes), PNG figures, a GIF render, tables.json.",
        _reproduce,
    )
    p.add_argument("--out", default="report", help="report folder (default: ./report)")
    p.add_argument("--quick", action="store_true", help="reduced run (under a minute), every table still filled")
    p.add_argument("--seed", type=int, default=0, help="seed of everything random (default 0)")
    p.add_argument("--workers", type=int, default=2, help="worker processes (default 2)")

    p = _sub(
        sub,
        "simulate",
        "run a plant on an input signal or file -> Record",
        "Run the twin or the linear model open loop on a generated signal (around hover, on one input) or on "
        "inputs read from a file, and save the Record (.npz, optionally .csv).",
        _simulate,
    )
    _plant_options(p)
    p.add_argument(
        "--signal",
        default="prbs",
        choices=["prbs", "uniform", "3211", "doublet", "square", "hold"],
        help="generated signal, added to the hover trim of --channel (default prbs)",
    )
    p.add_argument("--input", metavar="FILE", help="inputs from a file instead (.csv/.txt, .npy, or a Record .npz)")
    p.add_argument(
        "--deviation", action="store_true", help="the --input file holds deviations from hover, not absolute V"
    )
    p.add_argument("--channel", default="u1", help="input the signal drives (default u1)")
    p.add_argument("--duration", type=float, default=60.0, help="s (default 60)")
    p.add_argument("--amplitude", type=float, default=0.1, help="V (default 0.1)")
    p.add_argument(
        "--bandwidth",
        type=float,
        default=2.0,
        help="clock of prbs (a random binary signal) and uniform in Hz (default 2)",
    )
    p.add_argument(
        "--step", type=float, default=2.0, help="unit step of the 3211 / pulse of the doublet in s (default 2)"
    )
    p.add_argument("--start", type=float, default=2.0, help="first edge of the 3211/doublet in s (default 2)")
    p.add_argument("--period", type=float, default=40.0, help="square-wave period in s (default 40)")
    p.add_argument("--gusts", action="store_true", help="gust torques on the twin")
    _cap_options(p, "V", MAX_AMPLITUDE_V)
    p.add_argument("--out", default="record.npz", help="Record file (default record.npz)")
    p.add_argument("--csv", action="store_true", help="also write a CSV beside it")

    p = _sub(
        sub,
        "identify",
        "fit an ARMAX model to a Record, with tests and plots",
        "Fit an ARMAX model by the prediction-error method to one channel of a Record (deviations from its "
        "operating point), run the residual tests, and write model.json and figures.",
        _identify,
    )
    p.add_argument("record", help="a Record file (.npz)")
    p.add_argument("--input", default=None, help="input channel (needed when the record has several)")
    p.add_argument("--output", default=None, help="output channel (needed when the record has several)")
    p.add_argument(
        "--orders",
        type=int,
        nargs=4,
        default=[4, 4, 4, 1],
        metavar=("NA", "NB", "NC", "NK"),
        help="ARMAX orders and delay (default 4 4 4 1, eq. 3.11's)",
    )
    p.add_argument("--validate", metavar="RECORD", help="a second Record for a free-run validation")
    p.add_argument("--out", default="identification", help="output folder (default ./identification)")

    p = _sub(
        sub,
        "design",
        "integral LQG gains, estimator and prefilter for given weights",
        "Design the integral LQG (current estimator, Qe = I, Re = 1) on the 1-DOF model eq. (3.11) or the 2-DOF "
        "reduced twin model, and write gains, poles and the prefilter as JSON.",
        _design,
    )
    p.add_argument("--config", default="1dof", choices=["1dof", "2dof"], help="design model (default 1dof: eq. 3.11)")
    p.add_argument("--q", type=float, default=1.0, help="Q = q I (default 1)")
    p.add_argument("--r", type=float, default=125.0, help="R = r I (default 125)")
    p.add_argument("--case", default="SAS", help="SAS or a CSAS prefilter, e.g. 'CSAS LPF 0.2 Hz' (default SAS)")
    p.add_argument("--out", default="lqg.json", help="JSON file (default lqg.json)")

    p = _sub(
        sub,
        "run",
        "a closed loop on the twin or the linear model",
        "Close the LQG around the twin or the linear model: 1-DOF SAS/CSAS designed on eq. (3.11) tracking a "
        "square wave, or the 2-DOF autopilot (MIMO LQG or two SISO loops). Writes the Record and a figure.",
        _run,
    )
    _plant_options(p, ("1dof", "2dof"))
    p.add_argument("--r", type=float, default=None, help="1dof: R (Q = I; default 125)")
    p.add_argument("--case", default="SAS", choices=list(ALL_CASES), help="1dof: SAS or CSAS prefilter")
    p.add_argument("--amplitude", type=float, default=0.2, help="1dof: square-wave amplitude in rad (default 0.2)")
    p.add_argument("--period", type=float, default=40.0, help="1dof: square-wave period in s (default 40)")
    p.add_argument("--duration", type=float, default=80.0, help="1dof: run length in s (default 80)")
    p.add_argument("--controller", default="MIMO LQG", choices=list(CONTROLLERS), help="2dof: controller")
    p.add_argument("--scenario", default="pitch square wave", choices=list(SCENARIOS), help="2dof: scenario")
    p.add_argument("--gusts", action="store_true", help="gust torques on the twin")
    p.add_argument("--push-impulse", type=float, default=0.0, help="push on the beam about pitch, N m s (twin)")
    p.add_argument("--push-time", type=float, default=19.0, help="push time in s (default 19)")
    _cap_options(p, "rad", MAX_AMPLITUDE_RAD)
    p.add_argument("--out", default="run", help="output folder (default ./run)")

    p = _sub(
        sub,
        "render",
        "render a twin Record to PNG, GIF or MP4",
        "Render a Record of the twin offscreen: the last frame as PNG, or every n-th sample as a GIF or MP4.",
        _render,
    )
    p.add_argument("record", help="a twin Record file (.npz) with its qpos channel")
    p.add_argument("--out", default="render.gif", help=".png (last frame), .gif or .mp4 (default render.gif)")
    p.add_argument(
        "--config", default=None, choices=["1dof", "2dof", "yaw"], help="configuration (default: the record's)"
    )
    p.add_argument("--camera", default="oblique", choices=["front", "oblique", "top"], help="camera (default oblique)")
    p.add_argument("--every", type=int, default=2, help="GIF: every n-th sample (default 2)")
    p.add_argument("--width", type=int, default=320, help="pixels (default 320)")
    p.add_argument("--height", type=int, default=240, help="pixels (default 240)")

    from trms.rigdata import add_csv_arguments

    p = _sub(
        sub,
        "import",
        "read a rig's CSV or MATLAB export into a Record",
        "Read a rig's export -- CSV/text or a MATLAB .mat file: a time column (s or ms), named voltage and angle "
        "columns, degrees or radians -- check it, take the operating point as the mean of a hover segment, and "
        "write a Record (.npz).",
        _import,
    )
    p.add_argument("csv", metavar="EXPORT", help="the rig's export: text (.csv, .txt, ...) or MATLAB (.mat)")
    add_csv_arguments(p)
    p.add_argument("--out", default="rig.npz", help="Record file (default rig.npz)")

    from trms import calibration

    p = sub.add_parser(
        "calibrate",
        help="fit the twin's physical parameters to the thesis's modes or your records",
        description="Fit the twin's named physical parameters so its spectra and identified model "
        "match the targets (default), or so it reproduces your rig's records in the "
        "time domain (--records), and write them into a new MJCF.",
        epilog=calibration.command.EPILOG,
        formatter_class=_FMT,
    )
    calibration.add_calibrate_arguments(p)
    p.set_defaults(func=calibration.run_calibrate)
    _debug_option(p)

    from trms.experiments import robustness_study

    p = sub.add_parser(
        "robustness",
        help="Monte Carlo of the closed loops under a parameter spread (Dask)",
        description="Run both robustness loops on N seeded parameter samples of the twin as Dask tasks "
        "and write the success rates and metric distributions (JSON), histograms (PNG) and "
        "the worst cases as Records that `trms render` replays.",
        epilog=_EPILOGS["robustness"],
        formatter_class=_FMT,
    )
    robustness_study.add_arguments(p)
    p.set_defaults(func=robustness_study.run_command)

    p = _sub(
        sub,
        "demo",
        "trim, excite around hover, write a record and renders",
        "Trim the twin at hover, excite it with a small PRBS around hover, and write the record (npz, csv) and "
        "renders (png, gif).",
        _demo,
    )
    p.add_argument("--out", default="out", help="output folder (default: out)")
    p.add_argument("--config", default="2dof", choices=["1dof", "2dof", "yaw"], help="rig configuration")
    p.add_argument("--sample-time", type=float, default=0.1, help="control sample time in s (default 0.1)")
    p.add_argument("--duration", type=float, default=60.0, help="simulated seconds (default 60)")
    p.add_argument(
        "--amplitude",
        type=float,
        default=DEMO_AMPLITUDE,
        help=f"PRBS amplitude around hover in V (default {DEMO_AMPLITUDE:g}: yaw within +-45 deg)",
    )
    p.add_argument("--bandwidth", type=float, default=2.0, help="PRBS bandwidth in Hz (default 2)")
    p.add_argument("--seed", type=int, default=0, help="seed of the excitation and the twin (default 0)")
    p.add_argument("--modes", type=int, default=4, help="how many modes to print, 1-100 (default 4)")
    _cap_options(p, "V", MAX_AMPLITUDE_V)
    return parser


@contextlib.contextmanager
def _quiet_mujoco() -> Iterator[None]:
    """Silence MuJoCo's printed warnings during a command: the twin checks every warning counter
    after each interval and raises (one line), so the printout would only add lines to stderr."""
    import mujoco

    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda message: None)
    try:
        yield
    finally:
        mujoco.set_mju_user_warning(previous)


def _one_line(command: str, exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or "(no message)"
    if isinstance(exc, TrmsError):
        return f"trms {command}: error: {text}"
    if isinstance(exc, OSError) and exc.errno in (errno.ENOSPC, errno.EDQUOT):
        where = f" writing {str(exc.filename)!r}" if exc.filename else ""
        return f"trms {command}: error: no space left on the device{where}; nothing was written, old files are kept"
    if isinstance(exc, (OSError, ValueError)):  # a file or a value the command could not use
        return f"trms {command}: error: {type(exc).__name__}: {text}"
    return f"trms {command}: internal error: {type(exc).__name__}: {text} (rerun with --debug for the traceback)"


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``trms`` command; returns the exit status.

    Every failure -- a refused argument, a bad file, a diverged simulation, an unexpected error --
    ends as one line on stderr and status 2; ``--debug`` prints the traceback too. Ctrl-C ends as one
    line and status 130. Python warnings
    of a successful command are printed after it, one line each.

    Examples
    --------
    >>> main(["design", "--q", "-1"])  # doctest: +SKIP
    2
    """
    argv = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in argv[: argv.index("--")] if "--" in argv else "--debug" in argv
    command = next((a for a in argv if not a.startswith("-")), "?")  # named in a Ctrl-C during the parse
    try:
        args = _parser().parse_args(argv)
        command = args.command
        with warnings.catch_warnings(record=True) as caught, _quiet_mujoco():
            warnings.simplefilter("always")
            status = int(args.func(args))
        for w in caught:
            print(f"trms {command}: warning: {' '.join(str(w.message).split())}", file=sys.stderr)
        sys.stdout.flush()
        return status
    except BrokenPipeError:
        # The reader of stdout went away (`trms ... | head -1`): stop quietly. Python would flush stdout
        # again at exit and complain, so point stdout at devnull first (the Python docs' SIGPIPE recipe).
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 1
    except _UsageError as exc:
        print(str(exc), file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        # Ctrl-C: one line and the shell's status for SIGINT (128 + 2); files are written atomically, so none is
        # left half-written, and the workers of a parallel run stop with the parent.
        print(f"trms {command}: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # noqa: BLE001 -- the one place every failure becomes one line
        if debug:
            traceback.print_exc()
        print(_one_line(command, exc), file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
