"""The time-domain calibration's HTML report: ``mujoco.sysid``'s report, self-contained, with the reported intervals.

``mujoco.sysid.default_report`` builds the sections (insights, parameters, control and
observation signals, parameter distribution, covariance, optimisation trace); two things
in it would contradict or fail the calibration, and are replaced here:

- its parameter distribution and covariance come from ``calculate_intervals``, the
  white-noise intervals; the calibration reports the sandwich or disturbance ones
  (:mod:`~trms.calibration.timedomain.intervals`), so both sections are rebuilt from the reported
  intervals and covariance, and the error bars, hover labels and caption name it as ``calibration.json``
  does (:data:`~trms.calibration.timedomain.intervals.INTERVAL_NAME`);
- its page loads plotly.js from a web address and a font from another, so a PC without a
  network sees empty plots: plotly.js is written into the page from the installed plotly
  package (:func:`self_contained`), and the web font is dropped (the page's own font
  fallbacks apply).

The page is written atomically (:func:`trms.files.atomic_write`).
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import numpy as np

from trms.calibration.timedomain.intervals import INTERVAL_NAME
from trms.files import atomic_write

__all__ = ["self_contained", "write_sysid_report"]

_REMOTE_SCRIPT = re.compile(r"<script\b[^>]*\bsrc\s*=\s*[\"']https?://[^\"']*[\"'][^>]*>\s*</script>", re.IGNORECASE)
_REMOTE_IMPORT = re.compile(r"@import\s+url\(\s*[\"']?https?://[^)]*\)\s*;?", re.IGNORECASE)
_PLOTLY = re.compile(r"plotly", re.IGNORECASE)


def self_contained(html: str) -> str:
    """``html`` with plotly.js inlined from the installed plotly package and no other remote resource.

    Every ``<script src="http(s)://...">`` that loads plotly becomes one inline script holding
    ``plotly.offline.get_plotlyjs()`` (once, where the first stood); a remote script of anything
    else is refused, and stylesheet ``@import``\\ s of web addresses (fonts) are dropped.

    Parameters
    ----------
    html : str
        A page.

    Returns
    -------
    str

    Raises
    ------
    ValueError
        The page loads a remote script other than plotly.js.

    Examples
    --------
    >>> page = self_contained('<head><script src="https://example.org/plotly-3.0.1.min.js"></script></head>')
    >>> "example.org" in page, page.startswith('<head><script type="text/javascript">/**')
    (False, True)
    """
    from plotly.offline import get_plotlyjs  # type: ignore[import-untyped]

    inline: list[str] = []

    def replace(match: re.Match[str]) -> str:
        if not _PLOTLY.search(match.group(0)):
            raise ValueError(f"the report loads a remote script other than plotly.js: {match.group(0)[:120]}")
        if inline:
            return ""
        inline.append(f'<script type="text/javascript">{get_plotlyjs()}</script>')
        return inline[0]

    return _REMOTE_IMPORT.sub("", _REMOTE_SCRIPT.sub(replace, html))


def _sandwich_distribution(base: Any) -> type:
    """``ParameterDistribution`` whose error bars, hover labels and caption name the reported interval."""

    class SandwichDistribution(base):
        def _build_figure(self) -> Any:
            fig = super()._build_figure()
            for trace in fig.data:
                template = trace.hovertemplate
                if template and " ±" in template and "<extra>" in template:
                    trace.hovertemplate = template.replace("<extra>", f" ({INTERVAL_NAME})<extra>", 1)
            return fig

        def get_context(self) -> dict[str, Any]:
            context: dict[str, Any] = super().get_context()
            context["caption"] = context["caption"].replace("95% Confidence Interval", INTERVAL_NAME)
            return context

    return SandwichDistribution


def write_sysid_report(
    folder: str | os.PathLike[str],
    sequences: Any,
    initial: Any,
    fitted: Any,
    residual_fn: Any,
    opt_result: Any,
    half_widths: np.ndarray,
    covariance: np.ndarray,
    *,
    title: str,
    build_model: Any,
) -> Path:
    """Write ``folder/report.html``: ``mujoco.sysid``'s report with the reported intervals, self-contained.

    Parameters
    ----------
    folder : path-like
        Created if needed.
    sequences : list of mujoco.sysid.ModelSequences
        The fitted records.
    initial, fitted : mujoco.sysid.ParameterDict
        The parameters before and after.
    residual_fn : callable
        ``mujoco.sysid.build_residual_fn``'s residual of the fitted records.
    opt_result : scipy.optimize.OptimizeResult
        ``x``, ``jac`` and ``extras`` (objective and candidate of each iteration), as
        ``mujoco.sysid.optimize`` returns it.
    half_widths : numpy.ndarray
        Half-widths of the reported 95 % intervals, one per parameter of ``fitted``
        (units of the parameters).
    covariance : numpy.ndarray
        Their covariance, ``(p, p)``.
    title : str
        The page's title.
    build_model : callable
        The calibration's ``BuildModelFn``.

    Returns
    -------
    pathlib.Path
        The page.

    Examples
    --------
    >>> write_sysid_report("cal/sysid", seqs, p0, p, fn, res, half, cov, title="t", build_model=b)  # doctest: +SKIP
    """
    from mujoco import sysid
    from mujoco.sysid.report.sections.covariance import Covariance
    from mujoco.sysid.report.sections.parameter_distribution import ParameterDistribution

    builder = sysid.default_report(
        sequences,
        initial,
        fitted,
        residual_fn,
        opt_result,
        title=title,
        save_path=None,
        build_model=build_model,
        generate_videos=False,
    )
    sections = builder._sections  # the library's own section list, two of which are rebuilt
    replaced = set()
    for i, section in enumerate(sections):
        if isinstance(section, ParameterDistribution):
            sections[i] = _sandwich_distribution(ParameterDistribution)(
                title=section.title,
                opt_params=fitted,
                initial_params=initial,
                confidence_intervals=np.asarray(half_widths, float),
                anchor=section.anchor,
            )
            replaced.add("distribution")
        elif isinstance(section, Covariance):
            sections[i] = Covariance(
                title=section.title, covariance=covariance, parameter_dict=fitted, anchor=section.anchor
            )
            replaced.add("covariance")
    if replaced != {"distribution", "covariance"}:
        raise RuntimeError("mujoco.sysid's report has no parameter distribution or covariance section to replace")
    html = self_contained(builder.build())
    return atomic_write(Path(folder) / "report.html", lambda fh: fh.write(html), binary=False)
