"""``trms identify``: a Record -> an ARMAX model of one channel, or with ``--method`` one model of all its inputs and
outputs (MIMO ARX/ARMAX, n4sid, ssest): JSON, residual tests, spectra and validation figures."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import TYPE_CHECKING

from trms.errors import InputError
from trms.files import atomic_write
from trms.identification.mimo_report import MIMO_METHODS

if TYPE_CHECKING:
    from trms.record import Record

__all__ = ["NAME", "HELP", "DESCRIPTION", "EPILOG", "add_arguments", "run"]

NAME = "identify"
HELP = "fit an ARMAX model (or a MIMO model: --method) to a Record, with tests and plots"
DESCRIPTION = (
    "Fit an ARMAX model by the prediction-error method to one channel of a Record (deviations from its "
    "operating point), run the residual tests, and write model.json and figures. On a record of several inputs "
    "(the 2-DOF rig, where the main rotor drives yaw too) --method fits one model of every input and output at "
    "once: MIMO ARX (least squares), MIMO ARMAX (prediction error), n4sid (subspace) or ssest (prediction-error "
    "state space)."
)
EPILOG = """examples:
  trms identify prbs.npz --out ident
  trms identify prbs.npz --validate doublet.npz --orders 4 4 4 1 --out ident
  trms identify yaw.npz --input u2 --output yaw --out ident_yaw
  trms identify rig2dof.npz --method armax-mimo --orders 4 4 1 1 --validate rig2dof_b.npz --out ident_2dof
  trms identify rig2dof.npz --method ssest --states 6 --out ident_ss
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The options of ``trms identify``."""
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
    p.add_argument(
        "--method",
        default="armax",
        choices=["armax", *MIMO_METHODS],
        help="armax: one channel (default); the others fit every input and output at once",
    )
    p.add_argument("--states", type=int, help="n4sid, ssest: states (default: n4sid's choice from its singular values)")
    p.add_argument("--validate", metavar="RECORD", help="a second Record for a free-run validation")
    p.add_argument("--out", default="identification", help="output folder (default ./identification)")


def run(args: argparse.Namespace) -> int:
    """Run ``trms identify``; return the exit status."""
    from trms.identification.armax_report import check_same_configuration, identify_armax
    from trms.modes import oscillatory, real_poles
    from trms.present.figures import plot_correlation_tests, plot_series, plot_spectra, save_figure
    from trms.rigdata import load_record

    rec = load_record(args.record)
    if args.method != "armax":
        return _all_channels(args, rec)
    if args.states is not None:
        raise InputError(f"--states {args.states} sets the order of n4sid and ssest; ARMAX takes --orders")
    if len(rec.input_names) > 1 and args.input is None:
        raise InputError(
            f"the record has {len(rec.input_names)} inputs ({', '.join(rec.input_names)}): name the one ARMAX fits "
            f"with --input, or fit every input and output at once with --method {' | '.join(MIMO_METHODS)}"
        )
    ident = identify_armax(rec, args.orders, args.input, args.output)
    val = None
    if args.validate:
        val = load_record(args.validate)
        check_same_configuration(rec, val, args.record, args.validate)
        ident = ident.validated(val)
    summary = ident.to_dict()
    d, model, tests, f, c = ident.data, ident.model, ident.tests, ident.frequency, ident.validation
    # Every number is computed: only now are files written.
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    files = [
        save_figure(
            plot_correlation_tests(tests, f"{d.input_name} -> {d.output_name}: residual tests"), out / "residuals.png"
        ),
        save_figure(
            plot_spectra(
                {"measured": (f, ident.measured_psd), "model": (f, ident.model_psd)},
                "Output PSD, measured and model",
                (),
                {"measured": ident.peaks},
                fmax=ident.band[1],
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
    na, nb, nc, nk = args.orders
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


def _all_channels(args: argparse.Namespace, rec: Record) -> int:
    """``--method`` other than armax: one model of every input and output (:mod:`trms.identification.mimo_report`)."""
    from trms.identification.armax_report import check_same_configuration
    from trms.identification.mimo_report import identify_all_channels
    from trms.identification.polynomial import modes_of_poles
    from trms.modes import oscillatory
    from trms.present.figures import plot_correlation_tests, plot_series, save_figure
    from trms.rigdata import load_record

    if args.input is not None or args.output is not None:
        raise InputError(f"--input and --output pick one channel for ARMAX; --method {args.method} fits all of them")
    fit = identify_all_channels(rec, args.method, args.orders, args.states)
    if args.validate:
        val = load_record(args.validate)
        check_same_configuration(rec, val, args.record, args.validate)
        fit = fit.validated(val)
    summary = fit.to_dict()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    files = []
    for j, name in enumerate(fit.output_names):
        tests = [t for label, t in fit.tests if label.startswith(f"{name}: ")]
        title = f"{name}: residual tests of the {args.method} model ({', '.join(fit.input_names)} -> outputs)"
        files.append(save_figure(plot_correlation_tests(tests, title), out / f"residuals_{name}.png"))
        if fit.validation is not None and fit.validation_fit is not None:
            time, measured, simulated = fit.validation
            series = {"measured": measured[:, j], f"model (fit {fit.validation_fit[j]:.1f} %)": simulated[:, j]}
            ylabel = f"{name}, deviation from the operating point (rad)"
            figure = plot_series(time, series, f"Free-run validation, {args.method}", ylabel)
            files.append(save_figure(figure, out / f"validation_{name}.png"))
    js = atomic_write(out / "model.json", lambda fh: fh.write(json.dumps(summary, indent=1)), binary=False)
    ss = fit.state_space
    print(
        f"{args.method} {', '.join(fit.input_names)} -> {', '.join(fit.output_names)} on {len(rec)} samples: "
        f"{ss.nstates} states; estimation fit "
        + ", ".join(f"{n} {f:.1f} %" for n, f in zip(fit.output_names, fit.estimation_fit))
    )
    for m in oscillatory(modes_of_poles(ss.poles(), fit.sample_time), fit.sample_time):
        print(f"  mode {m.frequency_hz:.4f} Hz, damping {m.damping:.3f}")
    print("  residual tests: " + ", ".join(f"{label} {'pass' if t.passed else 'fail'}" for label, t in fit.tests))
    if fit.validation_fit is not None:
        print("  validation fit " + ", ".join(f"{n} {f:.1f} %" for n, f in zip(fit.output_names, fit.validation_fit)))
    for path in (js, *files):
        print(f"wrote {path}")
    return 0
