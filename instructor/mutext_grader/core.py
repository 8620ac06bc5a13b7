"""Exercises, questions, scoring and reports of the autograder."""
from __future__ import annotations

import hashlib
import hmac
import importlib
import math
import re
import secrets as _secrets
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from mutext.errors import MutextError
from mutext.grading.sandbox import Job, SandboxError, run_submission

__all__ = ["GradingError", "Call", "Question", "Exercise", "QuestionReport", "Report", "EXERCISES",
           "get_exercise", "grade", "read_secret", "input_seed", "clean_text", "clean_name"]


class GradingError(MutextError):
    """The grader was used wrongly (unknown exercise, missing submission file)."""


@dataclass
class Call:
    """One call of the student's function: a label for the feedback and JSON arguments."""
    label: str
    args: list = field(default_factory=list)
    kwargs: dict = field(default_factory=dict)


@dataclass
class Question:
    """A graded question: the function to call, how, and how to score what it returns.

    ``check(outcomes)`` receives one dict per call, ``{"ok": True, "value": ...}``
    or ``{"ok": False, "error": "..."}``, and returns ``(score, feedback_lines)``
    with ``0 <= score <= points``.
    """
    id: str
    function: str
    title: str
    points: float
    kind: str                    # "ss", "float" or "array": what the function must return
    calls: list
    check: Callable

    @property
    def name(self) -> str:
        return f"({self.id}) {self.function}: {self.title}"


@dataclass
class Exercise:
    name: str
    title: str
    questions: Callable          # (rng) -> list[Question]: inputs drawn from ``rng`` (a numpy Generator)
    stub: str = ""               # path of the file students fill in, relative to the repository
    prepare: Callable | None = None   # (rng) -> None: expensive reference computations, run while the child
    #                                   works, given a generator seeded as the one ``questions`` got
    blocked_modules: tuple = ()  # library modules that compute this exercise's answers (not importable)


# ----------------------------------------------------------------------------------------------------------
# text that came from a submission (error messages, violations, file names) on its way to a report
# ----------------------------------------------------------------------------------------------------------

#: terminal escape sequences: CSI (colours, cursor moves, erase), OSC (titles, hyperlinks), DCS/SOS/PM/APC
#: strings, and the two-character ESC forms; their 8-bit C1 variants too
_ESCAPES = re.compile(r"(?:\x1b\[|\x9b)[0-?]*[ -/]*[@-~]?"
                      r"|(?:\x1b[\]PX^_]|[\x90\x98\x9d\x9e\x9f])[^\x07\x1b\x9c]*(?:\x07|\x1b\\|\x9c)?"
                      r"|\x1b[ -/]*[0-~]?")
#: what Python (str.splitlines) and terminals take for a line break
_BREAKS = re.compile(r"\r\n|[\r\n\v\f\x1c\x1d\x1e\x85\u2028\u2029]")
#: invisible characters that reorder or hide text (bidirectional overrides and marks)
_BIDI = "\u061c\u200e\u200f\u202a\u202b\u202c\u202d\u202e\u2066\u2067\u2068\u2069"
#: every control character but the newline (C0, DEL, C1), and the bidirectional ones
_CONTROLS = re.compile("[\x00-\x09\x0b-\x1f\x7f-\x9f" + _BIDI + "]")


def clean_text(text) -> str:
    """``text`` with terminal escape sequences and control characters removed; line breaks (``\\r``,
    ``\\r\\n``, vertical tab, form feed, the Unicode line separators) become ``\\n``, a tab a space.

    Applied to everything a submission can influence before it is reported (error messages,
    integrity violations); :meth:`Report.text` then indents every line of it."""
    text = _ESCAPES.sub("", str(text))
    text = _BREAKS.sub("\n", text).replace("\t", " ")
    return _CONTROLS.sub("", text)


def clean_name(text) -> str:
    """A single-line rendering of ``text`` (a file name, a path): each control, line-break or
    bidirectional character shown as its escape (``\\n``, ``\\x1b``, ``\\u202e``), so the name stays
    recognisable and nothing in it acts on a terminal or starts a new line."""
    def esc(m):
        c = m.group(0)
        return {"\n": "\\n", "\r": "\\r", "\t": "\\t"}.get(c) or (
            f"\\x{ord(c):02x}" if ord(c) < 0x100 else f"\\u{ord(c):04x}")
    return re.sub("[\x00-\x1f\x7f-\x9f\u2028\u2029" + _BIDI + "]", esc, str(text))


def _block(text, first: str, rest: str) -> list:
    """The lines of a cleaned ``text``: the first after ``first``, the others after ``rest``."""
    lines = clean_text(text).split("\n")
    return [first + lines[0]] + [rest + line for line in lines[1:]]


@dataclass
class QuestionReport:
    """Points and feedback of one question.  The feedback lines are cleaned of terminal control
    characters (:func:`clean_text`) when the report is made: they may quote the submission's own
    error messages."""
    id: str
    name: str
    score: float
    max_score: float
    feedback: list
    status: str = "ok"

    def __post_init__(self):
        self.feedback = [clean_text(f) for f in self.feedback]
        self.name = clean_name(self.name)

    @property
    def output(self) -> str:
        """The feedback as one text (Gradescope's ``output`` of the test): one item per line, the
        further lines of an item indented."""
        return "\n".join(line for f in self.feedback for line in _block(f, "", "  "))


@dataclass
class Report:
    exercise: str
    title: str
    submission: str
    questions: list
    seconds: float = 0.0
    notes: list = field(default_factory=list)
    isolation: str = "none"      # "uid", "landlock" or "none": how the submission's process was confined
    isolation_details: list = field(default_factory=list)
    inputs: str = ""             # where the inputs came from (the course secret, or the seed of this run)

    def __post_init__(self):
        # notes quote integrity violations (paths and module names the submission chose); the isolation
        # details come from the child's report of its confinement
        self.notes = [clean_text(n) for n in self.notes]
        self.isolation_details = [clean_name(d) for d in self.isolation_details]

    @property
    def isolated(self) -> bool:
        """The submission ran confined (``uid`` or ``landlock``)."""
        return self.isolation in ("uid", "landlock")

    @property
    def isolation_text(self) -> str:
        """One line saying how the submission was isolated (or that it was not)."""
        if self.isolation == "none":
            why = "; ".join(d for d in self.isolation_details if "could" in d or "no " in d)
            return ("isolation: none - this run was NOT isolated, the submission could reach the grader's files"
                    + (f" ({why})" if why else "") + ". For a course, grade as root in a container "
                    "(docs/grading.md).")
        who = {"uid": "an unprivileged user", "landlock": "Landlock"}.get(self.isolation, self.isolation)
        return f"isolation: {self.isolation} - the submission ran confined ({who}; {', '.join(self.isolation_details)})"

    @property
    def score(self) -> float:
        return round(sum(q.score for q in self.questions), 2)

    @property
    def max_score(self) -> float:
        return round(sum(q.max_score for q in self.questions), 2)

    def to_gradescope(self) -> dict:
        """The ``results.json`` schema of Gradescope (also written by otter-grader).

        The texts meant for people (``output``, each test's ``output``) are the cleaned ones of the
        report (no control characters; the further lines of a note or feedback item indented): Gradescope
        shows them and ``jq -r`` prints them raw.  Numbers and the grader's own fields are as computed."""
        notes = [line for n in self.notes for line in _block(n, "note: ", "  ")]
        return {
            "score": float(self.score),
            "execution_time": round(self.seconds, 2),
            "output": "\n".join([f"{self.exercise}: {self.score:g} / {self.max_score:g}"] + notes
                                + [self.isolation_text]),
            "isolation": self.isolation,
            "extra_data": {"isolation_details": list(self.isolation_details), "inputs": self.inputs},
            "tests": [{"name": q.name, "score": float(q.score), "max_score": float(q.max_score),
                       "output": q.output} for q in self.questions],
        }

    def text(self) -> str:
        """Human-readable report: points and feedback per question, then the total.

        Nothing a submission wrote can pose as a line of the report: its file name is shown on one line
        with control characters escaped (:func:`clean_name`), and every line of feedback and of the
        notes after the first is indented (the feedback by four spaces, its further lines by six), so
        only the grader's own lines start in the first column, ``Total:`` among them."""
        lines = [f"Exercise {self.exercise}: {self.title}", f"Submission: {clean_name(self.submission)}",
                 self.isolation_text[0].upper() + self.isolation_text[1:]]
        lines += ([f"Inputs: {self.inputs}"] if self.inputs else []) + [""]
        for n in self.notes:
            lines += _block(n, "note: ", "      ")
        if self.notes:
            lines.append("")
        width = max(len(q.name) for q in self.questions)
        for q in self.questions:
            lines.append(f"{q.name:<{width}}  {q.score:5.2f} / {q.max_score:g}")
            for f in q.feedback:
                lines += _block(f, "    ", "      ")
        lines += ["", f"Total: {self.score:.2f} / {self.max_score:g}"]
        return "\n".join(lines)


#: name -> (module with ``EXERCISE``, one-line description)
EXERCISES = {
    "ex01_two_mass_hinf": ("mutext_grader.ex01_two_mass_hinf",
                           "two-mass system: mechanical model, generalized plant, H-infinity norm, controller"),
    "ex02_mu": ("mutext_grader.ex02_mu",
                "structured singular value: full-block mu, D-scaling upper bound, destabilising Delta, "
                "uncertain spring as an LFT, peak over frequency"),
    "ex03_free_decay": ("mutext_grader.ex03_free_decay",
                        "free-decay identification of a cart: frequency, damping ratio, mass, stiffness, "
                        "damping coefficient"),
    "ex04_beam_element": ("mutext_grader.ex04_beam_element",
                          "Euler-Bernoulli beam elements: element matrices, assembly, natural frequencies, "
                          "convergence"),
    "ex05_diagnose": ("mutext_grader.ex05_diagnose",
                      "diagnosis: log misfit, a grounded spring added, its size fitted, a hidden effect found"),
    "ex06_sidebands": ("mutext_grader.ex06_sidebands",
                       "cracked rotor at speed: where sidebands appear, a local sideband detector, breathing "
                       "crack, open crack or none"),
    "ex07_small_gain": ("mutext_grader.ex07_small_gain",
                        "M-Delta loop: M = F_l(P, K) of the two-mass springs, H-infinity norm and small-gain "
                        "margin, least destabilising Delta, mu bounds for a diagonal structure"),
    "ex08_mbi": ("mutext_grader.ex08_mbi",
                 "model-based identification on the three-mass rig: the plant of Fig. 3.3, D-K, the W_z rule, K "
                 "read as mass, damper and spring on its identifiable band"),
}


def get_exercise(name: str) -> Exercise:
    """The exercise called ``name`` (or the only one starting with ``name``, e.g. ``ex01``)."""
    found = [n for n in EXERCISES if n == name] or [n for n in EXERCISES if n.startswith(name)]
    if len(found) != 1:
        raise GradingError(f"unknown exercise '{name}'. Available: {', '.join(EXERCISES)} "
                           "(mutext grade --list)")
    return importlib.import_module(EXERCISES[found[0]][0]).EXERCISE


def _collapse(lines, labels):
    """Say once what went wrong identically for every call (e.g. NotImplementedError)."""
    if len(labels) < 2:
        return lines
    tags = [f"[{lab}] " for lab in labels]
    by_msg = {}
    for line in lines:
        for t in tags:
            if line.startswith(t):
                by_msg.setdefault(line[len(t):], set()).add(t)
    common = [m for m, ts in by_msg.items() if len(ts) == len(tags)]
    out = []
    for line in lines:
        tag = next((t for t in tags if line.startswith(t)), None)
        if tag is not None and line[len(tag):] in common:
            msg = line[len(tag):]
            if msg not in out:
                out.append(msg)
        else:
            out.append(line)
    return out


def _quietly(fn):
    try:
        fn()
    except Exception:   # noqa: BLE001 - the check that needs the result reports the error
        pass


def _clip(x, hi):
    return round(min(max(float(x), 0.0), float(hi)), 2)


#: bytes of a course secret at least (an instructor's file of random bytes, ``secrets.token_bytes(32)``)
SECRET_MIN_BYTES = 16


def read_secret(path) -> bytes:
    """The course secret in the file ``path`` (at least :data:`SECRET_MIN_BYTES` bytes; surrounding
    whitespace is ignored, so a hex or base64 line works as well as raw bytes)."""
    try:
        data = Path(path).read_bytes().strip()
    except OSError as exc:
        raise GradingError(f"cannot read the course secret {path}: {exc.strerror or exc}") from None
    if len(data) < SECRET_MIN_BYTES:
        raise GradingError(f"the course secret {path} holds {len(data)} bytes; at least {SECRET_MIN_BYTES} are "
                           "needed (e.g. python -c 'import secrets; print(secrets.token_hex(32))' > FILE)")
    return data


def input_seed(exercise: str, submission_bytes: bytes, secret: bytes) -> int:
    """The seed of a submission's inputs in course mode: an HMAC of the exercise and the file's content
    under the course secret.  Without the secret nobody can compute it; the same file is always graded on
    the same inputs (a regrade gives the same score), and any edit of the file draws new ones, so answers
    learned from one run cannot be pasted into the next."""
    msg = exercise.encode() + b"\0" + hashlib.sha256(submission_bytes).digest()
    return int.from_bytes(hmac.new(secret, msg, hashlib.sha256).digest()[:8], "little")


def grade(exercise: str, submission, time_limit: float = 60.0, *, require_isolation: bool = False,
          secret: bytes | None = None, seed: int | None = None) -> Report:
    """Grade ``submission`` (a ``.py`` file) for ``exercise``.

    The submission runs in a confined child process (:mod:`mutext.grading.sandbox`)
    that holds no reference answers and cannot read the grader's files: as
    root it runs as an unprivileged user in its own mount namespace, for
    everyone under Landlock and seccomp where the kernel offers them.  The
    scores are computed here from the plain numbers it sends back.

    Integrity policy: an attempt to open the grader's files, to import
    ``mutext.grading``, ``mutext.examples`` or ``mutext.demos`` (and the
    exercise's ``blocked_modules``, e.g. ``mutext.rotor`` for ex04), to start a
    process or to load native code with :mod:`ctypes` fails.  If the child's
    audit hook sees it while a question's function runs, that question scores
    0; if at import time (module level), every question scores 0.

    Parameters
    ----------
    exercise : str
        Exercise name (see :data:`EXERCISES`); a unique prefix is accepted.
    submission : path-like
        The student's file.
    time_limit : float
        Seconds allowed for importing the submission and for each question
        (a positive, finite number).
    secret : bytes, optional
        The course secret (:func:`read_secret`): the inputs are drawn from a
        seed computed from it and the submission's content
        (:func:`input_seed`), which students cannot compute.
    seed : int, optional
        Draw the inputs from this seed instead (to repeat a run). Without
        ``secret`` or ``seed`` the inputs are drawn afresh on every run.

    Returns
    -------
    Report
        With ``isolation``: ``"uid"`` (as root: the submission ran as an
        unprivileged user that cannot read the grader's files),
        ``"landlock"`` (a plain user on a kernel with Landlock) or ``"none"``
        (not isolated; the report says so).  With ``require_isolation``, a
        run that was not isolated scores 0 on every question (course mode: a
        score that a submission could have forged is not given).

    Raises
    ------
    GradingError
        Unknown exercise, the submission file does not exist, a time limit
        that is not a positive number, or (as root) the child could not be
        confined.
    """
    if isinstance(time_limit, bool) or not isinstance(time_limit, (int, float)) \
            or not math.isfinite(time_limit) or time_limit <= 0:
        raise GradingError(f"the time limit must be a positive number of seconds, got {time_limit!r}")
    ex = get_exercise(exercise)
    path = Path(submission)
    if not path.is_file():
        raise GradingError(f"submission file not found: {submission}")
    if path.suffix != ".py":
        raise GradingError(f"a submission is a Python file (.py), got {path.name}")
    t0 = time.perf_counter()
    if seed is not None:
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
            raise GradingError(f"the seed must be a non-negative integer, got {seed!r}")
        inputs = f"drawn from seed {int(seed)}"
    elif secret is not None:
        seed = input_seed(ex.name, path.read_bytes(), secret)
        inputs = "drawn for this file from the course secret"
    else:
        seed = _secrets.randbits(63)
        inputs = f"drawn afresh for this run (seed {seed}; --seed {seed} repeats it)"
    seed = int(seed)
    questions = ex.questions(np.random.default_rng(seed))
    jobs = [Job(q.id, q.function, q.kind, [{"args": c.args, "kwargs": c.kwargs} for c in q.calls])
            for q in questions]
    warm = None
    if ex.prepare is not None:
        # the reference computations overlap with the child's run; checks wait for them
        warm = threading.Thread(target=_quietly, args=(lambda: ex.prepare(np.random.default_rng(seed)),),
                                daemon=True)
        warm.start()
    try:
        res = run_submission(path, jobs, time_limit=time_limit, blocked_modules=ex.blocked_modules)
    except SandboxError as exc:
        if warm is not None:
            warm.join()
        raise GradingError(f"the submission could not be run in a confined process: {exc}") from None
    imp = res.import_
    reports, notes = [], []
    import_violation = "; ".join(dict.fromkeys(imp.violations))
    if imp.violations:
        notes.append(f"integrity violation at import time, all questions score 0: {import_violation}")
    for q in questions:
        o = res.questions[q.id]
        if imp.status != "ok":
            fb = [f"the submission could not be imported: {imp.error}"]
            if imp.status == "crashed" and res.stderr_tail:
                fb.append("last error output: " + res.stderr_tail.strip().splitlines()[-1])
            reports.append(QuestionReport(q.id, q.name, 0.0, q.points, fb, imp.status))
            continue
        if imp.violations:
            reports.append(QuestionReport(q.id, q.name, 0.0, q.points,
                                          [f"0 points: integrity violation when the file was imported "
                                           f"({import_violation})"], "violation"))
            continue
        if o.violations:
            what = "; ".join(dict.fromkeys(o.violations))
            reports.append(QuestionReport(q.id, q.name, 0.0, q.points,
                                          [f"0 points: integrity violation, {q.function}() tried {what}"],
                                          "violation"))
            continue
        if o.status != "ok":
            msg = o.error or o.status
            if isinstance(o.last_call, int) and 0 <= o.last_call < len(q.calls) and len(q.calls) > 1:
                msg += f" [while {q.function}() ran on: {q.calls[o.last_call].label}]"
            reports.append(QuestionReport(q.id, q.name, 0.0, q.points, [msg], o.status))
            continue
        outcomes = list(o.calls) + [{"ok": False, "error": "no result"}] * (len(q.calls) - len(o.calls))
        try:
            score, fb = q.check(outcomes)
        except Exception as exc:   # noqa: BLE001 - an unforeseen return value must not stop the report
            score, fb = 0.0, [f"the returned value could not be checked ({type(exc).__name__}: {exc})"]
        fb = _collapse(list(fb), [c.label for c in q.calls])
        reports.append(QuestionReport(q.id, q.name, _clip(score, q.points), q.points, fb))
    if warm is not None:
        warm.join()   # never leave a solver running in a thread at interpreter exit
    if require_isolation and res.isolation not in ("uid", "landlock"):
        why = ("not scored: this run was not isolated and isolation was required (--require-isolation), "
               "so the submission could have reached the grader's files")
        notes.insert(0, why)
        reports = [QuestionReport(r.id, r.name, 0.0, r.max_score, [why], "not isolated") for r in reports]
    return Report(ex.name, ex.title, str(submission), reports, time.perf_counter() - t0, notes,
                  res.isolation, list(res.isolation_details), inputs)
