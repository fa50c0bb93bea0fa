"""The calibration's progress bars: tqdm on a terminal, nothing at all in a pipe or a log."""

import io

from trms.calibration.calibrate import Progress


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def test_progress_is_silent_when_not_on_a_terminal():
    log = io.StringIO()
    p = Progress(enabled=True, stream=log)
    p.update("linear fit", 0.5, "10 evaluations")
    p.done("linear fit", "20 evaluations")
    assert log.getvalue() == ""


def test_progress_draws_one_bar_per_stage_on_a_terminal():
    term = _Terminal()
    p = Progress(enabled=True, stream=term)
    p.update("linear fit", 0.25, "5 evaluations")
    p.done("linear fit", "20 evaluations")
    p.update("verification", 0.0)
    p.close()
    text = term.getvalue()
    assert "[calibrate] linear fit" in text and "100.0%" in text and "20 evaluations" in text
    assert "[calibrate] verification" in text
    assert Progress(enabled=False, stream=_Terminal()).enabled is False
