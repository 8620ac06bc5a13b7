"""Not an exercise submission: ``probe()`` tries one escape after another from the grading child.

It returns one number per attempt: 1 if the attempt worked, 0 if it was
refused (the order is ``ATTEMPTS``).  The child's audit hook is switched off
first, so that every refusal comes from the confinement.  Used by
tests/test_grading_hostile.py through ``run_submission``.
"""
import gc
import os
import socket

ATTEMPTS = ["read the solution", "list the solutions", "read the grader's core.py", "read the checkout's .git",
            "write site-packages", "write the grader's home", "write /tmp", "write the package",
            "signal the grader", "read the grader's environ", "open the grader's memory", "fork",
            "connect over TCP", "open a Unix socket", "become root again",
            # these must work (the child's own directory and the staged library)
            "write the working directory", "import mutext.lti"]


def _disarm():
    for o in gc.get_objects():
        if type(o).__name__ == "Guard":
            o.blocked, o.modules, o.phase, o.protected = [], (), None, "/nonexistent"
            o._local.busy = True


def _read(path):
    with open(path, "rb") as fh:
        fh.read(1)


def _write(path):
    with open(path, "w") as fh:
        fh.write("# probe\n")
    os.unlink(path)


def _fork():
    pid = os.fork()
    if pid == 0:
        os._exit(0)
    os.waitpid(pid, 0)


def _connect():
    try:
        socket.create_connection(("127.0.0.1", 9), timeout=2).close()
    except ConnectionRefusedError:
        return          # the network was reachable: nothing listens on port 9
    except OSError:
        raise


def _setuid():
    os.setuid(0)
    if os.getuid() != 0:
        raise OSError("not root")


def _lti():
    import mutext.lti  # noqa: F401


def probe(solution, grader_dir, checkout, site_packages, home, package):
    _disarm()
    ppid = os.getppid()
    tries = [lambda: _read(solution), lambda: os.listdir(os.path.dirname(solution)),
             lambda: _read(os.path.join(grader_dir, "core.py")),
             lambda: _read(os.path.join(checkout, ".git", "HEAD")),
             lambda: _write(os.path.join(site_packages, "zz_mutext_probe.pth")),
             lambda: _write(os.path.join(home, "zz_mutext_probe")), lambda: _write("/tmp/zz_mutext_probe"),
             lambda: _write(os.path.join(package, "zz_mutext_probe.py")),
             lambda: os.kill(ppid, 0), lambda: _read(f"/proc/{ppid}/environ"),
             lambda: open(f"/proc/{ppid}/mem", "rb").close(), _fork, _connect,
             lambda: socket.socket(socket.AF_UNIX, socket.SOCK_STREAM).close(), _setuid,
             lambda: _write("zz_probe_here"), _lti]
    out = []
    for t in tries:
        try:
            t()
            out.append(1.0)
        except Exception:   # noqa: BLE001 - any refusal
            out.append(0.0)
    return out
