"""Child process of the autograder: import a submission and call its functions.

Never imported by the grader: :mod:`mutext.grading._jail` confines the child
process first (another user, Landlock, seccomp, resource limits; see there)
and then executes this file's source and calls :func:`serve`.  It imports
nothing from :mod:`mutext.grading`; the process that executes student code
holds no reference answers and cannot read the files that contain them.  It
only evaluates the student's functions on the inputs listed in the request
and writes the plain numeric results, one JSON object per line, to the
results channel (a file descriptor the parent opened).  Every line carries
the parent's random nonce, so text the submission prints (stdout is
discarded anyway) cannot pose as a result; the parent validates every value
it reads, and accepts the events only in the order of the phases.

The audit hook :class:`Guard` installed before the submission is imported is
*not* what enforces the rules (student code can reach and disable it; the
kernel-level confinement is what holds).  It turns the usual attempts into a
clear integrity note for the report: opening files or directories under the
protected directories (the grader, its reference solutions, the example
models), importing the protected modules (``mutext.grading``,
``mutext.examples``, ...), modifying the package, starting processes,
loading native libraries through :mod:`ctypes`, opening the ``/proc`` entries
of other processes.  Attempts made while student code runs are reported to
the parent as violations.
"""
from __future__ import annotations

import json
import os
import re
import sys
import threading
import traceback

# the parent's limits (the request carries them; it rejects larger values as malformed, whoever sent them)
MAX_STATES = 200      # states, inputs and outputs of a returned model: larger ones are almost certainly a bug
MAX_ARRAY = 100_000   # numbers in a returned array (kind "array") or model


def _write(out, nonce, **event):
    event["nonce"] = nonce
    out.write(json.dumps(event) + "\n")
    out.flush()


def _real(path):
    try:
        if isinstance(path, int):
            return None
        return os.path.realpath(os.fsdecode(path))
    except (TypeError, ValueError):
        return None


def _under(p, dirs):
    """True if the path ``p`` is one of ``dirs`` or inside one of them."""
    for d in dirs:
        try:
            if os.path.commonpath([p, d]) == d:
                return True
        except ValueError:   # different drives
            pass
    return False


class Guard:
    """The audit hook and the record of what it refused."""

    # events that start another program (which the hook could not follow)
    PROCESS_EVENTS = ("subprocess.Popen", "os.system", "os.exec", "os.posix_spawn", "os.spawn",
                      "os.fork", "os.forkpty", "pty.spawn")
    # events that change or link files
    MUTATING_EVENTS = ("os.remove", "os.rename", "os.rmdir", "os.truncate", "os.chmod", "os.chown",
                       "os.link", "os.symlink", "os.utime", "shutil.rmtree", "shutil.move")

    def __init__(self, out, nonce, blocked_dirs, protected_root, blocked_modules):
        self.out, self.nonce = out, nonce
        self.blocked = [os.path.realpath(d) for d in blocked_dirs]
        self.protected = os.path.realpath(protected_root)
        self.modules = tuple(blocked_modules)
        self.phase = None       # set while student code runs
        self._local = threading.local()   # per thread: the hook must not recurse, but other threads
                                          # must not slip through while one thread is inside it

    def _refuse(self, what):
        if self.phase is not None:
            _write(self.out, self.nonce, event="violation", phase=self.phase, what=what)
        raise PermissionError(f"blocked by the grader: {what}")

    def _check_open(self, path, flags):
        p = _real(path)
        if p is None:
            return
        if _under(p, self.blocked):
            self._refuse(f"opening {p}")
        if os.path.isdir(p) and any(_under(b, [p]) for b in self.blocked):
            self._refuse(f"opening the directory {p} (it contains the grader's files)")
        m = re.match(r"/proc/(\d+)(/|$)", p)
        if m and int(m.group(1)) != os.getpid():
            self._refuse(f"opening {p} (another process)")
        writing = isinstance(flags, int) and flags & (os.O_WRONLY | os.O_RDWR | os.O_APPEND | os.O_TRUNC)
        if writing and _under(p, [self.protected]):
            self._refuse(f"writing {p}")

    def __call__(self, event, args):
        if getattr(self._local, "busy", False):
            return
        self._local.busy = True
        try:
            if event == "open":
                self._check_open(args[0], args[2] if len(args) > 2 else None)
            elif event == "import":
                name = str(args[0])
                if any(name == m or name.startswith(m + ".") for m in self.modules):
                    self._refuse(f"importing {name}")
            elif event in ("os.listdir", "os.scandir"):
                p = _real(args[0]) if args and args[0] is not None else None
                if p is not None and _under(p, self.blocked):
                    self._refuse(f"listing {p}")
            elif event in self.MUTATING_EVENTS:
                for a in args[:2]:
                    p = _real(a) if isinstance(a, (str, bytes, os.PathLike)) else None
                    if p is not None and (_under(p, [self.protected]) or _under(p, self.blocked)):
                        self._refuse(f"{event} on {p}")
            elif event in self.PROCESS_EVENTS:
                self._refuse(f"starting a process ({event})")
            elif event in ("ctypes.dlopen", "ctypes.dlsym", "ctypes.dlsym/handle"):
                self._refuse(f"loading native code through ctypes ({event})")
        finally:
            self._local.busy = False


def _error_text(exc, sub_path, func=None):
    """One-paragraph description of an exception, keeping only the submission's frames."""
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if f.filename == sub_path]
    head = f"{type(exc).__name__}: {exc}".strip().rstrip(":")
    if isinstance(exc, SyntaxError) and exc.filename == sub_path:
        return f"{head}: `{(exc.text or '').strip()}`"
    if frames:
        f = frames[-1]
        where = f"line {f.lineno}" + (f" in {f.name}" if f.name != "<module>" else "")
        code = f": `{f.line.strip()}`" if f.line else ""
        return f"{head} ({where}{code})"
    return head


def _encode_ss(value, np, ct):
    """StateSpace / TransferFunction / (A, B, C, D) -> dict of real matrices."""
    if isinstance(value, ct.TransferFunction):
        value = ct.ss(value)
    elif isinstance(value, (tuple, list)) and len(value) == 4:
        try:
            value = ct.ss(*value)
        except Exception as exc:   # noqa: BLE001 - report any construction failure
            raise TypeError(f"the (A, B, C, D) tuple is not a valid state space: {exc}") from None
    if not isinstance(value, ct.StateSpace):
        raise TypeError(f"returned {type(value).__name__}, expected a control.StateSpace")
    mats = {}
    for name in "ABCD":
        M = np.asarray(getattr(value, name))
        if np.iscomplexobj(M):
            if np.any(M.imag != 0):
                raise TypeError(f"matrix {name} has complex entries; a physical model is real")
            M = M.real
        mats[name] = np.asarray(M, dtype=float)
    if mats["A"].shape[0] > MAX_STATES:
        raise TypeError(f"the model has {mats['A'].shape[0]} states (more than {MAX_STATES})")
    if max(mats["D"].shape) > MAX_STATES:
        raise TypeError(f"the model has {mats['D'].shape[1]} inputs and {mats['D'].shape[0]} outputs "
                        f"(more than {MAX_STATES})")
    if sum(M.size for M in mats.values()) > MAX_ARRAY:
        raise TypeError(f"the model's matrices hold more than {MAX_ARRAY} numbers")
    dt = value.dt
    return {"A": mats["A"].tolist(), "B": mats["B"].tolist(), "C": mats["C"].tolist(),
            "D": mats["D"].tolist(), "dt": None if dt is None else float(dt),
            "inputs": [str(s) for s in value.input_labels], "outputs": [str(s) for s in value.output_labels]}


def _encode_float(value, np):
    if isinstance(value, (str, bytes, bool)) or value is None:
        raise TypeError(f"returned {type(value).__name__} {value!r}, expected a float")
    arr = np.asarray(value) if not hasattr(value, "__float__") else None
    if arr is not None and arr.size != 1:
        raise TypeError(f"returned an array of shape {arr.shape}, expected a single float")
    try:
        return float(value if arr is None else arr.reshape(()))
    except (TypeError, ValueError) as exc:
        raise TypeError(f"returned {type(value).__name__}, expected a float ({exc})") from None


def _encode_array(value, np):
    """Array-like of real numbers (a tuple ``(K, M)`` of equal shapes too) -> nested lists."""
    if isinstance(value, (str, bytes, bool, dict)) or value is None:
        raise TypeError(f"returned {type(value).__name__}, expected a numpy array of numbers")
    try:
        arr = np.asarray(value)
    except Exception as exc:   # noqa: BLE001 - ragged sequences and the like
        raise TypeError(f"returned a value that is not an array of numbers ({exc})") from None
    if arr.dtype == object:
        raise TypeError("returned a ragged or mixed sequence, expected a numpy array of numbers "
                        "(are the matrices of a tuple of different sizes?)")
    if np.iscomplexobj(arr):
        if np.any(arr.imag != 0):
            raise TypeError("returned complex numbers; real numbers are expected")
        arr = arr.real
    try:
        arr = np.asarray(arr, dtype=float)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"returned {arr.dtype} entries, expected numbers ({exc})") from None
    if arr.ndim > 32:
        raise TypeError(f"returned an array with {arr.ndim} dimensions")
    if arr.size > MAX_ARRAY:
        raise TypeError(f"returned an array with {arr.size} entries (more than {MAX_ARRAY})")
    return {"shape": list(arr.shape), "data": arr.ravel().tolist()}


def _decode_arg(a, ct):
    if isinstance(a, dict) and "__ss__" in a:
        A, B, C, D = a["__ss__"]
        return ct.ss(A, B, C, D)
    return a


def serve(req, out):
    """Import the submission and run the jobs of the request ``req``, writing events to ``out``."""
    global MAX_STATES, MAX_ARRAY
    nonce = req["nonce"]
    sub_path = req["submission"]
    MAX_STATES = int(req.get("max_states", MAX_STATES))
    MAX_ARRAY = int(req.get("max_elements", MAX_ARRAY))

    # Scientific stack first: its import is not student code and should not
    # count against the submission's time.
    import warnings
    warnings.simplefilter("ignore")
    import numpy as np
    import scipy.linalg  # noqa: F401
    import control as ct
    # The library limits BLAS to one thread in D-K and the rotor solvers; its first use finds the loaded
    # BLAS through ctypes, which the guard refuses to the submission.  Made here, before the guard, later
    # uses reuse it, and a submission calling those solvers is not blocked for the library's own doing.
    from mutext.lti import blas_single_thread
    with blas_single_thread():
        pass

    # A protected module already imported (e.g. pulled in by a package
    # __init__) must not be reachable through sys.modules either.
    for name in list(sys.modules):
        if any(name == m or name.startswith(m + ".") for m in req["blocked_modules"]):
            del sys.modules[name]

    guard = Guard(out, nonce, req["blocked_dirs"], req["protected_root"], req["blocked_modules"])
    sys.addaudithook(guard)
    _write(out, nonce, event="boot")

    # import the submission as module "submission" (so `if __name__ == "__main__"` blocks stay quiet)
    import importlib.util
    _write(out, nonce, event="start", phase="import")
    guard.phase = "import"
    try:
        spec = importlib.util.spec_from_file_location("submission", sub_path)
        mod = importlib.util.module_from_spec(spec)
        sys.modules["submission"] = mod
        spec.loader.exec_module(mod)
    except BaseException as exc:   # noqa: BLE001 - SystemExit/KeyboardInterrupt from student code too
        guard.phase = None
        _write(out, nonce, event="result", phase="import", ok=False, error=_error_text(exc, sub_path))
        out.close()
        os._exit(0)
    guard.phase = None
    _write(out, nonce, event="result", phase="import", ok=True)

    for job in req["jobs"]:
        qid, fname, kind = job["id"], job["function"], job["kind"]
        _write(out, nonce, event="start", phase=qid)
        calls = []
        func = getattr(mod, fname, None)
        if not callable(func):
            calls = [{"ok": False, "error": f"the submission defines no function {fname}()"}
                     for _ in job["calls"]]
        else:
            for k, call in enumerate(job["calls"]):
                _write(out, nonce, event="call", phase=qid, index=k)
                args = [_decode_arg(a, ct) for a in call.get("args", [])]
                kwargs = {k: _decode_arg(v, ct) for k, v in call.get("kwargs", {}).items()}
                guard.phase = qid
                try:
                    value = func(*args, **kwargs)
                except NotImplementedError:
                    guard.phase = None
                    calls.append({"ok": False, "error": f"{fname}() is not implemented yet "
                                                        "(it raises NotImplementedError)"})
                    continue
                except BaseException as exc:   # noqa: BLE001
                    guard.phase = None
                    calls.append({"ok": False, "error": _error_text(exc, sub_path)})
                    continue
                guard.phase = None
                try:
                    if kind == "ss":
                        enc = _encode_ss(value, np, ct)
                    elif kind == "array":
                        enc = _encode_array(value, np)
                    else:
                        enc = _encode_float(value, np)
                except Exception as exc:   # noqa: BLE001 - a bad return value, not a grader bug
                    calls.append({"ok": False, "error": f"{fname}() {exc}" if str(exc).startswith("returned")
                                  else f"{fname}(): {exc}"})
                    continue
                calls.append({"ok": True, "value": enc})
        _write(out, nonce, event="result", phase=qid, calls=calls)
    _write(out, nonce, event="done")
    out.close()
    # threads the submission left running must not keep the process alive
    os._exit(0)

