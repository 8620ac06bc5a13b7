"""Hostile: take the grading machine's memory and disk outside the child's limits, then forge an
oversize result.

Each question raises an error that says how far it got (the feedback shows it):

* (a1) 56 memfds of 64 MiB each, written (memory the address-space limit does not count);
* (a2) System V shared memory (``shmget``), a message queue (``msgget``), a ``socketpair``;
* (b1) up to 20,000 nested directories (for 3 s), each made unreadable (a recursive cleanup dies on
  them);
* (b2) 1 GiB in files of 60 MiB, every other one deleted but held open (invisible to a listing);
* (c)  30,000 empty files;
* (d)  a forged result for (d) on the results channel: an array of 1,000,000 numbers.

tests/test_grading_resources.py grades it as root and as a plain user: every question scores 0,
the grader's memory and time stay bounded, and nothing is left in /tmp, /var/tmp or /dev/shm."""
import ctypes
import errno
import gc
import json
import os
import socket
import time


def _disarm():
    for o in gc.get_objects():
        if type(o).__name__ == "Guard":
            o.blocked, o.modules, o.phase, o.protected = [], (), None, "/nonexistent"
            o._local.busy = True


_disarm()
HELD = []          # descriptors kept open for the child's lifetime


def natural_frequency(t, y, cycles):
    n, why = 0, "all created"
    block = b"\x01" * 2 ** 20
    for _ in range(56):
        try:
            fd = os.memfd_create("hold")
        except OSError as exc:
            why = f"memfd_create: {exc}"
            break
        HELD.append(fd)
        for _ in range(64):
            os.write(fd, block)
        n += 1
    raise RuntimeError(f"memfd flood: {n} of 56 memfds of 64 MiB held ({why})")


def damping_ratio(t, y, cycles):
    libc = ctypes.CDLL(None, use_errno=True)
    out = []
    shm = libc.shmget(0, 2 ** 30, 0o1600)          # IPC_PRIVATE, IPC_CREAT | 0600, 1 GiB
    out.append(f"shmget {'worked' if shm >= 0 else errno.errorcode.get(ctypes.get_errno())}")
    if shm >= 0:
        libc.shmctl(shm, 0, None)                   # IPC_RMID: do not leave it on a test machine
    msq = libc.msgget(0, 0o1600)
    out.append(f"msgget {'worked' if msq >= 0 else errno.errorcode.get(ctypes.get_errno())}")
    if msq >= 0:
        libc.msgctl(msq, 0, None)
    try:
        HELD.extend(s.detach() for s in socket.socketpair())
        out.append("socketpair worked")
    except OSError as exc:
        out.append(f"socketpair {errno.errorcode.get(exc.errno)}")
    raise RuntimeError("System V memory: " + ", ".join(out))


def cart_mass(omega_bare, omega_weighted, m_w):
    fd = os.open(".", os.O_RDONLY | os.O_DIRECTORY)
    depth, why, t0 = 0, "all created", time.monotonic()
    try:
        for depth in range(20_000):
            if time.monotonic() - t0 > 3.0:      # Landlock makes each level slower than the last
                why = "stopped after 3 s"
                break
            os.mkdir("d", dir_fd=fd)
            sub = os.open("d", os.O_RDONLY | os.O_DIRECTORY, dir_fd=fd)
            if depth:
                os.fchmod(fd, 0)
            os.close(fd)
            fd = sub
        depth += 1
    except OSError as exc:
        why = str(exc)
    raise RuntimeError(f"deep tree: {depth} nested directories ({why})")


def stiffness(omega_bare, m_c):
    written, why = 0, "all written"
    block = b"\x02" * 2 ** 20
    try:
        for i in range(17):
            fd = os.open(f"big{i}", os.O_WRONLY | os.O_CREAT, 0o600)
            if i % 2:
                os.unlink(f"big{i}")
                HELD.append(fd)
            for _ in range(60):
                os.write(fd, block)
                written += 1
            if not i % 2:
                os.close(fd)
    except OSError as exc:
        why = str(exc)
    raise RuntimeError(f"big files: {written} MiB written ({why})")


def damping_coefficient(zeta, m_c, omega):
    n, why = 0, "all created"
    os.makedirs("many", exist_ok=True)
    try:
        for n in range(30_000):
            os.close(os.open(f"many/f{n}", os.O_WRONLY | os.O_CREAT, 0o600))
        n += 1
    except OSError as exc:
        why = str(exc)
    raise RuntimeError(f"small files: {n} created ({why})")


def _channel():
    for o in gc.get_objects():
        if isinstance(o, dict) and "nonce" in o and "results_fd" in o:
            return o["nonce"], o["results_fd"]
    raise RuntimeError("no channel")


def identify_cart(t_bare, y_bare, t_w, y_w, m_w):
    nonce, fd = _channel()
    n = 1_000_000
    value = {"shape": [n], "data": [0] * n}
    line = json.dumps({"event": "result", "phase": "d", "nonce": nonce,
                       "calls": [{"ok": True, "value": value}]}) + "\n"
    os.write(fd, line.encode())
    return (0.8, 840.0, 5.3)
