"""The ``trms`` command: argument parsing and printing only; the work lives in the package.

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
(:data:`~trms.cli.options.MAX_DURATION`, :data:`~trms.cli.options.MAX_AMPLITUDE_V`,
:data:`~trms.cli.options.MAX_AMPLITUDE_RAD`); ``--max-duration`` and ``--max-amplitude`` raise the caps.

One module per command (:mod:`trms.cli.simulate`, ...) holds its options (``add_arguments``) and its run
(``run``); :mod:`trms.cli.parser` builds the one parser from them and :mod:`trms.cli.main` runs it.
"""

from trms.cli.main import main
from trms.cli.options import DEMO_AMPLITUDE, MAX_AMPLITUDE_RAD, MAX_AMPLITUDE_V, MAX_DURATION

__all__ = ["main", "MAX_DURATION", "MAX_AMPLITUDE_V", "MAX_AMPLITUDE_RAD", "DEMO_AMPLITUDE"]
