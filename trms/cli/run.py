"""``trms run``: a closed loop (SAS/CSAS, or the 2-DOF autopilot) on the twin or the linear model."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from trms.cli.options import MAX_AMPLITUDE_RAD, add_cap_options, add_plant_options, check_caps, plant_of
from trms.control.lqg import LQGDesign
from trms.control.metrics import StepMetrics
from trms.errors import InputError, check_in_range
from trms.experiments.ch8_mimo_lqg import SCENARIOS
from trms.experiments.ch67_lqg import ALL_CASES
from trms.experiments.single_runs import AUTOPILOT_CONTROLLERS

__all__ = ["NAME", "HELP", "DESCRIPTION", "EPILOG", "add_arguments", "run", "step_line", "autopilot_line"]

NAME = "run"
HELP = "a closed loop on the twin or the linear model"
DESCRIPTION = (
    "Close the LQG around the twin or the linear model: 1-DOF SAS/CSAS designed on eq. (3.11) tracking a "
    "square wave, or a 2-DOF controller of chapter 8 (the MIMO LQG autopilot, two SISO loops, MIMO MPC, "
    "H-infinity or PID; a `trms design --config 2dof` file with --design) in a pitch or yaw step, checked against "
    "the autopilot's targets. Writes the Record and a figure."
)
EPILOG = """examples:
  trms run --r 125 --case "CSAS LPF 0.2 Hz" --gusts --out run125
  trms run --plant linear --r 1 --case SAS --out run1
  trms run --r 125 --case SAS --duration 40 --amplitude 0 --push-impulse 0.02 --out push
  trms run --config 2dof --controller "MIMO LQG" --scenario "pitch step" --out autopilot
  trms run --config 2dof --controller "MIMO H-infinity" --scenario "yaw step" --out hinf
  trms design --config 2dof --out autopilot.json && trms run --config 2dof --design autopilot.json --out mine
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``trms run``."""
    add_plant_options(p, ("1dof", "2dof"))
    p.add_argument("--r", type=float, default=None, help="1dof: R (Q = I; default 125)")
    p.add_argument("--case", default="SAS", choices=list(ALL_CASES), help="1dof: SAS or CSAS prefilter")
    p.add_argument("--amplitude", type=float, default=0.2, help="1dof: square-wave amplitude in rad (default 0.2)")
    p.add_argument("--period", type=float, default=40.0, help="1dof: square-wave period in s (default 40)")
    p.add_argument("--duration", type=float, default=80.0, help="1dof: run length in s (default 80)")
    p.add_argument("--controller", default="MIMO LQG", choices=list(AUTOPILOT_CONTROLLERS), help="2dof: controller")
    p.add_argument("--scenario", default="pitch step", choices=list(SCENARIOS), help="2dof: scenario")
    p.add_argument("--design", default=None, help="2dof: a `trms design --config 2dof` JSON flown as the MIMO LQG")
    p.add_argument("--gusts", action="store_true", help="gust torques on the twin")
    p.add_argument(
        "--push-impulse",
        type=float,
        default=0.0,
        help="push on the beam about pitch, N m s (twin): positive raises the main rotor (pitch up), negative "
        "lowers it",
    )
    p.add_argument("--push-time", type=float, default=19.0, help="push time in s (default 19)")
    add_cap_options(p, "rad", MAX_AMPLITUDE_RAD)
    p.add_argument("--out", default="run", help="output folder (default ./run)")


def run(args: argparse.Namespace) -> int:
    """Run ``trms run``; return the exit status."""
    from trms.control.loop import deviation_limits
    from trms.control.plots import plot_closed_loop
    from trms.experiments.ch67_lqg import NARROW_BAND, WIDE_BAND
    from trms.experiments.single_runs import autopilot_loop, pitch_loop, plot_autopilot
    from trms.present.figures import save_figure

    check_caps(args, MAX_AMPLITUDE_RAD, " rad")
    if args.config != "1dof" and args.r is not None:
        raise InputError(
            f"--r {args.r:g} sets the 1-DOF loop's R; the {args.config} autopilot's controllers have their own "
            "weights (--controller), or take a design file (--design): leave --r out"
        )
    if args.config == "1dof" and args.design is not None:
        raise InputError("--design flies a 2-DOF design file; the 1-DOF loop takes --r and --case")
    design = None
    if args.design is not None:
        design = _design_file(Path(args.design))
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
    plant = plant_of(args, pushes=pushes)
    if args.config == "1dof":
        rec, steps, wide, status = pitch_loop(
            plant, r, args.case, args.amplitude, args.period, args.duration, args.seed
        )
        if status == "settled":
            status = f"settled within the {100 * WIDE_BAND:g} % band"
        title = f"{args.case}, Q = I, R = {r:g} ({args.plant})"
        lines = [step_line(m, w, NARROW_BAND, WIDE_BAND) for m, w in zip(steps, wide)]
        fig = plot_closed_loop(rec, title, deviation_limits(plant), output=0)
    else:
        from trms.experiments.ch8_mimo_lqg import meets_targets

        rec, tracked, m = autopilot_loop(plant, args.controller, args.scenario, args.seed, design)
        settled = np.isfinite(m["TS"])
        missed = meets_targets(args.scenario, m)
        status = (
            f"{'settled' if settled else 'not settled'} within the noise band ({rec.output_names[tracked]} tracked); "
            + ("every target met" if not missed else "targets missed: " + ", ".join(missed))
        )
        name = args.controller if design is None else f"{args.controller} ({Path(args.design).name})"
        title = f"{name}, {args.scenario} ({args.plant})"
        lines = [autopilot_line(m, rec.output_names[1 - tracked])]
        fig = plot_autopilot(rec, title, deviation_limits(plant))
    rec.metadata.update({"config": args.config, "world": args.plant})
    out.mkdir(parents=True, exist_ok=True)
    npz = rec.save(out / "record.npz")
    png = save_figure(fig, out / "response.png")
    print(f"{title}: {status}")
    if args.push_impulse:
        way = "raising the main rotor (pitch up)" if args.push_impulse > 0 else "lowering the main rotor (pitch down)"
        print(f"  push of {args.push_impulse:+g} N m s about pitch at {args.push_time:g} s, {way}")
    for ln in lines:
        print(ln)
    print(f"wrote {npz}\nwrote {png}")
    return 0


def _seconds(value: float, missing: str) -> str:
    return f"{value:.2f} s" if np.isfinite(value) else missing


def step_line(m: StepMetrics, wide: StepMetrics, narrow_band: float, wide_band: float) -> str:
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


def _design_file(path: Path) -> LQGDesign:
    """The MIMO LQG of a ``trms design --config 2dof`` file, or one line saying why not."""
    import json

    from trms.experiments.lqg_design import design_from_dict

    if not path.is_file():
        raise InputError(f"--design {str(path)!r} is not a file (write one with trms design --config 2dof)")
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"--design {str(path)!r} is not a trms design JSON: {exc!s:.80}") from None
    if not isinstance(data, dict) or data.get("config") != "2dof":
        raise InputError(f"--design {str(path)!r} is not a 2-DOF design (write one with trms design --config 2dof)")
    return design_from_dict(data)


def autopilot_line(m: dict[str, float], other: str) -> str:
    """The 2-DOF measures with their units; a step that never settled is said, not printed as nan."""
    return (
        f"  TR {_seconds(m['TR'], 'not reached')}, TS (noise band) {_seconds(m['TS'], 'not settled')}, "
        f"TS (5 %) {_seconds(m['TS 5 %'], 'not settled')}, "
        f"overshoot {m['overshoot']:.1f} %, {other} excursion {m['cross']:.3g} rad, "
        f"RMS u1 {m['rms u1']:.3g} V, RMS u2 {m['rms u2']:.3g} V, total variation of u {m['TV']:.3g} V"
    )
