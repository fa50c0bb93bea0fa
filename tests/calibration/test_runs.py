"""The targets a calibration run uses: a mode table first, then a rig's records, else the thesis's."""

import json

from trms.calibration.runs import choose_targets
from trms.calibration.targets import Targets


def test_a_table_is_used_as_given_and_nothing_means_the_thesis(tmp_path):
    table = tmp_path / "modes.json"
    table.write_text(json.dumps({"peaks": [{"config": "1dof", "channel": "u1->pitch", "frequency_hz": 0.32}]}))
    mine = choose_targets(str(table))
    assert mine.source == str(table) and [p.frequency_hz for p in mine.peaks] == [0.32]
    assert choose_targets().source == Targets.thesis().source == "thesis"
    assert choose_targets(None, []).source == "thesis"
