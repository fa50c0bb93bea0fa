"""``trms calibrate``: fit the twin's physical parameters to the thesis's targets, or to your rig's records in the
time domain, and write them into a new MJCF.

Calibration never overwrites by surprise: the calibrated values go into a *new* MJCF (``--mjcf``, default
``<out>/trms.xml``, a copy of the starting model with the values written in, comments kept); the shipped
model is replaced only with ``--replace-shipped``. A target that is not met (spectral), or a parameter at a
bound or undetermined (time domain), makes the exit status 1 unless ``--accept-unmet`` is given. A time-domain
fit that failed -- the optimiser took no step, or the fit on the held-out records is below 0 % or worse than the
start's -- makes it 3 whatever the options, and no model is written; a start that no coarse search can free from
an end stop the records do not reach is refused (status 2, one line naming the axis, record and time).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from trms.cli.records import add_csv_arguments, load_records
from trms.errors import InputError
from trms.measurement.protocol import VERIFY_SEEDS
from trms.twin.model import DEFAULT_MODEL_PATH

__all__ = ["NAME", "HELP", "DESCRIPTION", "EPILOG", "add_arguments", "run"]

NAME = "calibrate"
HELP = "fit the twin's physical parameters to the thesis's modes or your records"
DESCRIPTION = (
    "Fit the twin's named physical parameters so its spectra and identified model "
    "match the targets (default), or so it reproduces your rig's records in the "
    "time domain (--records), and write them into a new MJCF."
)
EPILOG = """examples:
  trms calibrate                                  # thesis targets; writes ./calibration/trms.xml and the report
  trms calibrate --out /tmp/cal --no-write        # report only, no model written
  trms calibrate --targets my_modes.json          # your own mode table (JSON)
  trms calibrate --target-records run1.npz run2.npz   # spectral targets measured on your rig's records
  trms calibrate --records rig1.npz rig2.npz --held-out rig3.npz   # time domain (mujoco.sysid) on your records
  trms calibrate --records rig*.csv --time t --inputs Vmain --outputs pitch_deg --units deg --config 1dof
  trms calibrate --start-from my_rig.xml --mjcf my_rig_calibrated.xml
  trms calibrate --replace-shipped                # also write the values into the shipped trms/models/trms.xml

exit status: 0 all met, 1 something not met (0 with --accept-unmet), 2 bad input (or, time domain, no start
  that keeps off the end stops the records stay away from), 3 the time-domain fit failed: the optimiser took no
  step, or the held-out fit is below 0 % or worse than the start's (no model written; not overridable).

mode table format: {"peaks": [{"config": "1dof", "channel": "u1->pitch", "frequency_hz": 0.34,
  "tolerance_hz": 0.02}], "coherences": [{"config": "2dof", "channel": "u2->pitch", "level": "low",
  "threshold": 0.5}]}
"""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The options of ``trms calibrate``."""
    src = parser.add_mutually_exclusive_group()
    src.add_argument("--targets", metavar="JSON", help="a mode table (JSON) instead of the thesis's targets")
    src.add_argument(
        "--target-records",
        metavar="NPZ",
        nargs="+",
        help="spectral targets measured on Records of your rig (one protocol run each)",
    )
    src.add_argument(
        "--records",
        metavar="FILE",
        nargs="+",
        help="time-domain calibration (mujoco.sysid) on your rig's Records (.npz) or CSV exports",
    )
    parser.add_argument(
        "--held-out",
        metavar="FILE",
        nargs="+",
        default=[],
        help="time domain: records the fit never sees, for the fit before/after",
    )
    parser.add_argument(
        "--parameters",
        metavar="NAME",
        nargs="+",
        help="time domain: parameters to fit (default: those the configuration observes)",
    )
    parser.add_argument("--max-iters", type=int, default=30, help="time domain: most Gauss-Newton iterations")
    parser.add_argument(
        "--start-from",
        metavar="MJCF",
        default=str(DEFAULT_MODEL_PATH),
        help="MJCF to start from (default: the shipped model)",
    )
    parser.add_argument("--out", default="calibration", help="output folder (default: ./calibration)")
    parser.add_argument("--mjcf", metavar="PATH", help="calibrated MJCF to write (default: <out>/trms.xml)")
    parser.add_argument("--no-write", action="store_true", help="write no MJCF, only the report")
    parser.add_argument(
        "--replace-shipped",
        action="store_true",
        help="also write the calibrated values into the shipped trms/models/trms.xml",
    )
    parser.add_argument("--accept-unmet", action="store_true", help="exit 0 even if a target is not met")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.add_argument(
        "--workers", type=int, help="spectral stage: run the candidates on a local Dask cluster of N workers"
    )
    parser.add_argument(
        "--scheduler",
        metavar="URL",
        help="spectral stage: run the candidates on the Dask cluster at URL (e.g. tcp://host:8786)",
    )
    parser.add_argument(
        "--seeds",
        metavar="SEED",
        type=int,
        nargs="+",
        help=f"spectral stage: the verification's unseen seeds (default {VERIFY_SEEDS[0]}-{VERIFY_SEEDS[-1]})",
    )
    parser.add_argument(
        "--no-evidence",
        action="store_true",
        help="skip the measured side-peak and trade-off evidence in the report (the longest part of a calibration)",
    )
    add_csv_arguments(parser)


def _spectral(args: argparse.Namespace, spec) -> tuple[dict[str, float], list[str]]:
    from trms.calibration.elastic_modes import format_evidence
    from trms.calibration.report import format_table
    from trms.calibration.runs import choose_targets, spectral_run

    targets = choose_targets(args.targets, args.target_records)
    done = spectral_run(
        targets,
        spec,
        args.out,
        quiet=args.quiet,
        workers=args.workers,
        scheduler=args.scheduler,
        seeds=args.seeds,
        evidence=not args.no_evidence,
    )
    result = done.result
    print(format_table(result))
    if done.evidence is not None:
        print()
        print(format_evidence(done.evidence))
    print()
    for name, v in result.values.items():
        print(f"  {name:22s} {result.start[name]:10.5g} -> {v:10.5g}")
    t = result.timings
    print(
        f"calibration {done.seconds:.1f} s: linear fit {t['linear_fit']:.1f} s, ambient fit {t['ambient_fit']:.1f} s, "
        f"spectral fit {t['spectral_fit']:.1f} s, "
        f"verification {t['verification']:.1f} s ({result.passes} pass{'es' if result.passes != 1 else ''})"
    )
    if not result.converged:
        print(
            f"not converged: the spectral fit still moved the coupling in pass {result.passes}, the last allowed; "
            "the values are that pass's (calibrate again from them with --start-from)"
        )
    print(f"wrote {done.json} and {done.png}")
    # a target is unmet by the verification's rule (met at MET_FRACTION of its seeds), not by one seed's miss
    return result.values, list(result.unreachable)


def _time_domain(args: argparse.Namespace, spec) -> tuple[dict[str, float], list[str], list[str]]:
    from trms.calibration.runs import time_domain_run

    records = load_records(args.records, args)
    held = load_records(args.held_out, args) if args.held_out else []
    for path, rec in zip([*args.records, *args.held_out], [*records, *held]):
        start = float(rec.metadata.get("start_time", 0.0))
        print(
            f"{path}: operating point {rec.metadata.get('operating_point_source', 'of the record')}, "
            f"{len(rec)} samples at {rec.sample_time:g} s"
            + (
                f" from t = {start:g} s on its own clock (the times below are on it)"
                if abs(start) >= 0.5 * rec.sample_time
                else ""
            )
        )
    result, js = time_domain_run(
        records,
        spec,
        args.out,
        held_out=held,
        labels=args.records,
        held_out_labels=args.held_out,
        parameters=args.parameters,
        config=args.rig_config,
        max_iters=args.max_iters,
        quiet=args.quiet,
    )
    if result.start_check:
        print(f"start: {result.start_check}")
    print(result.table())
    for o in result.fit_before:
        print(
            f"fit of {o} on the {result.fit_on} records: "
            f"{', '.join(f'{b:.1f} % -> {a:.1f} %' for b, a in zip(result.fit_before[o], result.fit_after[o]))}"
        )
    print(
        f"optimisation {result.timings['optimisation']:.1f} s ({result.iterations} optimiser "
        f"iteration{'' if result.iterations == 1 else 's'}, "
        f"{result.evaluations} rollouts; {result.stopped or 'no termination line'}); "
        f"sandwich bandwidth {result.bandwidth} samples"
    )
    print(f"wrote {js} and {result.report_html}")
    return result.values, result.problems, result.failures


def _check_modes(args: argparse.Namespace) -> None:
    """Refuse an option of one calibration (time domain or spectral) given to the other: it would be ignored."""
    if args.records:
        given = [f for f, v in (("--workers", args.workers), ("--scheduler", args.scheduler)) if v is not None]
        if given:
            raise InputError(
                f"{' and '.join(given)} {'run' if len(given) > 1 else 'runs'} the spectral stage's candidates; "
                "--records calibrates in the time domain instead"
            )
        if args.seeds is not None:
            raise InputError(
                "--seeds sets the spectral calibration's verification; --records calibrates in the time domain"
            )
    else:
        given = [f for f, v in (("--held-out", args.held_out), ("--parameters", args.parameters)) if v]
        if given:
            raise InputError(
                f"{' and '.join(given)} {'belong' if len(given) > 1 else 'belongs'} to the time-domain calibration; "
                "give --records too"
            )


def run(args: argparse.Namespace) -> int:
    """Run ``trms calibrate``; return the exit status (0: all met or accepted, 1: something not met, 3: failed)."""
    from trms.calibration.model_file import check_destination, write_calibrated_model, write_new_model
    from trms.files import atomic_group
    from trms.twin.model import load_spec

    _check_modes(args)
    spec = load_spec(args.start_from)
    mjcf = args.mjcf or Path(args.out) / "trms.xml"
    if not args.no_write:
        check_destination(args.start_from, mjcf)
    failed: list[str] = []
    with atomic_group():  # the report's files appear together, or (Ctrl-C, a failure) none of them
        if args.records:
            values, unmet, failed = _time_domain(args, spec)
        else:
            values, unmet = _spectral(args, spec)
    for line in unmet:
        print(f"not met: {line}")
    if failed:
        for line in failed:
            print(f"failed: {line}")
        print(f"calibration failed: {failed[0]}", file=sys.stderr)
        print("the calibration failed: no model written, exit status 3")
        return 3
    if not args.no_write:
        path = write_new_model(values, args.start_from, mjcf)
        print(f"wrote the calibrated model {path}")
    if args.replace_shipped and (args.accept_unmet or not unmet):
        from trms.calibration.evidence import refresh_shipped

        write_calibrated_model(DEFAULT_MODEL_PATH, values)
        print(f"replaced the values in the shipped model {DEFAULT_MODEL_PATH}")
        print(f"measured it again: {refresh_shipped()}")
    elif args.replace_shipped:
        print("the shipped model is left as it was: a target is not met (--accept-unmet to replace it anyway)")
    if unmet and not args.accept_unmet:
        print(f"{len(unmet)} target(s) not met: exit status 1 (--accept-unmet to accept)")
        return 1
    return 0
