"""What the tests of the ``trms`` commands share: running the command in a subprocess or in-process, and the
checks every failure passes (one line on stderr, status 2, nothing written)."""

import re
import subprocess
import sys

from trms.cli import main


def trms(*args, cwd):
    """The command in a subprocess, as a user runs it."""
    return subprocess.run([sys.executable, "-m", "trms.cli", *args], cwd=cwd, capture_output=True, text=True)


def run_main(argv, capsys):
    """``main(argv)`` in-process: (status, stderr lines); an escaped exception fails the test."""
    try:
        status = main(argv)
    except SystemExit as exc:  # --help and --version only
        status = exc.code
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    return status, err


def assert_clean(status, err, argv):
    assert status == 0 or (status == 2 and len(err) == 1), (argv, status, err)
    if status == 2:
        assert "Traceback" not in err[0] and err[0].startswith("trms"), (argv, err)


def known_failure(files, tmp_path, capsys, argv, match):
    """A refused command line over the odd record files: one line matching ``match``, nothing written."""
    argv = [a.format(d=files) for a in argv]
    if argv and argv[0] in ("simulate", "identify", "render", "design", "run", "demo"):
        argv += [
            "--out",
            str(tmp_path / ("o.npz" if argv[0] == "simulate" else "o.png" if argv[0] == "render" else "o")),
        ]
    status, err = run_main(argv, capsys)
    assert status == 2 and len(err) == 1, err
    assert re.search(match, err[0]), err[0]
    assert list(tmp_path.iterdir()) == []  # nothing written by a failed command


def bad_input(work, capsys, monkeypatch, args, message):
    """A bad argument or file in the folder of simulated records: status 2 and one line naming it."""
    (work / "two_columns.csv").write_text("1,2\n3,4\n")
    monkeypatch.chdir(work)
    try:
        code = main(list(args))
    except SystemExit as exc:  # argparse's own errors
        code = exc.code
    err = capsys.readouterr().err
    assert code == 2
    assert message in err
    # our errors are one line; argparse's last line is its one-line message after the usage
    assert err.strip().splitlines()[-1].startswith("trms") and message in err.strip().splitlines()[-1]


def refusal(odd, tmp_path, capsys, argv, match):
    """A value no rig gives, refused in one line that names it; nothing written."""
    argv = [a.format(d=odd, o=tmp_path) for a in argv]
    status, err = run_main(argv, capsys)
    assert status == 2 and len(err) == 1, err
    assert re.search(match, err[0]), err[0]
    assert list(tmp_path.iterdir()) == []  # nothing written


def angle_warning(odd, tmp_path, capsys, argv, warning):
    """Angles past the end stops: status 0 and one warning line (``warning`` None: no line at all)."""
    argv = [a.format(d=odd) for a in argv] + ["--out", str(tmp_path / ("o.npz" if argv[0] == "simulate" else "id"))]
    status, err = run_main(argv, capsys)
    assert status == 0, err
    if warning is None:
        assert err == []
    else:
        assert len(err) == 1 and err[0].startswith(f"trms {argv[0]}: warning: ") and re.search(warning, err[0]), err
