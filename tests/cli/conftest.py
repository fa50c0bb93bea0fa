"""Record files the command tests share: simulated twin records, broken and odd files."""

import io
import json
import zipfile
from pathlib import Path

import numpy as np
import pytest

from trms.plant import LinearPlant, simulate
from trms.record import OperatingPoint, Record

from ._helpers import trms


@pytest.fixture(scope="session")
def work(tmp_path_factory):
    """A folder with a simulated PRBS and a doublet record of the 1-DOF twin (made once per test process: the tests
    only read its records and write files of their own names beside them)."""
    d = tmp_path_factory.mktemp("cli")
    for args in (
        ("--signal", "prbs", "--out", "prbs.npz"),
        ("--signal", "doublet", "--duration", "30", "--out", "doublet.npz", "--csv"),
    ):
        res = trms("simulate", "--config", "1dof", *args, cwd=d)
        assert res.returncode == 0, res.stderr
    return d


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Good, odd and broken record files."""
    d = tmp_path_factory.mktemp("bad")
    import control

    from trms.twin import Twin

    nq = Twin("1dof").model.nq
    lin = LinearPlant(
        control.ss([[0.9]], [[1.0]], [[1.0]], [[0.0]], dt=0.2),
        input_names=("u1",),
        output_names=("pitch",),
        noise_std=0.01,
    )
    u = np.random.default_rng(0).choice([-1.0, 1.0], size=200)
    rec = simulate(lin, u, seed=0, metadata={"config": "1dof"})
    rec.save(d / "one.npz")
    lin2 = LinearPlant(
        control.ss(0.9 * np.eye(2), np.eye(2), np.eye(2), np.zeros((2, 2)), dt=0.2),
        input_names=("u1", "u2"),
        output_names=("pitch", "yaw"),
        noise_std=0.01,
    )
    simulate(lin2, np.random.default_rng(1).choice([-1.0, 1.0], size=(200, 2)), metadata={"config": "2dof"}).save(
        d / "two.npz"
    )
    raw = (d / "one.npz").read_bytes()
    (d / "trunc.npz").write_bytes(raw[: len(raw) // 3])
    (d / "empty.npz").write_bytes(b"")
    with zipfile.ZipFile(d / "listhdr.npz", "w") as z:
        buf = io.BytesIO()
        np.save(buf, np.array(json.dumps([1, 2, 3])))
        z.writestr("header.npy", buf.getvalue())
    Record(
        np.zeros(0),
        np.zeros((0, 1)),
        np.zeros((0, 1)),
        ("u1",),
        ("pitch",),
        {"qpos": np.zeros((0, nq))},
        {"config": "1dof", "sample_time": 0.2},
    ).save(d / "zero.npz")
    Record(
        rec.time,
        rec.inputs,
        rec.outputs,
        rec.input_names,
        rec.output_names,
        {"qpos": np.zeros((200, nq))},
        {"config": "1dof", "sample_time": 0.0},
    ).save(d / "ts0.npz")
    np.save(d / "complex.npy", np.linspace(0, 1, 10) + 0.5j)
    np.save(d / "text.npy", np.array(["1.5", "2.5"]))
    return d


@pytest.fixture(scope="module")
def odd(tmp_path_factory):
    """Records a rig never gives (all NaN, angles 1000 times the stops), a short one, odd input files."""
    d = tmp_path_factory.mktemp("odd")
    t = np.arange(300) * 0.2
    u = np.random.default_rng(4).choice([-0.5, 0.5], size=300)
    y = np.convolve(u, 0.9 ** np.arange(40))[:300] * 0.05  # a small, identifiable response (rad)
    meta = {"config": "1dof", "sample_time": 0.2, "operating_point": OperatingPoint.zero(["u1"], ["pitch"]).to_dict()}
    Record(t, u, y, ("u1",), ("pitch",), {}, meta).save(d / "good.npz")
    Record(t, u, 1000.0 * y, ("u1",), ("pitch",), {}, meta).save(d / "far.npz")
    Record(t, u, np.full(300, np.nan), ("u1",), ("pitch",), {}, meta).save(d / "nan.npz")
    Record(t[:50], u[:50], y[:50], ("u1",), ("pitch",), {}, meta).save(d / "short.npz")
    (d / "garbage.csv").write_bytes(bytes(range(256)) * 4)
    np.save(d / "objects.npy", np.array([{"a": 1}, None], dtype=object), allow_pickle=True)
    (d / "folder").mkdir()
    (d / "megavolts.csv").write_text("u1\n" + "\n".join(["0.5", "1e6", "0.5"] * 10))
    return d


@pytest.fixture
def figures(monkeypatch):
    """The figures the command saves, by file name (they are still written)."""
    import trms.present.figures as figs

    saved, original = {}, figs.save_figure

    def keep(fig, path, *args, **kwargs):
        saved[Path(path).name] = fig
        return original(fig, path, *args, **kwargs)

    monkeypatch.setattr(figs, "save_figure", keep)
    return saved
