"""The time-domain calibration's HTML report: readable offline, and showing the intervals calibration.json reports."""

import json
import re

import pytest

from trms.calibration.timedomain import calibrate_records
from trms.calibration.timedomain.intervals import INTERVAL_NAME
from trms.calibration.timedomain.report import self_contained
from trms.rig.faked import faked_rig_records

NAMES = ["main_motor_gain", "main_motor_lag"]


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    folder = tmp_path_factory.mktemp("sysid")
    _, recs = faked_rig_records("1dof", 0.25, 12.0, ("prbs", "prbs"), seed=3)
    result = calibrate_records(recs[:1], NAMES, held_out=recs[1:], report_dir=folder, max_iters=10)
    return result, (folder / "report.html").read_text()


def test_the_page_loads_nothing_from_the_web_and_carries_plotly_inline(report):
    result, html = report
    assert result.report_html and result.report_html.endswith("report.html")
    assert not re.search(r"<script\b[^>]*\bsrc\s*=\s*[\"']https?://", html, re.IGNORECASE)
    assert not re.search(r"@import\s+url\(\s*[\"']?https?://", html, re.IGNORECASE)
    assert len(html) > 1_000_000 and "plotly.js v" in html.lower()  # the library itself, not a link to it


def test_the_page_shows_the_intervals_of_calibration_json(report):
    result, html = report
    reported = json.loads(json.dumps(result.to_dict()))["parameters"]
    bars = [float(x) for x in re.findall(r'"error_y":\{"array":\[([^\]]+)\]', html)]
    assert bars == [pytest.approx(reported[n]["interval_95"], rel=1e-12) for n in NAMES]
    assert html.count(f"({INTERVAL_NAME})") >= len(NAMES)  # the hover labels name the reported interval
    assert "95% Confidence Interval" not in html  # not the library's white-noise caption


def test_a_remote_script_other_than_plotly_is_refused():
    with pytest.raises(ValueError, match="a remote script other than plotly.js"):
        self_contained('<script src="https://example.org/tracker.js"></script>')
