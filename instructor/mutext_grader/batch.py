"""A class at once: ``mutext grade EXERCISE DIR --jobs N`` grades every submission in a directory.

:func:`grade_batch` grades each ``*.py`` file directly in ``DIR`` exactly as
``mutext grade EXERCISE FILE`` does (:func:`mutext_grader.grade`: its own
confined child process, the same time limits and integrity policy), writes
the Gradescope ``results.json`` of each submission as ``OUT/<name>.json`` and
a class summary ``OUT/summary.csv`` (one row per submission: status, score
per question, total, integrity notes, other problems, isolation), ``OUT``
being ``DIR/results`` unless given.  A submission that could not be graded at
all (e.g. the child could not be confined) is a row with status ``error``
and the reason; the batch goes on.

What a submission controls (its file name, its error messages) reaches
``summary.csv`` and the table cleaned: no terminal control characters
(:func:`mutext_grader.core.clean_text`, :func:`~mutext_grader.core.clean_name`),
and a text cell that a spreadsheet would take for a formula (starting with
``=``, ``+``, ``-``, ``@``, a tab or a carriage return) starts with a single
quote (:func:`csv_cell`).  The results files keep the file name exactly
(``extra_data.submission``; JSON is not interpreted).

Parallel grading goes through the batch engine of :mod:`mutext.batch`
(joblib; ``jobs`` workers, each starting one confined child at a time).
Running several children at once must not give a submission a way at
another one: the first submission is graded alone, and the others run
concurrently only if its child was kept apart from everything outside it
by the kernel, which includes the children of the other submissions --
isolation ``uid`` or ``landlock`` with Landlock signal scoping (ABI 6, Linux
6.12 or newer; without it two children running as the same user could
signal each other).  Otherwise the batch grades one submission at a time
and says why.
"""
from __future__ import annotations

import csv
import json
import os
import re
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .core import GradingError, clean_name, clean_text, get_exercise, grade

__all__ = [
    "SUMMARY_HEAD",
    "SUMMARY_TAIL",
    "BatchGrades",
    "concurrency_problem",
    "csv_cell",
    "find_submissions",
    "grade_batch",
]

#: First and last columns of ``summary.csv``; one column per question (its id) in between.
SUMMARY_HEAD = ("submission", "status", "score", "max_score")
SUMMARY_TAIL = ("integrity", "problems", "isolation", "seconds", "results", "error")

#: Landlock ABI from which a confined child cannot signal processes outside its own domain.
SIGNAL_SCOPE_ABI = 6


@dataclass
class BatchGrades:
    """What :func:`grade_batch` did: one row per submission and where it wrote them."""
    exercise: str
    directory: Path
    out_dir: Path
    questions: list              # (id, points)
    rows: list
    jobs: int                    # workers used after the first submission
    notes: list = field(default_factory=list)

    @property
    def summary(self) -> Path:
        return self.out_dir / "summary.csv"

    @property
    def fields(self) -> list:
        return list(SUMMARY_HEAD) + [qid for qid, _ in self.questions] + list(SUMMARY_TAIL)

    @property
    def failed(self) -> list:
        """Rows of the submissions that could not be graded (status ``error``)."""
        return [r for r in self.rows if r["status"] != "graded"]


def find_submissions(directory) -> list[Path]:
    """The ``*.py`` files directly in ``directory`` (sorted by name; hidden files left out)."""
    d = Path(directory)
    if not d.is_dir():
        raise GradingError(f"'{directory}' is not a directory of submissions")
    return sorted(p for p in d.iterdir() if p.suffix == ".py" and not p.name.startswith(".")
                  and (p.is_file() or p.is_symlink()))


def concurrency_problem(isolation: str, details) -> str | None:
    """Why children of different submissions could reach each other if run at once, or None if they cannot.

    ``isolation`` and ``details`` are a report's :attr:`~mutext_grader.core.Report.isolation` and
    :attr:`~mutext_grader.core.Report.isolation_details`."""
    if isolation not in ("uid", "landlock"):
        return (f"the submissions' processes are not isolated here (isolation: {isolation}); one running "
                f"beside another could read or stop it")
    abi = 0
    for d in details or ():
        m = re.match(r"landlock \(ABI (\d+)\)", str(d))
        if m:
            abi = max(abi, int(m.group(1)))
    if abi < SIGNAL_SCOPE_ABI:
        what = f"Landlock ABI {abi}" if abi else "no Landlock"
        return (f"{what}: Landlock signal scoping (ABI {SIGNAL_SCOPE_ABI}, Linux 6.12 or newer) is needed so that "
                f"two submissions' processes running at once, as the same user, cannot signal each other")
    return None


def _clip(text, n=300) -> str:
    """One line of at most ``n`` characters, without control characters."""
    text = " ".join(clean_text(text).split())
    return text if len(text) <= n else text[:n - 3] + "..."


def _integrity_and_problems(report) -> tuple[str, str]:
    """The integrity violations of a report, and the other reasons questions scored 0 without an answer."""
    integrity = list(report.notes)
    if not integrity:
        integrity = [f"({q.id}) {q.feedback[0]}" for q in report.questions
                     if q.status == "violation" and q.feedback]
    bad = [q for q in report.questions if q.status not in ("ok", "violation")]
    firsts = {q.feedback[0] if q.feedback else q.status for q in bad}
    if bad and len(bad) == len(report.questions) and len(firsts) == 1:
        problems = [firsts.pop()]            # e.g. the submission could not be imported: said once
    else:
        problems = [f"({q.id}) {q.status}: {q.feedback[0] if q.feedback else ''}" for q in bad]
    return "; ".join(_clip(t) for t in integrity), "; ".join(_clip(t) for t in problems)


def _write_json(path: Path, data: dict):
    tmp = path.with_name(path.name + ".part")
    tmp.write_text(json.dumps(data, indent=2) + "\n", encoding="utf-8")
    os.replace(tmp, path)


def _grade_one(exercise: str, submission: str, time_limit: float, out_dir: str, directory: str,
               require_isolation: bool = False, secret: bytes | None = None) -> dict:
    """Grade one submission and write its results file; never raises (a failure is a row too)."""
    path = Path(submission)
    name = path.name
    results = Path(out_dir) / f"{path.stem}.json"
    row = {"submission": name, "status": "graded", "results": str(results)}
    t0 = time.perf_counter()
    try:
        if path.is_symlink() and not _inside(path, Path(directory)):
            raise GradingError(f"{name} is a symbolic link to a file outside the directory; not graded")
        report = grade(exercise, path, time_limit=time_limit, require_isolation=require_isolation, secret=secret)
        data = report.to_gradescope()
        data["extra_data"]["submission"] = name
        row.update(score=report.score, max_score=report.max_score, isolation=report.isolation,
                   isolation_details=list(report.isolation_details),
                   **{q.id: q.score for q in report.questions})
        row["integrity"], row["problems"] = _integrity_and_problems(report)
    except Exception as exc:   # noqa: BLE001 - one submission must not stop the class
        msg = str(exc) if isinstance(exc, GradingError) else f"{type(exc).__name__}: {exc}"
        row.update(status="error", error=_clip(msg, 500))
        data = {"score": 0.0, "output": f"{clean_name(name)} could not be graded: {row['error']}", "tests": [],
                "extra_data": {"submission": name, "status": "error", "error": row["error"]}}
    row["seconds"] = round(time.perf_counter() - t0, 2)
    try:
        _write_json(results, data)
    except OSError as exc:
        row.update(status="error", results="",
                   error=_clip(f"{row.get('error', '') + '; ' if row.get('error') else ''}"
                               f"cannot write {results}: {exc.strerror or exc}", 500))
    return row


def _inside(path: Path, directory: Path) -> bool:
    target, d = os.path.realpath(path), os.path.realpath(directory)
    return target.startswith(d.rstrip(os.sep) + os.sep)


def grade_batch(exercise: str, directory, *, jobs: int = 1, time_limit: float = 60.0, out_dir=None,
                progress=None, require_isolation: bool = False, secret: bytes | None = None) -> BatchGrades:
    """Grade every submission in ``directory``; write a results file per submission and ``summary.csv``.

    Parameters
    ----------
    exercise : str
        Exercise name (a unique prefix such as ``ex03`` works).
    directory : path
        Holds the submissions: every ``*.py`` file directly in it (sub-directories
        and other files are left alone).
    jobs : int
        Parallel workers (joblib; -1 for all cores).  The first submission is
        always graded alone; the rest concurrently only where the kernel keeps
        the submissions' processes apart (:func:`concurrency_problem`).
    time_limit : float
        Seconds for importing a submission and for each question (as for one).
    out_dir : path, optional
        Where ``<name>.json`` and ``summary.csv`` go (default ``directory/results``).
    progress : callable(stage, fraction), optional
    require_isolation : bool
        Course mode: a submission whose run was not isolated scores 0 (as
        :func:`mutext_grader.grade`).
    secret : bytes, optional
        The course secret: each file's inputs are drawn from it and the file's
        content (:func:`mutext_grader.core.input_seed`); without it, afresh
        for every file.

    Returns
    -------
    BatchGrades
        ``rows`` in the order of the files; a row's ``status`` is ``graded``
        (whatever the score) or ``error`` (not graded; ``error`` says why).

    Raises
    ------
    GradingError
        Unknown exercise, not a directory, no submission in it, a bad
        ``jobs`` or time limit, an output directory that cannot be created.
    """
    from mutext.batch import check_jobs, run_parallel
    from mutext.errors import ModelError
    ex = get_exercise(exercise)
    directory = Path(directory)
    subs = find_submissions(directory)
    if not subs:
        raise GradingError(f"no submission (*.py file) in '{directory}'")
    try:
        check_jobs(jobs, "mutext grade")
    except ModelError as exc:
        raise GradingError(str(exc)) from None
    if isinstance(time_limit, bool) or not isinstance(time_limit, (int, float)) or not time_limit > 0 \
            or time_limit == float("inf"):
        raise GradingError(f"the time limit must be a positive number of seconds, got {time_limit!r}")
    out = Path(out_dir) if out_dir is not None else directory / "results"
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise GradingError(f"cannot create the results directory {out}: {exc.strerror or exc}") from None
    questions = [(q.id, q.points) for q in ex.questions(np.random.default_rng(0))]
    tasks = [(ex.name, str(p), float(time_limit), str(out), str(directory), bool(require_isolation), secret)
             for p in subs]
    n = len(tasks)
    res = BatchGrades(ex.name, directory, out, questions, [], 1)

    def report(k, row):
        if progress is not None:
            what = (f"{row['score']:g}/{row['max_score']:g}" if row["status"] == "graded" else "not graded")
            progress(f"{k}/{n} {clean_name(row['submission'])}: {what}", k / n)

    rest = tasks
    if jobs != 1 and n > 1:
        first = _grade_one(*tasks[0])
        res.rows.append(first)
        report(1, first)
        why = concurrency_problem(first.get("isolation", "none"), first.get("isolation_details"))
        if first["status"] != "graded":
            why = "the first submission could not be graded, so the isolation was not confirmed"
        if why is None:
            res.jobs = jobs
        else:
            res.notes.append(f"graded one submission at a time: {why}")
        rest = tasks[1:]
    try:
        for row in run_parallel(_grade_one, rest, jobs=res.jobs):
            res.rows.append(row)
            report(len(res.rows), row)
    except Exception as exc:   # noqa: BLE001 - the pool failed (a worker died): the rest one at a time here
        res.notes.append(f"the parallel workers failed ({type(exc).__name__}: {_clip(exc, 200)}); "
                         f"the remaining submissions were graded one at a time")
        for k in range(len(res.rows), n):
            row = _grade_one(*tasks[k])
            res.rows.append(row)
            report(k + 1, row)
    if res.jobs != 1:
        odd = [r["submission"] for r in res.rows if r["status"] == "graded"
               and concurrency_problem(r.get("isolation", "none"), r.get("isolation_details")) is not None]
        if odd:
            res.notes.append(f"these submissions ran beside others but were not confined as the first one was "
                             f"(see their isolation): {', '.join(clean_name(o) for o in odd)}")
    _write_summary(res)
    return res


#: first characters that make a spreadsheet read a cell as a formula (OWASP, CSV injection)
FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r")


def csv_cell(value):
    """A value as a cell of ``summary.csv``: numbers as they are; text on one line without control
    characters (escaped, :func:`~mutext_grader.core.clean_name`) and, if it starts like a formula
    (:data:`FORMULA_STARTS`), after a single quote, which spreadsheets show as text and do not evaluate.
    The quote is not part of the value: a submission ``=1+1.py`` is the cell ``'=1+1.py``."""
    if value is None:
        return ""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return value
    text = str(value)
    if text.startswith(FORMULA_STARTS):
        return "'" + clean_name(text)
    return clean_name(text)


def _write_summary(res: BatchGrades):
    fields = res.fields
    tmp = res.summary.with_name(res.summary.name + ".part")
    with open(tmp, "w", newline="", encoding="utf-8") as fh:
        w = csv.DictWriter(fh, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        for r in res.rows:
            w.writerow({k: csv_cell(r.get(k)) for k in fields})
    os.replace(tmp, res.summary)
