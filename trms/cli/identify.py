"""``trms identify``: a Record -> an ARMAX model (JSON), residual tests, spectra and validation figures."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from trms.files import atomic_write

__all__ = ["NAME", "HELP", "DESCRIPTION", "EPILOG", "add_arguments", "run"]

NAME = "identify"
HELP = "fit an ARMAX model to a Record, with tests and plots"
DESCRIPTION = (
    "Fit an ARMAX model by the prediction-error method to one channel of a Record (deviations from its "
    "operating point), run the residual tests, and write model.json and figures."
)
EPILOG = """examples:
  trms identify prbs.npz --out ident
  trms identify prbs.npz --validate doublet.npz --orders 4 4 4 1 --out ident
  trms identify yaw.npz --input u2 --output yaw --out ident_yaw
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
    p.add_argument("--validate", metavar="RECORD", help="a second Record for a free-run validation")
    p.add_argument("--out", default="identification", help="output folder (default ./identification)")


def run(args: argparse.Namespace) -> int:
    """Run ``trms identify``; return the exit status."""
    from trms.identification.armax_report import check_same_configuration, identify_armax
    from trms.modes import oscillatory, real_poles
    from trms.present.figures import plot_correlation_tests, plot_series, plot_spectra, save_figure
    from trms.rigdata import load_record

    rec = load_record(args.record)
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
