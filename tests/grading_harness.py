"""One harness for the autograder tests: every (exercise, submission, seed) graded at most once per process.

``graded(exercise, path, seed)`` is the report of :func:`mutext_grader.grade` on the inputs of ``seed``,
memoised for the test session (each worker process) and graded two at a time in the background after
``prefetch``.  Several tests assert on one report instead of grading the same file again; on one seed the
grader's reference computations (``prepare`` and the checks' caches) are made once too.

``graded_here(exercise, path, seed)`` is the report of the same :func:`~mutext_grader.grade` code with the
confined child replaced by a run of the submission's functions in this process (no child, no confinement:
only for the repository's own, well-behaved submissions).  The questions, the inputs of the seed, the
encoding and validation of the returned values, the checks, the collapsed feedback and the report are the
grader's own; what it leaves out (the child, its time limits, the integrity guard) is checked on the
confined runs of the reference and the cheating, crashing and hostile submissions, and by the ``-m slow``
tests that grade the others confined and compare (:func:`assert_same_scores_and_feedback`).
``check_here`` is ``mutext check`` (:func:`mutext.grading.check.check`) likewise; ``scored_here`` feeds
chosen questions' checks directly (no report); ``drawn`` memoises an exercise's questions of a seed;
``grade_without_warm_up`` grades confined without the warm-up of the reference computations.

:class:`Submissions` names an exercise's files (the reference solution, the stub and
``tests/grading_submissions/<prefix>_*.py``) on the seed of a test module: ``graded(name)`` confined,
``graded.here(name)`` in process.
"""
import dataclasses
import importlib.util
import inspect
import json
import threading
import types
import uuid
import warnings
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

from mutext_grader import core, grade
from mutext_grader.core import get_exercise

ROOT = Path(__file__).resolve().parents[1]
SUBS = Path(__file__).resolve().parent / "grading_submissions"
SOLUTIONS = ROOT / "instructor" / "mutext_grader" / "solutions"
STUBS = ROOT / "exercises"

_pool = ThreadPoolExecutor(max_workers=2)
_futures = {}
_lock = threading.Lock()


def _key(exercise, path, seed, time_limit):
    return get_exercise(exercise).name, str(Path(path).resolve()), int(seed), float(time_limit)


def prefetch(runs):
    """Start grading ``(exercise, path, seed)`` or ``(exercise, path, seed, time_limit)`` runs in the
    background, two at a time, in the order given (a run already started is not started again)."""
    with _lock:
        for run in runs:
            exercise, path, seed, *rest = run
            key = _key(exercise, path, seed, rest[0] if rest else 60.0)
            if key not in _futures:
                _futures[key] = _pool.submit(grade, exercise, path, key[3], seed=key[2])


def graded(exercise, path, seed, time_limit=60.0):
    """The report of ``path`` graded (confined) on the inputs of ``seed``; graded once per process."""
    prefetch([(exercise, path, seed, time_limit)])
    return _futures[_key(exercise, path, seed, time_limit)].result()


# ----------------------------------------------------------------------------------------------------------
# the grader with the submission's functions run in this process
# ----------------------------------------------------------------------------------------------------------

def load(path, name=None):
    """``path`` imported as a fresh module (not kept in ``sys.modules``)."""
    spec = importlib.util.spec_from_file_location(name or f"submission_{Path(path).stem}_{uuid.uuid4().hex[:8]}",
                                                  path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _run_here(submission, jobs, time_limit=60.0, blocked_modules=(), **_):
    """:func:`mutext.grading.sandbox.run_submission` without the child: the submission imported and its
    functions called here as the child's runner (``mutext/grading/_runner.py``) calls them, the values
    encoded by the runner's own encoders and checked by the sandbox's own validation."""
    import control as ct
    from mutext.grading import _runner, sandbox
    sub_path = str(submission)
    imp = sandbox.PhaseOutcome("not_run")
    questions = {j.id: sandbox.PhaseOutcome("not_run") for j in jobs}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            mod = load(sub_path)
        except Exception as exc:   # noqa: BLE001
            imp.status, imp.error = "error", _runner._error_text(exc, sub_path)
            return sandbox.SandboxResult(imp, questions, isolation="none", isolation_details=["in process"])
        imp.status = "ok"
        for job in jobs:
            fname, kind = job.function, job.kind
            func = getattr(mod, fname, None)
            calls = []
            for call in json.loads(json.dumps(job.calls)):      # as the request file carries them
                if not callable(func):
                    calls.append({"ok": False, "error": f"the submission defines no function {fname}()"})
                    continue
                args = [_runner._decode_arg(a, ct) for a in call.get("args", [])]
                kwargs = {k: _runner._decode_arg(v, ct) for k, v in call.get("kwargs", {}).items()}
                try:
                    value = func(*args, **kwargs)
                except NotImplementedError:
                    calls.append({"ok": False, "error": f"{fname}() is not implemented yet "
                                                        "(it raises NotImplementedError)"})
                    continue
                except Exception as exc:   # noqa: BLE001
                    calls.append({"ok": False, "error": _runner._error_text(exc, sub_path)})
                    continue
                try:
                    enc = (_runner._encode_ss(value, np, ct) if kind == "ss" else
                           _runner._encode_array(value, np) if kind == "array" else _runner._encode_float(value, np))
                except Exception as exc:   # noqa: BLE001
                    calls.append({"ok": False, "error": f"{fname}() {exc}" if str(exc).startswith("returned")
                                  else f"{fname}(): {exc}"})
                    continue
                calls.append({"ok": True, "value": enc})
            calls = json.loads(json.dumps(calls))                # as the results channel carries them
            questions[job.id] = sandbox.PhaseOutcome("ok", sandbox._clean_calls(kind, calls, len(job.calls)))
    return sandbox.SandboxResult(imp, questions, isolation="none", isolation_details=["in process"])


#: :func:`mutext_grader.grade`, the same code, with :func:`_run_here` for the confined run (a copy of the
#: function with its own globals: grading confined in another thread at the same time is not affected)
assert inspect.unwrap(core.grade) is core.grade
_grade_here = types.FunctionType(core.grade.__code__, {**core.grade.__globals__, "run_submission": _run_here},
                                 "grade_here", core.grade.__defaults__, core.grade.__closure__)
_grade_here.__kwdefaults__ = core.grade.__kwdefaults__
_here = {}
_here_lock = threading.Lock()


def _check_here_function():
    from mutext.grading import check as chk
    real = inspect.unwrap(chk.check)         # the function under its parameter validation
    f = types.FunctionType(real.__code__, {**real.__globals__, "run_submission": _run_here},
                           "check_here", real.__defaults__, real.__closure__)
    f.__kwdefaults__ = real.__kwdefaults__
    return f


#: :func:`mutext.grading.check.check` (``mutext check``), the same code, with :func:`_run_here` for the
#: confined run
check_here = _check_here_function()


def _without_warm_up(name):
    return dataclasses.replace(get_exercise(name), prepare=None)


#: :func:`mutext_grader.grade`, the same code, without the warm-up thread of the exercise's reference
#: computations (``Exercise.prepare``, only started early so that they overlap with the child's run: the
#: checks compute what they need either way).  For files that mostly fail before any check, such as the
#: hostile submissions: ex08's warm-up alone is a D-K search of several CPU-seconds.
grade_without_warm_up = types.FunctionType(core.grade.__code__,
                                           {**core.grade.__globals__, "get_exercise": _without_warm_up},
                                           "grade_without_warm_up", core.grade.__defaults__, core.grade.__closure__)
grade_without_warm_up.__kwdefaults__ = core.grade.__kwdefaults__


def graded_here(exercise, path, seed):
    """The report of ``path`` on the inputs of ``seed`` with its functions run in this process (memoised)."""
    key = _key(exercise, path, seed, 60.0)
    with _here_lock:
        if key not in _here:
            _here[key] = _grade_here(exercise, path, 60.0, seed=int(seed))
        return _here[key]


def memoised_grade(here=False):
    """A stand-in for :func:`mutext_grader.grade` in the command line's module: a run with a seed and
    nothing else is the memoised :func:`graded` (``here``: :func:`graded_here`), so ``mutext grade FILE
    --seed N`` and a test on the same file share one run; any other run is graded as usual."""
    def grade_(exercise, submission, time_limit=60.0, *, require_isolation=False, secret=None, seed=None):
        if seed is None or require_isolation or secret is not None or (here and time_limit != 60.0):
            return grade(exercise, submission, time_limit, require_isolation=require_isolation, secret=secret,
                         seed=seed)
        return graded_here(exercise, submission, seed) if here else graded(exercise, submission, seed, time_limit)
    return grade_


_drawn = {}
_scored = {}


def drawn(exercise, seed):
    """``{qid: Question}`` of ``exercise`` on the inputs of ``seed`` (memoised: some draws cost seconds)."""
    key = (get_exercise(exercise).name, int(seed))
    if key not in _drawn:
        _drawn[key] = {x.id: x for x in get_exercise(exercise).questions(np.random.default_rng(seed))}
    return _drawn[key]


def scored_here(exercise, path, seed, qids=None):
    """``{qid: (score, feedback text)}`` of the questions ``qids`` (all by default) of ``path`` on the
    inputs of ``seed``: its functions run in this process as in :func:`graded_here`, each question's
    check fed directly (the feedback lines as the check gives them, not yet collapsed as in a report;
    the questions not asked for are not run, e.g. those whose check runs a D-K search)."""
    from mutext.grading.sandbox import Job
    key = (*_key(exercise, path, seed, 60.0), None if qids is None else tuple(qids))
    if key not in _scored:
        questions = [x for x in drawn(exercise, seed).values() if qids is None or x.id in qids]
        res = _run_here(path, [Job(x.id, x.function, x.kind, [{"args": c.args, "kwargs": c.kwargs} for c in x.calls])
                               for x in questions])
        if res.import_.status != "ok":
            raise AssertionError(f"{path} could not be imported: {res.import_.error}")
        out = {}
        for x in questions:
            score, fb = x.check(list(res.questions[x.id].calls))
            out[x.id] = (score, "\n".join(fb))
        _scored[key] = out
    return _scored[key]


# ----------------------------------------------------------------------------------------------------------
# the submissions of an exercise
# ----------------------------------------------------------------------------------------------------------

class Submissions:
    """An exercise's reference solution (``"reference"``), stub (``"stub"``) and
    ``tests/grading_submissions/<prefix>_*.py``, and ``extra`` files, graded on the inputs of ``seed``.

    ``graded(name)`` (confined) starts the ``confined`` names in the background the first time, in that
    order; ``graded.here(name)`` runs the functions in this process; ``seed`` overrides the module's seed
    for one run; ``time_limits`` gives a name its own time limit."""

    def __init__(self, exercise, seed, *, extra=None, confined=("reference",), time_limit=60.0, time_limits=None):
        self.exercise = get_exercise(exercise).name
        self.seed = seed
        self.time_limit = time_limit
        prefix = self.exercise.split("_")[0]
        self.paths = {
            "reference": SOLUTIONS / f"{self.exercise}.py",
            "stub": STUBS / f"{self.exercise}.py",
            **{p.stem: p for p in sorted(SUBS.glob(f"{prefix}_*.py"))},
            **(extra or {}),
        }
        self.confined = tuple(confined)
        self.time_limits = dict(time_limits or {})       # name -> seconds, for a run with its own limit
        self._started = False

    def _limit(self, name):
        return self.time_limits.get(name, self.time_limit)

    def __call__(self, name, seed=None):
        if not self._started:
            self._started = True
            prefetch([(self.exercise, self.paths[n], self.seed, self._limit(n)) for n in self.confined])
        return graded(self.exercise, self.paths[name], self.seed if seed is None else seed, self._limit(name))

    def here(self, name, seed=None):
        return graded_here(self.exercise, self.paths[name], self.seed if seed is None else seed)


def q(report, qid):
    return next(x for x in report.questions if x.id == qid)


def full(report, *qids):
    return all(q(report, i).score == q(report, i).max_score for i in qids)


def assert_same_scores_and_feedback(confined, here):
    """A confined report and the in-process one of the same file and seed: the same points, statuses and
    feedback per question (what the in-process runs of the default tests stand for)."""
    assert confined.inputs == here.inputs
    assert [(x.id, x.score, x.status, x.output) for x in confined.questions] == \
           [(x.id, x.score, x.status, x.output) for x in here.questions], confined.text()
