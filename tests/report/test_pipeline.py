"""The quick report (:func:`trms.report.reproduce`, two worker processes) in a subprocess: every table complete and
finite, every file written, the headline's verdicts recomputed from its source tables."""

import json
import math
import re
import subprocess
import sys

import pytest
from PIL import Image

from trms.present.seeds import OverSeeds
from trms.reference import SOURCES, TABLE_4_2, TABLE_4_3, TABLE_5_1, TABLE_6_1
from trms.report import AGREES, DIFFERS, EXPLAINED, NOTHING, PARTLY, VERDICT, numeric_verdict

#: The quick report in a fresh interpreter, its progress lines on stdout.
RUN = "import sys; from trms.report import reproduce; reproduce(sys.argv[1], quick=True, workers=2, progress=print)"


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    res = subprocess.run([sys.executable, "-c", RUN, str(out)], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    return out, res.stdout, json.loads((out / "tables.json").read_text())


def _computed_cells(table):
    cols = [c for c in ("linear model", "twin") if c in table["columns"]]
    if not cols:
        cols = [c for c in table["columns"] if not c.startswith("thesis") and c != "notes"]
    idx = [table["columns"].index(c) for c in cols]
    cells = [row[i] for row in table["rows"] for i in idx]
    # a twin cell measured at several seeds: its median, and every seed's value
    return [v for c in cells for v in ([c["median"], *c["values"]] if isinstance(c, dict) else [c])]


def _cell(value):
    """A cell read back from the JSON: a twin cell over seeds as the report judged it."""
    if isinstance(value, dict):
        return OverSeeds(tuple(float(v) if v in ("nan", "inf") else v for v in value["values"]), tuple(value["seeds"]))
    return tuple(value) if isinstance(value, list) else value


def test_every_table_is_complete_and_finite(quick):
    _, _, data = quick
    assert data["missing"] == []
    assert len(data["tables"]) >= 12
    for table in data["tables"]:
        assert table["rows"], table["title"]
        for cell in _computed_cells(table):
            assert cell is not None and cell != "", table["title"]
            if isinstance(cell, float):
                assert math.isfinite(cell), table["title"]
            assert cell not in ("inf", "-inf"), table["title"]


#: Statuses a computed cell of a thesis table may hold instead of a number (each with a note giving its reason).
NAMED = ("settled", "not settled", "hit the stops", "diverged")


def _table(data, prefix):
    return next(t for t in data["tables"] if t["title"].startswith(prefix))


def test_thesis_table_cells_are_finite_numbers_or_named_statuses_with_a_reason(quick):
    _, _, data = quick
    for prefix in ("Table 4.2", "Table 4.3", "Table 5.1", "Table 6.1"):
        t = _table(data, prefix)
        notes = {n.split(":", 1)[0] for n in t["notes"] if n.startswith("note ")}
        for row in t["rows"]:
            thesis = row[t["columns"].index("thesis")]
            numeric = isinstance(thesis, (int, float, list)) or thesis == "-"
            for col in ("linear model", "twin"):
                cell = _cell(row[t["columns"].index(col)])
                values = cell.values if isinstance(cell, OverSeeds) else (cell,)
                for value in values:
                    if isinstance(value, (int, float)):
                        assert math.isfinite(value), (prefix, row)
                    elif not numeric:  # a pass/fail or ok/high row: a word, but never an empty or "nan" one
                        assert value not in ("", "nan", "inf", "-inf"), (prefix, row)
                    elif row[t["columns"].index("measure")] != "control" if "measure" in t["columns"] else True:
                        assert value in NAMED, (prefix, row)  # "nan", "not reached" or a word fails here
                        refs = re.findall(r"note \d+", row[-1])
                        assert refs and set(refs) <= notes, (prefix, row)
    assert set(data["statuses"]) == set(NAMED)


def test_every_cell_beyond_30_percent_carries_a_computed_note(quick):
    _, _, data = quick
    tables = [
        t
        for t in data["tables"]
        if {"thesis", "linear model", "twin"} <= set(t["columns"]) and not t["title"].startswith("Headline")
    ]  # the headline copies cells and points at their notes
    assert len(tables) >= 8
    for t in tables:
        prefix = t["title"]
        i = t["columns"].index("thesis")
        notes = {n.split(":", 1)[0]: n for n in t["notes"] if n.startswith("note ")}
        for row in t["rows"]:
            thesis = row[i]
            lo, hi = (thesis, thesis) if not isinstance(thesis, list) else thesis
            if isinstance(lo, bool) or not isinstance(lo, (int, float)) or not lo:
                continue
            for col in ("linear model", "twin"):
                cell = _cell(row[t["columns"].index(col)])
                values = cell.values if isinstance(cell, OverSeeds) else (cell,)
                if any(isinstance(v, (int, float)) and (v < 0.7 * lo or v > 1.3 * hi) for v in values):
                    refs = re.findall(r"note \d+", row[-1])
                    assert refs and all(r in notes for r in refs), (prefix, row)
                    assert all(re.search(r"\d", notes[r]) for r in refs)  # each backed by a computed number


def test_claimed_findings_hold(quick):
    _, _, data = quick
    t = _table(data, "Ch. 7 findings")
    twin = {row[0]: row[3] for row in t["rows"]}
    for finding in ("R = 1 SAS unstable on the rig", "R = 125 SAS best", "push rejected by all three controllers"):
        assert twin[finding] == "shown at 2 of 2 seeds", finding  # the quick run's two seeds
    margins = _table(data, "Stability margins")
    r1 = next(r for r in margins["rows"] if r[0] == 1.0 and r[1].startswith("linear"))
    assert r1[-1] == "unstable"  # eq. (3.11)'s R = 1 loop does not survive one sample of computation delay


def test_every_thesis_table_is_side_by_side(quick):
    _, _, data = quick
    for prefix in (
        "Headline",
        "Ch. 3, 1-DOF",
        "Table 3.1",
        "Table 4.2",
        "Table 4.3",
        "Table 5.1",
        "Table 6.1",
        "Ch. 7:",
        "Ch. 7.4",
        "Ch. 8 future work: 2-DOF",
        "Ch. 8 future work: a NARX-RBF",
        "Robustness",
    ):
        table = next(t for t in data["tables"] if t["title"].startswith(prefix))
        values = [c for c in table["columns"] if c not in (VERDICT, "source")]  # the headline adds its verdict
        assert values[-4:] == ["thesis", "linear model", "twin", "notes"], prefix
        if "source" in table["columns"]:  # where the thesis column's value comes from, said on every row
            i = table["columns"].index("source")
            assert {row[i] for row in table["rows"]} <= {*SOURCES, "-"}, prefix
    by_title = {t["title"].split(":")[0]: t for t in data["tables"]}
    thesis = lambda t: [row[t["columns"].index("thesis")] for row in t["rows"]]  # noqa: E731
    assert set(TABLE_4_2.values()) <= set(thesis(by_title["Table 4.2 (1-DOF)"]))
    assert set(TABLE_4_3.values()) <= set(thesis(by_title["Table 4.3 (2-DOF)"]))
    assert set(TABLE_5_1.values()) <= set(thesis(next(t for t in data["tables"] if t["title"].startswith("Table 5.1"))))
    t61 = next(t for t in data["tables"] if t["title"].startswith("Table 6.1"))
    assert {v[0] for v in TABLE_6_1.values()} <= {c for c in thesis(t61) if isinstance(c, float)}


def test_report_files_and_figures(quick):
    out, stdout, data = quick
    md = (out / "report.md").read_text()
    html = (out / "report.html").read_text()
    for t in data["tables"]:
        assert f"### {t['title']}" in md
    figures = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", md)
    assert len(figures) >= 20
    for rel in figures:
        assert (out / rel).is_file() and f'src="{rel}"' in html
    with Image.open(out / "figures" / "twin_csas_R125_lpf0p2.gif") as im:
        assert im.n_frames > 50
    assert re.search(r"wall time \d+\.\d s", md)
    assert f"| chapter | quantity | thesis | source | linear model | twin | {VERDICT} | notes |" in md
    assert re.search(r"^2dof: hover trim u1 = -?\d\.\d{3} V, u2 = -?\d\.\d{3} V; lowest modes", md, re.M)
    jobs = ["twin control", "twin identification", "robustness 0", "linear control", "linear identification"]
    jobs += ["twin control, seed 1000", "twin identification, seed 1000"]
    assert all(re.search(rf"^{job} done in \d+\.\d s$", stdout, re.M) for job in jobs), stdout
    assert data["mode"] == "quick (reduced)" and data["wall_time_s"] > 0


def test_the_headline_marks_agreement_from_the_cells_and_their_notes(quick):
    out, _, data = quick
    head = _table(data, "Headline")
    cols = head["columns"]
    assert cols[-2:] == [VERDICT, "notes"]
    by_title = {t["title"].split(":")[0]: t for t in data["tables"]}
    verdicts = {row[1]: row[cols.index(VERDICT)] for row in head["rows"]}
    # the quick run judges at its 2 seeds, Table 5.1 at its 20 NARX seeds
    known = {AGREES, EXPLAINED, PARTLY, DIFFERS, NOTHING, "inconclusive at 2 seeds", "inconclusive at 20 seeds"}
    assert set(verdicts.values()) <= known and AGREES in verdicts.values()
    for row in head["rows"]:  # a verdict recomputed from the source table's notes, for every row that cites them
        refs = re.findall(r"note \d+", row[-1])
        source = re.search(r"\((.+)\)$", row[-1])
        if not refs or not source:
            continue
        notes = [
            n
            for n in by_title[source.group(1)]["notes"]
            if n.split(":", 1)[0] in refs and ", linear model:" not in n.split(";")[0]
        ]
        thesis, twin = _cell(row[cols.index("thesis")]), _cell(row[cols.index("twin")])
        assert row[cols.index(VERDICT)] == numeric_verdict(thesis, twin, notes), row
    table_4_2 = verdicts["Table 4.2: LPF 0.1 Hz at 0.34 Hz (dB)"]
    assert table_4_2 == DIFFERS  # 7 dB printed; the twin reads the filter's own 30 dB, no checked floor explains it
    md = (out / "report.md").read_text()
    summary = next(line for line in md.splitlines() if line.startswith("**In short.** The twin agrees"))
    assert f"on {list(verdicts.values()).count(AGREES)} of its" in summary
    assert md.index(summary) < md.index('<a id="headline"></a>')


def _names_in_trms() -> set[str]:
    """Every function and class of the package, bare and as ``Class.method``: the names an explanation may cite."""
    import importlib
    import inspect
    import pkgutil

    import trms

    names: set[str] = set()
    for info in pkgutil.walk_packages(trms.__path__, "trms."):
        if info.name.startswith("trms.twin.render"):  # needs a display library
            continue
        module = importlib.import_module(info.name)
        for name, obj in vars(module).items():
            if inspect.isfunction(obj) or inspect.isclass(obj):
                names.add(name)
                if inspect.isclass(obj):
                    names.update(f"{name}.{m}" for m in vars(obj) if not m.startswith("__"))
    return names


def test_every_explanation_names_the_function_that_measured_it(quick):
    """An "explained" (or "explained in part") note or cell names, in the same text, the package's function that
    computed its measurement in this run; a verdict cell and a count of explanations are not explanations."""
    _, _, data = quick
    known = _names_in_trms()
    texts = [n for t in data["tables"] for n in t.get("notes", [])]
    texts += [str(c) for t in data["tables"] if not t["title"].startswith("Headline") for r in t["rows"] for c in r]
    claims = [x for x in texts if re.search(r"(?<!not )explained (by|in part)(?! a measurement of this run)", x)]
    assert claims  # the quick run prints some: the filter's gain bound, the findings' flights
    for text in claims:  # cited as the first word of a parenthesis: "(pci_flight: ...)", "(summarise)"
        cited = set(re.findall(r"\(([A-Za-z_][A-Za-z0-9_.]*)(?=[,:;)])", text))
        assert cited & known, text


def test_the_html_links_every_note_and_renders_inline_code(quick):
    out, _, _ = quick
    page = (out / "report.html").read_text()
    ids = set(re.findall(r'id="([^"]+)"', page))
    links = re.findall(r'href="#([^"]+)"', page)
    assert sum("-note-" in a for a in links) >= 10
    assert set(links) <= ids, sorted(set(links) - ids)  # every link lands
    text = re.sub(r"<[^>]+>", "", page)
    assert "`" not in text and "<code>trms calibrate</code>" in page
