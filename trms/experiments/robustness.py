"""Robustness of the closed loops to the twin's physical parameters: a seeded Monte Carlo batch.

Sample ``i`` of a study seeded ``seed`` draws its numbers from its own
:func:`trms.batch.distributed.sample_seed` ``(seed, i)``: :data:`SPREAD_PARAMETERS`, each uniform
within +-:data:`SPREAD` of its shipped value, and the seed of its twin's noise and gusts. The
result of a sample is therefore the same however the study is split into tasks. Two loops run on
every sample, with the controllers designed once on the nominal models, as a rig's would be:

* 1-DOF CSAS, R = 125 with the 0.2 Hz low-pass prefilter (the thesis's best rig case), designed on
  eq. (3.11), square wave +-0.2 rad;
* the 2-DOF LQG autopilot of ch. 8 (pitch step, yaw held), designed on the nominal twin.

The samples run as Dask tasks (:func:`trms.batch.distributed.map_samples`), each a chunk of
samples closed in one batch (:func:`trms.batch.batch_closed_loop`, or the MJX batch with
``backend="mjx"``). A sample succeeds when the run neither diverges nor reaches the stops and its
last step settles within the 5 % band. The nominal linear model's value of each measure stands
beside the batch's success rate and spread (median and range over the successful samples).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cache, lru_cache
from typing import Any

import numpy as np

from trms.batch.distributed import DEFAULT_CHUNK, map_samples, sample_seed
from trms.errors import InputError, check_choice, check_in_range, check_seed
from trms.experiments.ch8_mimo_lqg import SCENARIOS, controllers, scenario_reference
from trms.experiments.ch67_lqg import WIDE_BAND, case_setup, judge
from trms.plant import Plant
from trms.present.sections import finite_or
from trms.present.tables import ComparisonTable, side_by_side
from trms.record import Record
from trms.worlds import design_model, make_plant

__all__ = [
    "SPREAD",
    "samples_of",
    "SPREAD_PARAMETERS",
    "LOOPS",
    "BACKENDS",
    "Sample",
    "sample_parameters",
    "draw_parameters",
    "loop_setup",
    "measure",
    "run_samples",
    "monte_carlo",
    "replay",
    "nominal",
    "table",
]

#: Largest relative half-width of the spread: a parameter stays positive (1 - spread > 0) with room to spare.
MAX_SPREAD = 0.9
#: Relative half-width of the uniform spread.
SPREAD = 0.2
#: Parameters spread (mass, stiffness, motor lags).
SPREAD_PARAMETERS = ("counterweight_mass", "beam_stiffness", "cable_stiffness", "main_motor_lag", "tail_motor_lag")
#: The 1-DOF loop of the batch: (R, case).
CASE_1DOF = (125.0, "CSAS LPF 0.2 Hz")
#: The 2-DOF loop's scenario.
SCENARIO_2DOF = "pitch step"
#: Loop name -> configuration.
LOOPS: dict[str, str] = {
    "1-DOF CSAS R = 125, LPF 0.2 Hz": "1dof",
    "2-DOF LQG autopilot, pitch step": "2dof",
}
#: Where the physics of a batch runs: MuJoCo on the CPU cores (rollout) or MJX (JAX, a GPU if present).
BACKENDS = ("cpu", "mjx")


@dataclass
class Sample:
    """One loop on one parameter sample: success, and its overshoot (%) and 5 % settling time (s)."""

    parameters: dict[str, float]
    status: str
    overshoot: float
    settling: float
    index: int = -1
    seed: int = 0

    @property
    def success(self) -> bool:
        """True when the run settled (see the module docstring)."""
        return self.status == "settled"


def sample_parameters(seed: int, index: int, spread: float = SPREAD) -> tuple[dict[str, float], int]:
    """Parameters of sample ``index`` (each uniform in ``[1 - spread, 1 + spread]`` times its shipped value)
    and the seed of its twin's noise and gusts.

    Examples
    --------
    >>> p, s = sample_parameters(0, 3)
    >>> sorted(p) == sorted(SPREAD_PARAMETERS) and (p, s) == sample_parameters(0, 3)
    True
    """
    check_in_range("spread", spread, 0.0, MAX_SPREAD)
    nominal_values = _nominal_parameters()
    params_ss, twin_ss = sample_seed(seed, index).spawn(2)
    factors = np.random.default_rng(params_ss).uniform(1.0 - spread, 1.0 + spread, size=len(SPREAD_PARAMETERS))
    params = {k: float(nominal_values[k] * f) for k, f in zip(SPREAD_PARAMETERS, factors)}
    return params, int(twin_ss.generate_state(1)[0])


def draw_parameters(n: int, seed: int = 0, spread: float = SPREAD) -> list[dict[str, float]]:
    """The parameter sets of samples ``0 .. n - 1`` (see :func:`sample_parameters`)."""
    return [sample_parameters(seed, i, spread)[0] for i in range(int(n))]


@lru_cache(maxsize=1)
def _nominal_parameters() -> dict[str, float]:
    from trms.twin import load_spec
    from trms.twin.parameters import read_parameters

    return read_parameters(load_spec(), SPREAD_PARAMETERS)


@cache
def _nominal_setup(name: str) -> tuple[Any, np.ndarray, Any, dict[str, object]]:
    """The loop on the nominal twin: the designs are made once, on the nominal models."""
    plant = make_plant("twin", LOOPS[name])
    if LOOPS[name] == "1dof":
        r, case = CASE_1DOF
        return case_setup(plant, r, case, model=design_model("1dof"))
    ctrl = controllers(design_model("2dof"))["MIMO LQG"]
    return ctrl, scenario_reference(SCENARIO_2DOF, plant.sample_time), None, {"scenario": SCENARIO_2DOF}


def loop_setup(name: str, plant: Plant) -> tuple[Any, np.ndarray, Any, dict[str, object]]:
    """Controller (the nominal design, with ``plant``'s actuator limits), reference, prefilter and metadata
    of loop ``name`` on ``plant``."""
    from trms.control.loop import deviation_limits
    from trms.control.lqg import LQGController

    check_choice("loop", name, tuple(LOOPS))
    ctrl, ref, prefilter, meta = _nominal_setup(name)
    return LQGController(ctrl.design, deviation_limits(plant)), ref, prefilter, dict(meta, loop_name=name)


def measure(name: str, record: Record | None) -> tuple[str, float, float]:
    """Status, worst overshoot (%) and worst 5 % settling time (s) of a run of loop ``name`` (None: diverged)."""
    from trms.control.metrics import square_wave_metrics

    if record is None:
        return "diverged", float("nan"), float("nan")
    tracked = 0 if LOOPS[name] == "1dof" else SCENARIOS[SCENARIO_2DOF][0]
    wide = square_wave_metrics(record, output=tracked, band=WIDE_BAND)
    steps = square_wave_metrics(record, output=tracked)
    return judge(record, wide), max(m.overshoot for m in steps), max(m.settling_time for m in wide)


def _batch(
    name: str, indices: Sequence[int], seed: int, spread: float, backend: str
) -> list[tuple[Record | None, dict, int]]:
    """Loop ``name`` on samples ``indices``, all closed in one batch; (record, parameters, twin seed) each."""
    drawn = [sample_parameters(seed, i, spread) for i in indices]
    spec = None
    if backend == "mjx":  # MJX steps no discrete integrator: the same model with implicitfast at a finer step
        from trms.batch.mjx import mjx_spec

        spec = mjx_spec()
    plants = [make_plant("twin", LOOPS[name], gusts=True, parameters=p, seed=s, spec=spec) for p, s in drawn]
    setups = [loop_setup(name, p) for p in plants]
    metas = [dict(s[3], config=LOOPS[name], sample=int(i), study_seed=int(seed)) for s, i in zip(setups, indices)]
    args = (plants, [s[0] for s in setups], setups[0][1])
    kwargs = dict(prefilters=[s[2] for s in setups], seeds=[s for _, s in drawn], metadata=metas)
    if backend == "mjx":
        from trms.batch.mjx import mjx_closed_loop

        result = mjx_closed_loop(*args, **kwargs)
    else:
        from trms.batch import batch_closed_loop

        result = batch_closed_loop(*args, threads=1, **kwargs)
    return [(rec, p, s) for rec, (p, s) in zip(result.records, drawn)]


def run_samples(
    indices: Sequence[int], seed: int = 0, spread: float = SPREAD, backend: str = "cpu"
) -> list[dict[str, Any]]:
    """Every loop of :data:`LOOPS` on samples ``indices`` of the study ``seed``: one Dask task's work.

    Returns
    -------
    list of dict
        Per sample: ``index``, ``seed`` (its twin's), ``parameters`` and, per loop, ``status``,
        ``overshoot`` (%) and ``settling`` (s).
    """
    check_choice("backend", backend, BACKENDS)
    out: list[dict[str, Any]] = [{"index": int(i), "loops": {}} for i in indices]
    for name in LOOPS:
        for row, (rec, params, twin_seed) in zip(out, _batch(name, indices, seed, spread, backend)):
            status, os_, ts = measure(name, rec)
            row.update(seed=twin_seed, parameters=params)
            row["loops"][name] = {"status": status, "overshoot": float(os_), "settling": float(ts)}
    return out


def monte_carlo(
    n: int,
    seed: int = 0,
    *,
    spread: float = SPREAD,
    backend: str = "cpu",
    workers: int | None = None,
    scheduler: str | None = None,
    processes: bool = True,
    chunk_size: int = DEFAULT_CHUNK,
    progress: bool | None = None,
) -> dict[str, list[Sample]]:
    """Run every loop of :data:`LOOPS` on ``n`` seeded parameter samples of the twin (with gusts), as Dask tasks.

    Parameters
    ----------
    n : int
        Samples.
    seed : int
        Seed of the study (every sample's parameters, noise and gusts; module docstring).
    spread : float
        Relative half-width of the uniform parameter spread.
    backend : {"cpu", "mjx"}
        Physics of each batch.
    workers, scheduler, processes, chunk_size, progress
        See :func:`trms.batch.distributed.map_samples` (default: one local worker process).

    Returns
    -------
    dict
        Loop name -> one :class:`Sample` per sample, in sample order; the same for any split of the work.

    Raises
    ------
    InputError
        A spread outside ``[0, MAX_SPREAD]``, a negative or non-integer seed, an unknown backend (before any
        worker starts).

    Examples
    --------
    >>> batch = monte_carlo(1, seed=0, processes=False, progress=False)  # doctest: +SKIP
    """
    # Checked here, before a cluster starts: a bad argument is one line, not a traceback from every worker.
    check_in_range("spread", spread, 0.0, MAX_SPREAD)
    check_seed("seed", seed, allow_none=False)
    check_choice("backend", backend, BACKENDS, error=InputError)
    rows = map_samples(
        run_samples,
        n,
        (int(seed), float(spread), backend),
        chunk_size=chunk_size,
        workers=workers,
        scheduler=scheduler,
        processes=processes,
        progress=progress,
        label="samples",
    )
    return samples_of(rows)


def samples_of(rows: Sequence[dict[str, Any]]) -> dict[str, list[Sample]]:
    """:func:`run_samples`' rows (of one or several calls, any order) as :func:`monte_carlo` returns them.

    Returns
    -------
    dict
        Loop name -> one :class:`Sample` per row, in sample-index order.

    Examples
    --------
    >>> row = {"index": 0, "seed": 7, "parameters": {}, "loops": {n: {"status": "ok", "overshoot": 1.0,
    ...        "settling": 2.0} for n in LOOPS}}
    >>> [s.status for s in samples_of([row])[next(iter(LOOPS))]]
    ['ok']
    """
    ordered = sorted(rows, key=lambda r: int(r["index"]))
    return {
        name: [
            Sample(
                r["parameters"],
                r["loops"][name]["status"],
                r["loops"][name]["overshoot"],
                r["loops"][name]["settling"],
                r["index"],
                r["seed"],
            )
            for r in ordered
        ]
        for name in LOOPS
    }


def replay(name: str, seed: int, index: int, spread: float = SPREAD) -> Record | None:
    """The Record of loop ``name`` on sample ``index`` of the study ``seed`` (None if it diverged): the same
    batch path as :func:`monte_carlo`, so the same bits."""
    check_choice("loop", name, tuple(LOOPS))
    return _batch(name, [int(index)], int(seed), float(spread), "cpu")[0][0]


def nominal(world: str = "linear", seed: int = 0) -> dict[str, tuple[str, float, float]]:
    """Every loop of :data:`LOOPS` on the nominal plant of ``world`` (no spread)."""
    from trms.control.loop import closed_loop
    from trms.errors import DivergenceError

    out = {}
    for name, config in LOOPS.items():
        plant = make_plant(world, config)
        ctrl, ref, prefilter, meta = loop_setup(name, plant)
        try:
            record: Record | None = closed_loop(plant, ctrl, ref, prefilter=prefilter, seed=seed, metadata=meta)
        except DivergenceError:
            record = None
        out[name] = measure(name, record)
    return out


def _spread(values: list[float]) -> str:
    v = np.asarray([x for x in values if np.isfinite(x)])
    if v.size == 0:
        return "none settled"
    return f"{np.median(v):.3g} [{v.min():.3g}, {v.max():.3g}]"


def table(
    batch: Mapping[str, list[Sample]], linear: Mapping[str, tuple[str, float, float]], seed: int = 0
) -> ComparisonTable:
    """The batch beside the nominal linear model: success rate, overshoot and settling spreads."""
    n = len(next(iter(batch.values()))) if batch else 0
    t = side_by_side(
        f"Robustness: twin parameters spread +-{SPREAD:.0%} (uniform, seed {seed}), {n} samples", ["loop", "measure"]
    )
    for name, samples in batch.items():
        ok = [s for s in samples if s.success]
        status, os_, ts = linear[name]
        t.rows.append(
            [
                name,
                "success rate",
                "-",
                f"nominal: {status}",
                f"{len(ok)}/{len(samples)}",
                "settled within 5 %, no stops, no divergence",
            ]
        )
        t.rows.append(
            [
                name,
                "overshoot (%): median [min, max]",
                "-",
                finite_or(os_),
                _spread([s.overshoot for s in ok]),
                "over the successful samples",
            ]
        )
        t.rows.append(
            [
                name,
                "settling time, 5 % (s): median [min, max]",
                "-",
                finite_or(ts),
                _spread([s.settling for s in ok]),
                "over the successful samples",
            ]
        )
    t.notes = [
        f"Spread parameters: {', '.join(SPREAD_PARAMETERS)}; controllers designed once on the nominal models "
        "(eq. 3.11 for 1-DOF, the nominal twin's reduced linearisation for 2-DOF); each twin runs with gusts "
        "and measurement noise."
    ]
    return t
