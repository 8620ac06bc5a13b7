"""One child: its environment, its start, the wait for its events phase by phase, and its end."""
from __future__ import annotations

import json
import os
import secrets
import signal
import subprocess
import sys
import time

from ._channel import _clean_calls, _confinement, _Events
from ._settings import FILE_SIZE_LIMIT, JAIL, SCRATCH_BYTES, SCRATCH_CHECK_INTERVAL, SCRATCH_FILES, STARTUP_LIMIT


def _child_env(box):
    # nothing of the grader's environment: it may hold tokens, and PYTHON* would redirect imports
    return {"PATH": "/usr/local/bin:/usr/bin:/bin", "HOME": box, "TMPDIR": box, "MPLCONFIGDIR": box,
            "LANG": "C.UTF-8", "LC_ALL": "C.UTF-8", "MPLBACKEND": "Agg",
            # one BLAS thread: graders often run several submissions on a few cores
            "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
            # Windows needs these to start Python at all
            **{k: v for k, v in os.environ.items() if os.name == "nt" and k.upper() in ("SYSTEMROOT", "WINDIR")}}


def _kill(proc):
    try:
        if os.name == "posix":
            os.killpg(proc.pid, signal.SIGKILL)
        else:   # pragma: no cover
            proc.kill()
    except (ProcessLookupError, PermissionError):
        pass
    try:
        proc.kill()
    except (ProcessLookupError, PermissionError, OSError):
        pass
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:   # pragma: no cover
        pass


def _measure_at_end(scratch, proc, phase, outcome):
    """At the end of ``phase`` (its result just read): ``(phase, "disk", why)`` if the child's files are
    over the disk budget now, else None.  The files are that phase's (the next one has at most just
    begun), so it, not the next, is stopped; which of its calls made them is not known (``last_call``
    cleared)."""
    if scratch is None:
        return None
    why = scratch.over(proc.pid)
    if not why:
        return None
    outcome.last_call = None
    return (phase, "disk", why)


def _run_once(workdir, plan, jobs, time_limit, outcomes, imp, log, state, scratch=None, total_limit=None):
    """Start one child for ``jobs``; fill ``outcomes``/``imp``; return the phase that was cut short as
    ``(phase, status, exit code or reason)``.

    ``total_limit``: seconds for the whole submission, counted from the first child's boot (``state``
    keeps that time across children); beyond it the child is stopped with status ``"budget"``.
    ``scratch`` (a :class:`_Scratch`) is measured every :data:`SCRATCH_CHECK_INTERVAL` seconds and at the
    end of each phase; a child over the disk budget is stopped with status ``"disk"``, the phase it is in
    named, or the phase that has just ended when that one left the files behind (a question that floods the
    directory between two periodic measurements, then returns, is named, not the question after it)."""
    nonce = secrets.token_hex(16)
    results = workdir / f"results-{nonce}.jsonl"
    request = workdir / f"request-{nonce}.json"
    errpath = workdir / f"stderr-{nonce}.txt"
    n_phases = len(jobs) + 1
    budget = STARTUP_LIMIT + time_limit * n_phases + 10.0     # a child never lives longer than this
    cpu = int(min(budget, 2.0 ** 40)) + 1
    rfd = os.open(results, os.O_WRONLY | os.O_APPEND | os.O_CREAT | os.O_EXCL, 0o600)
    posix = os.name == "posix"
    try:
        req = dict(plan, nonce=nonce, results_fd=rfd if posix else None, results_path=str(results),
                   parent_pid=os.getpid(),
                   jobs=[{"id": t.id, "function": t.function, "kind": t.kind, "calls": t.calls} for t in jobs])
        req["rlimits"] = dict(plan["rlimits"], cpu=[cpu, cpu + 5])
        fd = os.open(request, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "w") as fh:
            json.dump(req, fh)
        with open(errpath, "wb") as err:
            proc = subprocess.Popen(
                [sys.executable, "-I", "-S", "-B", str(JAIL), str(request)], cwd=plan["box"],
                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=err, env=_child_env(plan["box"]),
                pass_fds=(rfd,) if posix else (), start_new_session=posix)
    finally:
        os.close(rfd)
    events = _Events(results, nonce)
    order = ["import"] + [t.id for t in jobs] if imp.status == "not_run" else [t.id for t in jobs]
    kinds = {t.id: (t.kind, len(t.calls)) for t in jobs}
    phase, t0, cut, started = "startup", time.monotonic(), None, time.monotonic()
    next_check = started + SCRATCH_CHECK_INTERVAL
    stage = "startup"        # startup -> confined -> booted: each event is accepted once, in order
    nxt = 0                  # index in ``order`` of the next phase allowed to start
    delay = 0.01
    while True:
        rc = proc.poll()
        for ev in events.read():
            kind, p = ev.get("event"), ev.get("phase")
            now = time.monotonic()
            if kind == "confined" and stage == "startup":
                stage = "confined"
                state["isolation"], state["details"] = _confinement(ev, plan["mode"], plan["probe_batch"])
                applied = [str(a) for a in ev.get("applied") or []]
                if scratch is not None and any(a == "mount-namespace" or a.startswith("landlock") for a in applied):
                    scratch.shared = False      # the child could not write into the shared directories
                if not any(a.startswith("scratch directory") for a in applied):
                    state["details"].append(
                        f"scratch directory: no tmpfs of its own; {FILE_SIZE_LIMIT // 2 ** 20} MiB per file, "
                        f"the grader stops the child beyond {SCRATCH_BYTES // 2 ** 20} MiB or {SCRATCH_FILES} "
                        f"files (measured every {SCRATCH_CHECK_INTERVAL:g} s and at the end of each phase)")
                if ev.get("fatal"):
                    state["fatal"] = str(ev["fatal"])[:500]
            elif kind == "boot" and stage == "confined":
                stage, phase, t0 = "booted", None, now
                state.setdefault("booted_at", now)
            elif stage != "booted":
                continue
            elif kind == "start" and phase is None and nxt < len(order) and p == order[nxt]:
                phase, t0 = p, now
                nxt += 1
            elif kind == "call" and p == phase and p in outcomes and isinstance(ev.get("index"), int):
                outcomes[p].last_call = ev["index"]
            elif kind == "violation" and p in (["import"] + list(outcomes)):
                o = imp if p == "import" else outcomes[p]
                if len(o.violations) < 20:
                    o.violations.append(str(ev.get("what"))[:300])
            elif kind == "result" and p == phase and p == "import":
                imp.status = "ok" if ev.get("ok") is True else "error"
                imp.error = str(ev.get("error", ""))[:2000]
                imp.seconds = now - t0
                phase, t0 = None, now
                cut = _measure_at_end(scratch, proc, p, imp)
            elif kind == "result" and p == phase and p in outcomes:
                o = outcomes[p]
                kind_, n = kinds[p]
                o.status, o.calls, o.seconds = "ok", _clean_calls(kind_, ev.get("calls"), n), now - t0
                phase, t0 = None, now
                cut = _measure_at_end(scratch, proc, p, o)
            if cut is not None:
                break
        if cut is not None:          # a phase that has ended left too much on disk
            _kill(proc)
            break
        if rc is not None:
            if phase is not None:
                cut = (phase, "crashed", rc)
            break
        if "fatal" in state:
            _kill(proc)
            break
        # phase None: the runner between phases; a stuck runner (e.g. a thread the
        # submission started holding the interpreter) must not stall grading either
        limit = STARTUP_LIMIT if phase == "startup" else time_limit
        now = time.monotonic()
        if total_limit is not None and "booted_at" in state and now - state["booted_at"] > total_limit:
            _kill(proc)
            cut = (phase, "budget", None)
            break
        if now - t0 > limit or now - started > budget:
            _kill(proc)
            cut = (phase, "timeout", None)
            break
        if scratch is not None and now >= next_check:
            why = scratch.over(proc.pid)
            next_check = time.monotonic() + SCRATCH_CHECK_INTERVAL
            if why:
                _kill(proc)
                cut = (phase, "disk", why)
                break
        time.sleep(delay)
        delay = min(0.05, delay * 1.5)
    with open(errpath, "rb") as fh:
        fh.seek(max(0, os.path.getsize(errpath) - 4000))
        log.append(fh.read().decode("utf-8", "replace"))
    return cut

