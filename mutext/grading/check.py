"""``mutext check EXERCISE FILE``: does a student's file run and return values of the right kind?

The check runs the file the way the grader does, in a separate confined
process (:func:`mutext.grading.sandbox.run_submission`), on sample inputs
drawn afresh from :mod:`mutext.grading.spec` (never the graded ones), and
says per function whether it

* is defined and implemented (a stub raises ``NotImplementedError``),
* runs without raising (the error and the line if it does),
* finishes within the time limit,
* returns the right kind and shape of value (a float, an array of 3
  numbers, a StateSpace with 2 inputs and 2 outputs, ...; what was expected
  if not).

It never says whether a value is right: no reference solution, reference
value or point is computed, printed or installed with ``mutext``; the
instructor's grader decides that.  The isolation of the process is reported
but not required (on a laptop without Landlock the check still runs).
"""
from __future__ import annotations

import re
import secrets
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from .._validation import Integer, NoneOr, Real, validate_params
from ..errors import MutextError
from .sandbox import Job, SandboxError, run_submission
from .spec import EXERCISES, UnknownExercise, get_exercise

__all__ = ["CheckError", "FunctionCheck", "CheckReport", "check", "STATUS_TEXT", "DEFAULT_TIME_LIMIT"]

#: seconds allowed for importing the file and for each function (as the grader's default)
DEFAULT_TIME_LIMIT = 60.0

#: status -> how the report names it
STATUS_TEXT = {
    "ok": "OK",
    "not_implemented": "not implemented",
    "missing": "missing",
    "raises": "raises an error",
    "wrong_kind": "wrong kind of value",
    "timeout": "times out",
    "crashed": "crashed",
    "blocked": "blocked",
    "not_run": "not run",
}
#: which status a function gets when its calls end differently (the first that occurs)
_PRIORITY = ("missing", "not_implemented", "raises", "wrong_kind")


class CheckError(MutextError):
    """The check was used wrongly (``usage``: unknown exercise, missing file, not a ``.py`` file, a bad time
    limit) or the file could not be run in a confined process at all.

    Parameters
    ----------
    message : str
        What went wrong.
    usage : bool, optional
        A wrong use (exit status 2), not a failure to run the file.
    """

    def __init__(self, message, usage=True):
        super().__init__(message)
        self.usage = usage


@dataclass
class FunctionCheck:
    """What happened to one function on its sample calls.

    Attributes
    ----------
    id : str
        Question id.
    function : str
        Name of the function.
    title : str
        The question's title.
    expected : str
        The expected return, in words.
    status : str
        A key of :data:`STATUS_TEXT`.
    calls : int
        Sample calls made.
    good : int
        Calls that ran and returned the right kind of value.
    messages : list of str
        What went wrong, per call.
    """
    id: str
    function: str
    title: str
    expected: str                 # the expected return, in words
    status: str                   # a key of STATUS_TEXT
    calls: int                    # sample calls made
    good: int = 0                 # calls that ran and returned the right kind of value
    messages: list = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return self.status == "ok"


@dataclass
class CheckReport:
    """What ``mutext check`` found in one submission.

    Attributes
    ----------
    exercise : str
        Name of the exercise.
    title : str
        Its title.
    file : str
        The submission checked.
    functions : list of FunctionCheck
        One entry per graded function.
    inputs : str
        Which sample inputs were used, in words.
    seed : int or None
        Seed of the sample inputs.
    imported : bool
        Whether the file imported.
    import_error : str
        The error when it did not.
    notes : list of str
        Further remarks.
    isolation : str
        How the child was confined: ``"uid"``, ``"landlock"`` or ``"none"``.
    isolation_details : list of str
        What the confinement did and did not achieve.

    seconds : float
        Wall time of the check.
    """
    exercise: str
    title: str
    file: str
    functions: list
    inputs: str = ""
    seed: int | None = None
    imported: bool = True
    import_error: str = ""
    notes: list = field(default_factory=list)
    isolation: str = "none"
    isolation_details: list = field(default_factory=list)
    seconds: float = 0.0

    @property
    def n_ok(self) -> int:
        return sum(f.ok for f in self.functions)

    @property
    def ok(self) -> bool:
        """Every function runs and returns the right kind of value."""
        return self.imported and all(f.ok for f in self.functions)

    @property
    def summary(self) -> str:
        return (f"{self.n_ok} of {len(self.functions)} functions run and return the right kind of value; "
                "the grader decides whether they are right.")

    @property
    def isolation_text(self) -> str:
        if self.isolation in ("uid", "landlock"):
            who = {"uid": "an unprivileged user", "landlock": "Landlock"}[self.isolation]
            return f"{self.isolation} (your file ran confined by {who}, as it will be when graded)"
        return ("none (your file was not confined on this machine; fine for a check, the grader runs it "
                "confined)")

    def text(self) -> str:
        """The report for a terminal."""
        lines = [f"Check of {self.exercise}: {self.title}", f"File: {_clean(self.file)}",
                 f"Inputs: {self.inputs}", f"Isolation: {self.isolation_text}", ""]
        if not self.imported:
            lines += [f"The file could not be imported: {_clean(self.import_error)}", ""]
        lines += [f"note: {_clean(n)}" for n in self.notes] + ([""] if self.notes else [])
        width = max(len(f"({f.id}) {f.function}") for f in self.functions)
        for f in self.functions:
            head = f"({f.id}) {f.function}"
            lines.append(f"{head:<{width}}  {STATUS_TEXT[f.status]}")
            lines.append(f"    expected: {f.expected}")
            lines += [f"    {_clean(m)}" for m in f.messages]
        lines += ["", self.summary]
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """Plain data for ``--json``."""
        d = asdict(self)
        d["functions"] = [dict(asdict(f), ok=f.ok) for f in self.functions]
        d.update(ok=self.ok, summary=self.summary, seconds=round(self.seconds, 1))
        return d


_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f]")


def _clean(text) -> str:
    """Text from the submission without control characters (no terminal escapes posing as our output)."""
    return _CONTROL.sub("?", str(text))


def _call_error_kind(function: str, error: str) -> str:
    """What a failed call's message from the child means."""
    if "is not implemented yet" in error and error.startswith(f"{function}()"):
        return "not_implemented"
    if error.startswith("the submission defines no function"):
        return "missing"
    if error.startswith(f"{function}() returned") or error.startswith(f"{function}(): ") \
            or error.startswith("the grading process sent back a malformed value"):
        return "wrong_kind"
    return "raises"


def _which(indices, n) -> str:
    if n == 1:
        return ""
    if len(indices) == n:
        return ""
    return ("on sample call " if len(indices) == 1 else "on sample calls ") \
        + ", ".join(str(i + 1) for i in indices) + f" of {n}: "


def _function_check(q, calls, outcome) -> FunctionCheck:
    n = len(calls)
    fc = FunctionCheck(q.id, q.function, q.title, q.returns, "ok", n)
    if outcome.violations:
        what = "; ".join(dict.fromkeys(outcome.violations))
        fc.status = "blocked"
        fc.messages.append(f"{q.function}() tried {what}: this is blocked in the exercise (see its rules), "
                           "and the grader does not accept it")
        return fc
    if outcome.status in ("timeout", "crashed", "not_run"):
        fc.status = outcome.status
        msg = outcome.error or STATUS_TEXT[outcome.status]
        if isinstance(outcome.last_call, int) and 0 <= outcome.last_call < n and n > 1:
            msg += f" [while running sample call {outcome.last_call + 1} of {n}]"
        fc.messages.append(msg)
        return fc
    results = list(outcome.calls) + [{"ok": False, "error": "no result came back"}] * (n - len(outcome.calls))
    found: dict = {}      # (status, message) -> call indices
    for i, ((args, kwargs), res) in enumerate(zip(calls, results)):
        if res.get("ok"):
            problem = q.shape_problem(res["value"], args, kwargs)
            if problem is None:
                fc.good += 1
                continue
            key = ("wrong_kind", f"{q.function}() {problem}")
        else:
            err = str(res.get("error", ""))
            kind = _call_error_kind(q.function, err)
            if kind == "missing":
                err = f"your file defines no function {q.function}() (the name must be exactly this)"
            key = (kind, err)
        found.setdefault(key, []).append(i)
    if found:
        statuses = [s for s, _ in found]
        fc.status = next(s for s in _PRIORITY if s in statuses)
        fc.messages = [_which(idx, n) + msg for (_, msg), idx in found.items()]
    else:
        fc.messages.append(f"runs and returns the right kind of value on {n} sample call{'s' if n > 1 else ''}")
    return fc


@validate_params({"time_limit": Real(lo=0, closed="neither"), "seed": NoneOr(Integer(lo=0))}, error=CheckError)
def check(exercise: str, path, time_limit: float = DEFAULT_TIME_LIMIT, *, seed: int | None = None) -> CheckReport:
    """Run the file ``path`` on fresh sample inputs of ``exercise`` and report per function.

    Parameters
    ----------
    exercise : str
        An exercise name (``mutext check --list``); a unique prefix such as ``ex01`` works.
    path : path-like
        The student's ``.py`` file.
    time_limit : float
        Seconds allowed for importing the file and, separately, for each function.
    seed : int, optional
        Draw the sample inputs from this seed (to repeat a check); by default they are drawn afresh.

    Returns
    -------
    CheckReport
        Per function: ``ok``, ``not_implemented``, ``missing``, ``raises``, ``wrong_kind``, ``timeout``,
        ``crashed`` or ``blocked``, with what was expected and what went wrong.  Never a reference value
        or a score.

    Raises
    ------
    CheckError
        Unknown exercise, missing file, not a ``.py`` file, a bad time limit (``usage``), or the file
        could not be run in a confined process.
    """
    try:
        ex = get_exercise(exercise)
    except UnknownExercise as exc:
        raise CheckError(str(exc)) from None
    time_limit = float(time_limit)
    p = Path(path)
    if not p.exists():
        raise CheckError(f"file not found: {path}")
    if not p.is_file() or p.suffix != ".py":
        raise CheckError(f"expected a Python file (.py), got {path}")
    if seed is None:
        seed = secrets.randbits(63)
        inputs = f"sample inputs drawn afresh (seed {seed}; --seed {seed} repeats them), not the graded ones"
    else:
        seed = int(seed)
        inputs = f"sample inputs drawn from seed {seed}, not the graded ones"
    rng = np.random.default_rng(seed)
    calls = {q.id: q.sample_calls(rng) for q in ex.questions}
    jobs = [Job(q.id, q.function, q.kind, [{"args": a, "kwargs": k} for a, k in calls[q.id]])
            for q in ex.questions]
    t0 = time.perf_counter()
    try:
        res = run_submission(p, jobs, time_limit=time_limit, blocked_modules=ex.blocked_modules)
    except SandboxError as exc:
        raise CheckError(f"the file could not be run in a confined process: {exc}", usage=False) from None
    report = CheckReport(ex.name, ex.title, str(path), [], inputs, seed, isolation=res.isolation,
                         isolation_details=list(res.isolation_details))
    imp = res.import_
    if imp.violations:
        report.notes.append("at import time (module level) the file tried "
                            + "; ".join(dict.fromkeys(imp.violations))
                            + ": this is blocked in the exercise, and the grader does not accept the file")
    if imp.status != "ok":
        report.imported = False
        report.import_error = imp.error or imp.status
        if imp.status == "crashed" and res.stderr_tail.strip():
            report.import_error += "; last error output: " + res.stderr_tail.strip().splitlines()[-1]
        report.functions = [FunctionCheck(q.id, q.function, q.title, q.returns, "not_run", len(calls[q.id]),
                                          messages=["not run: the file could not be imported"])
                            for q in ex.questions]
    else:
        report.functions = [_function_check(q, calls[q.id], res.questions[q.id]) for q in ex.questions]
        if imp.violations:
            for f in report.functions:
                if f.status == "ok":
                    f.status = "blocked"
                    f.messages = ["runs, but the file did something blocked when it was imported (see the note)"]
    report.seconds = time.perf_counter() - t0
    return report


def exercise_list() -> list:
    """``(name, title, description, functions)`` of every exercise, for ``mutext check --list``."""
    return [(ex.name, ex.title, ex.description, [q.function for q in ex.questions]) for ex in EXERCISES.values()]
