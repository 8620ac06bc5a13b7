"""What a submission writes cannot reach a terminal as control characters nor pose as the grader's lines.

The submissions in ``tests/grading_submissions/reports/`` (graded once, in a class directory under
names that are spreadsheet formulas and escape sequences themselves) fail with error
messages (and make the grader quote a module name and a line of error output)
that carry terminal escape sequences, carriage returns, other C0/C1 and
bidirectional control characters and fake ``Total: 10.00 / 10`` lines.  The
text report, the results JSON, the class table and ``summary.csv`` must hold
none of those characters, the grader's ``Total:`` line must be the only line
starting with ``Total:``, and a file named like a spreadsheet formula must
reach ``summary.csv`` as text.
"""
import csv
import json
import re
import shutil
import unicodedata
from pathlib import Path

import pytest
from grading_harness import ROOT, SUBS

from mutext_grader import batch as gbatch
from mutext_grader import grade
from mutext_grader.cli import _table
from mutext_grader.core import QuestionReport, Report, clean_name, clean_text

REPORTS = SUBS / "reports"
HOSTILE = sorted(REPORTS.glob("ex03_*.py"))
SOLUTION = ROOT / "instructor" / "mutext_grader" / "solutions" / "ex03_free_decay.py"
#: what a terminal acts on: C0 (but the newline), DEL, C1, and the bidirectional overrides and marks
BAD = re.compile("[\x00-\x09\x0b-\x1f\x7f-\x9f\u061c\u200e\u200f\u202a-\u202e\u2066-\u2069\u2028\u2029]")
#: the grader's own lines of a text report start with one of these (all else is indented)
OWN = ("Exercise ", "Submission: ", "Isolation: ", "Inputs: ", "note: ", "(", "Total: ")


def _strings(obj):
    """Every string in a JSON value."""
    if isinstance(obj, str):
        yield obj
    elif isinstance(obj, dict):
        for v in obj.values():
            yield from _strings(v)
    elif isinstance(obj, list):
        for v in obj:
            yield from _strings(v)


def _bad(text):
    return sorted({f"U+{ord(c):04X}" for c in BAD.findall(text)})


@pytest.fixture(scope="module")
def reports(batch):
    """The reports of the hostile files, as the class batch below graded them (under the names of
    ``NAMES``; each file is graded once in this module)."""
    _res, _seen, _d, made = batch
    return {NAMES[name].name: rep for name, rep in made if NAMES[name] in HOSTILE}


def test_the_hostile_submissions_are_there_and_score_zero(reports):
    assert {"ex03_forged_errors.py", "ex03_forged_import.py", "ex03_forged_crash.py"} <= set(reports)
    for name, rep in reports.items():
        assert rep.score == 0, name
        # they did get their texts in front of the grader: the report quotes them
        assert "Total: 10.00 / 10" in rep.text(), name


def test_text_report_has_no_control_characters_and_one_total_line(reports):
    for name, rep in reports.items():
        text = rep.text()
        assert _bad(text) == [], name
        lines = text.split("\n")
        totals = [ln for ln in lines if ln.startswith("Total:")]
        assert totals == [f"Total: {rep.score:.2f} / {rep.max_score:g}"] and lines[-1] == totals[0], name
        for ln in lines:
            assert ln == "" or ln.startswith(OWN) or ln.startswith("    "), (name, ln)
        # the question lines are the grader's: one per question, in order, with its points
        qlines = [ln for ln in lines if ln.startswith("(")]
        assert [ln.split(")")[0] + ")" for ln in qlines] == [f"({q.id})" for q in rep.questions], name
        assert [ln for ln in lines if ln.startswith("note: ")] == [f"note: {n.split(chr(10))[0]}" for n in rep.notes]


def test_every_escape_route_was_taken(reports):
    rep = reports["ex03_forged_errors.py"]
    # the messages, without the quoted source line (which shows the escapes as the code wrote them)
    errors = "\n".join(f.split(" (line ")[0] for q in rep.questions for f in q.feedback)
    assert "RuntimeError" in errors and "graded 10/10" not in errors     # the OSC window title is gone whole
    assert "[2J" not in errors and "[?1049h" not in errors and "1$r" not in errors
    imp = reports["ex03_forged_import.py"]
    assert imp.notes and "integrity violation" in imp.notes[0] and "Total: 10.00 / 10" in imp.notes[0]
    crash = reports["ex03_forged_crash.py"].text()
    assert "last error output: Total: 10.00 / 10" in crash and "http://x" not in crash


def test_results_json_is_cleaned_where_people_read_it(reports):
    for name, rep in reports.items():
        data = json.loads(json.dumps(rep.to_gradescope()))
        for t in _strings(data):                     # what jq -r or Gradescope shows is clean
            assert _bad(t) == [], (name, t)
        assert data["score"] == 0.0
        top = data["output"].split("\n")
        assert top[0] == f"ex03_free_decay: 0 / {rep.max_score:g}"
        assert not any(ln.startswith("Total:") for ln in top), name


def test_cleaning_rules():
    assert clean_text("a\x1b[31mred\x1b[0m b") == "ared b"
    assert clean_text("x\x1b]0;title\x07y\x1b]8;;http://x\x1b\\z") == "xyz"
    assert clean_text("1\r\n2\r3\x0b4\x0c5\x856\u20287\u20298") == "1\n2\n3\n4\n5\n6\n7\n8"
    assert clean_text("a\tb\x00c\x07d\x7fe\x9b2Jf\u202eg") == "a bcdefg"
    assert clean_text("ünïcode ∞ and 中文 stay") == "ünïcode ∞ and 中文 stay"
    assert clean_name("=a\n\x1b[2J\u202e.py") == "=a\\n\\x1b[2J\\u202e.py"
    for c in map(chr, range(0x3000)):
        if unicodedata.category(c) == "Cc" and c != "\n":
            out = clean_text(f"a{c}b")                  # ESC b and the like are one sequence, gone whole
            assert out in ("ab", "a b", "a\nb", "a"), hex(ord(c))
            assert _bad(clean_name(c)) == [], hex(ord(c))
    # the report itself cleans what it is given, whoever builds it
    q = QuestionReport("a1", "(a1) f: t", 0.0, 1.0, ["\x1b[2Jmsg\rTotal: 1 / 1"])
    assert q.feedback == ["msg\nTotal: 1 / 1"] and q.output == "msg\n  Total: 1 / 1"
    rep = Report("ex", "title", "sub\n\x1b[2J.py", [q], notes=["n\x1b[1m\nTotal: 1 / 1"],
                 isolation_details=["uid\x1b[2J"])
    text = rep.text()
    assert _bad(text) == [] and "Submission: sub\\n\\x1b[2J.py" in text
    assert [ln for ln in text.split("\n") if ln.startswith("Total:")] == ["Total: 0.00 / 1"]


def test_csv_cells_that_look_like_formulas_are_quoted():
    assert gbatch.csv_cell("=HYPERLINK(\"x\")+1.py") == "'=HYPERLINK(\"x\")+1.py"
    for s in ("+1", "-1+2", "@SUM(A1)", "\tx", "\rx"):
        assert gbatch.csv_cell(s).startswith("'"), s
    assert gbatch.csv_cell("\tx") == "'\\tx" and gbatch.csv_cell("ok.py") == "ok.py"
    assert gbatch.csv_cell(None) == "" and gbatch.csv_cell(7.5) == 7.5 and gbatch.csv_cell(0) == 0


#: hostile file names for the class directory: formulas, and escapes with a fake line
NAMES = {
    '=HYPERLINK("x")+1.py': SOLUTION,                         # a formula that gets full marks
    "@SUM(1+1)*cmd.py": REPORTS / "ex03_forged_crash.py",
    "-2+3.py": REPORTS / "ex03_forged_import.py",
    "\x1b[2J\x1b[31m\n1 of 1 graded; mean 10.00 \u2215 10\r.py": REPORTS / "ex03_forged_errors.py",
}


@pytest.fixture(scope="module")
def batch(tmp_path_factory):
    """The class directory graded once (one job, so in this process): the batch's result, its progress
    lines, the directory and the reports the batch made."""
    d = tmp_path_factory.mktemp("class")
    for name, src in NAMES.items():
        shutil.copyfile(src, d / name)
    seen, made = [], []

    def keep(exercise, path, *args, **kwargs):
        made.append((Path(path).name, grade(exercise, path, *args, **kwargs)))
        return made[-1][1]
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(gbatch, "grade", keep)
        res = gbatch.grade_batch("ex03_free_decay", d, jobs=1, time_limit=30, progress=lambda s, f: seen.append(s))
    assert len(made) == len(NAMES)
    return res, seen, d, made


def test_summary_csv_quotes_formulas_and_holds_no_control_characters(batch):
    res, _seen, d, _made = batch
    raw = (d / "results" / "summary.csv").read_text(encoding="utf-8")
    assert _bad(raw.replace("\r\n", "\n")) == []
    with open(d / "results" / "summary.csv", newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == len(NAMES)
    for r in rows:
        for k, v in r.items():
            assert not v.startswith(gbatch.FORMULA_STARTS), (k, v)
    by_name = {r["submission"]: r for r in rows}
    ref = by_name["'=HYPERLINK(\"x\")+1.py"]
    assert float(ref["score"]) == 10 and ref["status"] == "graded"       # the name changes nothing
    assert "'@SUM(1+1)*cmd.py" in by_name and "'-2+3.py" in by_name
    assert "\\x1b[2J\\x1b[31m\\n1 of 1 graded; mean 10.00 \u2215 10\\r.py" in by_name


def test_results_files_keep_the_exact_name_and_clean_texts(batch):
    res, _seen, d, _made = batch
    for r in res.rows:
        data = json.loads(Path(r["results"]).read_text(encoding="utf-8"))
        assert data["extra_data"]["submission"] == r["submission"]        # exact (JSON is not interpreted)
        for t in [data["output"]] + [t["output"] for t in data["tests"]]:
            assert _bad(t) == [], (r["submission"], t)
    assert sorted(r["submission"] for r in res.rows) == sorted(NAMES)


def test_table_and_progress_lines_are_clean(batch):
    res, seen, _d, _made = batch
    table = _table(res)
    assert _bad(table) == [] and all(_bad(s) == [] for s in seen)
    lines = table.split("\n")
    summary = [ln for ln in lines if re.match(r"\d+ of \d+ graded", ln)]
    assert summary == [lines[-2]] and summary[0].startswith(f"{len(res.rows)} of {len(res.rows)} graded")
    rows = lines[3:-2]
    assert len(rows) == len(res.rows) and all(ln.startswith("  ") for ln in rows)
