"""First code of the grader's child process: confine it, then run the submission.

Started by :mod:`mutext.grading.sandbox` as ``python -I -S -B _jail.py REQUEST``
(isolated mode, no ``site``: nothing from site-packages runs before the
confinement).  It imports only the standard library, reads the request and
the runner's source, then, in this order:

1. as root, in a new mount (and network and IPC) namespace: covers the
   grader's package, the source checkout, ``/root``, ``/home``, the
   temporary directories and the submission's own directory (its batch-mates)
   with empty read-only file systems, keeping only the Python installation
   and the child's own directories visible; a small tmpfs (bytes and files
   limited) over the scratch directory;
2. as root, drops to an unprivileged user (``nobody``, no supplementary
   groups) that owns nothing but the child's scratch directory;
3. sets ``no_new_privs`` and a Landlock ruleset (reading only the Python
   installation, the system directories and the child's directories; writing
   only its scratch directory; no TCP; no signals to processes outside);
4. a seccomp filter: no new processes (``fork``, ``vfork``, ``clone`` other
   than threads), no ``execve``, no ``ptrace``, mount or namespace changes,
   no sockets (a user's D-Bus could start programs outside), no keyrings, no
   memory outside the address-space limit (``memfd_create``, System V shared
   memory and message queues);
5. resource limits (address space, CPU time, file size, processes, core dumps).

All of these are kernel state that the Python code running afterwards can
neither see as an object nor undo.  The child then checks from the inside
that the grader's files cannot be read and that site-packages and the
grader's home cannot be written, reports what it applied and found on the
results channel (``confined`` event), adds site-packages to ``sys.path`` and runs
:mod:`mutext.grading._runner`, which imports the submission.

What can be applied depends on the machine: a plain user gets Landlock and
seccomp where the kernel has them (``isolation`` ``"landlock"``), root gets
the unprivileged user on top (``"uid"``); the parent reports ``"none"`` when
the probe could read a reference solution.
"""
from __future__ import annotations

import ctypes
import errno
import json
import os
import site
import struct
import sys

try:
    import resource
except ImportError:       # Windows
    resource = None

LINUX = sys.platform.startswith("linux")
libc = ctypes.CDLL(None, use_errno=True) if os.name == "posix" else None
if LINUX:
    libc.syscall.restype = ctypes.c_long

# --- constants (linux/sched.h, linux/mount.h, linux/prctl.h, linux/landlock.h, linux/seccomp.h) ----------
CLONE_NEWNS, CLONE_NEWNET, CLONE_NEWIPC = 0x00020000, 0x40000000, 0x08000000
CLONE_THREAD = 0x00010000
MS_RDONLY, MS_NOSUID, MS_NODEV, MS_REMOUNT, MS_BIND, MS_REC, MS_PRIVATE = 1, 2, 4, 32, 4096, 16384, 1 << 18
PR_SET_PDEATHSIG, PR_SET_NO_NEW_PRIVS, PR_SET_SECCOMP, SECCOMP_MODE_FILTER = 1, 38, 22, 2
SYS_LANDLOCK_CREATE_RULESET, SYS_LANDLOCK_ADD_RULE, SYS_LANDLOCK_RESTRICT_SELF = 444, 445, 446
LANDLOCK_CREATE_RULESET_VERSION, LANDLOCK_RULE_PATH_BENEATH = 1, 1
LL_EXECUTE, LL_WRITE_FILE, LL_READ_FILE, LL_READ_DIR = 1 << 0, 1 << 1, 1 << 2, 1 << 3
LL_TRUNCATE, LL_IOCTL_DEV = 1 << 14, 1 << 15
LL_NET_BIND_TCP, LL_NET_CONNECT_TCP = 1 << 0, 1 << 1
LL_SCOPE_ABSTRACT_UNIX_SOCKET, LL_SCOPE_SIGNAL = 1 << 0, 1 << 1
O_PATH = getattr(os, "O_PATH", 0o10000000)

#: seccomp: audit architecture and the system calls denied to the submission (EPERM; the process goes on).
#: Besides new processes, privileges and namespaces: memory the address-space limit does not count
#: (``memfd_create``, ``memfd_secret``, System V shared memory and message queues) and ``socketpair``
#: (socket buffers, and descriptors in flight that no listing of the process shows)
SECCOMP_ARCH = {
    "x86_64": (0xC000003E, {"fork": 57, "vfork": 58, "clone": 56, "clone3": 435, "execve": 59, "execveat": 322,
                            "ptrace": 101, "process_vm_readv": 310, "process_vm_writev": 311, "unshare": 272,
                            "setns": 308, "mount": 165, "umount2": 166, "pivot_root": 155, "chroot": 161,
                            "bpf": 321, "perf_event_open": 298, "io_uring_setup": 425, "userfaultfd": 323,
                            "kexec_load": 246, "init_module": 175, "finit_module": 313, "socket": 41,
                            "keyctl": 250, "add_key": 248, "request_key": 249, "socketpair": 53,
                            "memfd_create": 319, "memfd_secret": 447, "shmget": 29, "shmat": 30, "msgget": 68}),
    "aarch64": (0xC00000B7, {"clone": 220, "clone3": 435, "execve": 221, "execveat": 281, "ptrace": 117,
                             "process_vm_readv": 270, "process_vm_writev": 271, "unshare": 97, "setns": 268,
                             "mount": 40, "umount2": 39, "pivot_root": 41, "chroot": 51, "bpf": 280,
                             "perf_event_open": 241, "io_uring_setup": 425, "userfaultfd": 282,
                             "kexec_load": 104, "init_module": 105, "finit_module": 273, "socket": 198,
                             "keyctl": 219, "add_key": 217, "request_key": 218, "socketpair": 199,
                             "memfd_create": 279, "memfd_secret": 447, "shmget": 194, "shmat": 196,
                             "msgget": 186}),
}


def _check(ret, what):
    if ret < 0:
        e = ctypes.get_errno()
        raise OSError(e, f"{what}: {os.strerror(e)}")
    return ret


def _b(s):
    return None if s is None else os.fsencode(s)


def _mount(src, target, fstype, flags, data=None):
    _check(libc.mount(_b(src), _b(target), _b(fstype), ctypes.c_ulong(flags), _b(data)), f"mount {target}")


# --- 1. namespaces: hide directories, keep some paths inside them -----------------------------------------

def _cover(directory, keep):
    """Mount an empty read-only tmpfs on ``directory``; bind the paths ``keep`` (inside it) back."""
    fds = []
    for k in keep:
        try:
            fds.append((k, os.open(k, O_PATH | os.O_CLOEXEC), os.path.isdir(k)))
        except OSError:
            pass
    _mount("tmpfs", directory, "tmpfs", MS_NOSUID | MS_NODEV, "mode=0755,size=1m")
    old = os.umask(0o022)
    for k, fd, isdir in fds:
        os.makedirs(os.path.dirname(k), mode=0o755, exist_ok=True)
        if isdir:
            os.makedirs(k, mode=0o755, exist_ok=True)
        elif not os.path.exists(k):
            os.close(os.open(k, os.O_CREAT | os.O_WRONLY, 0o644))
        _mount(f"/proc/self/fd/{fd}", k, None, MS_BIND | MS_REC)
        os.close(fd)
    os.umask(old)
    _mount(None, directory, None, MS_REMOUNT | MS_RDONLY | MS_NOSUID | MS_NODEV, "mode=0755,size=1m")


def namespaces(req, applied, problems):
    """New mount/network/IPC namespaces; cover ``req["hide"]`` (``[[dir, [keep, ...]], ...]``)."""
    if libc.unshare(CLONE_NEWNS) != 0:
        problems.append(f"no mount namespace ({os.strerror(ctypes.get_errno())})")
        return
    try:
        _mount(None, "/", None, MS_REC | MS_PRIVATE)
        for directory, keep in req["hide"]:
            if os.path.isdir(directory):
                _cover(directory, keep)
        applied.append("mount-namespace")
    except OSError as exc:
        problems.append(f"mount namespace incomplete ({exc})")
    else:
        try:
            scratch_quota(req, applied)
        except OSError as exc:
            problems.append(f"no size limit on the scratch directory ({exc})")
    if libc.unshare(CLONE_NEWNET | CLONE_NEWIPC) == 0:
        applied.append("network-namespace")
    else:
        problems.append(f"no network namespace ({os.strerror(ctypes.get_errno())})")


def scratch_quota(req, applied):
    """A tmpfs of ``req["scratch"]`` bytes and files over the scratch directory (``box``), owned by the
    unprivileged user: the submission's files, deleted or not, cannot take more disk or memory than that.
    It lives in this mount namespace only and goes with it; the files the parent put into ``box`` (the
    submission) are copied onto it first."""
    quota, box = req.get("scratch"), req["box"]
    if not quota:
        return
    files = []
    for name in os.listdir(box):
        p = os.path.join(box, name)
        if os.path.isfile(p) and not os.path.islink(p):
            with open(p, "rb") as fh:
                files.append((name, fh.read(), os.stat(p).st_mode & 0o777))
    _mount("tmpfs", box, "tmpfs", MS_NOSUID | MS_NODEV,
           f"size={int(quota['bytes'])},nr_inodes={int(quota['files'])},mode=0700,"
           f"uid={int(req['uid'])},gid={int(req['gid'])}")
    for name, data, mode in files:
        fd = os.open(os.path.join(box, name), os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, mode)
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.chmod(os.path.join(box, name), mode)
    applied.append(f"scratch directory: tmpfs of {int(quota['bytes']) // 2 ** 20} MiB, "
                   f"{int(quota['files'])} files")


# --- 2. unprivileged user ---------------------------------------------------------------------------------

def drop_privileges(uid, gid):
    os.setgroups([])
    if hasattr(os, "setresuid"):
        os.setresgid(gid, gid, gid)
        os.setresuid(uid, uid, uid)
    else:   # pragma: no cover - BSD, macOS
        os.setgid(gid)
        os.setuid(uid)
    if os.getuid() != uid or os.geteuid() != uid or os.getgroups() not in ([], [gid]):
        raise OSError(errno.EPERM, "could not drop privileges")
    try:
        os.setuid(0)
    except OSError:
        return
    raise OSError(errno.EPERM, "privileges could be regained after dropping them")


# --- 3. Landlock ------------------------------------------------------------------------------------------

class _PathBeneath(ctypes.Structure):
    _pack_ = 1
    _fields_ = [("allowed_access", ctypes.c_uint64), ("parent_fd", ctypes.c_int32)]


def landlock_abi():
    abi = libc.syscall(SYS_LANDLOCK_CREATE_RULESET, None, ctypes.c_size_t(0),
                       ctypes.c_uint32(LANDLOCK_CREATE_RULESET_VERSION))
    return abi if abi > 0 else 0


def landlock(read, listing, write, abi):
    """Allow reading (and executing) ``read``, listing ``listing``, everything in ``write``; deny the rest.

    Each is a list of paths (directories or files).  No TCP (ABI 4), no
    signals or abstract sockets out of the sandbox (ABI 6).
    """
    fs_all = (1 << 13) - 1                     # ABI 1: execute ... make_sym
    if abi >= 2:
        fs_all |= 1 << 13                      # refer
    if abi >= 3:
        fs_all |= LL_TRUNCATE
    if abi >= 5:
        fs_all |= LL_IOCTL_DEV
    file_rights = LL_EXECUTE | LL_WRITE_FILE | LL_READ_FILE | (LL_TRUNCATE if abi >= 3 else 0) | (
        LL_IOCTL_DEV if abi >= 5 else 0)
    if abi >= 6:
        attr = struct.pack("QQQ", fs_all, LL_NET_BIND_TCP | LL_NET_CONNECT_TCP,
                           LL_SCOPE_ABSTRACT_UNIX_SOCKET | LL_SCOPE_SIGNAL)
    elif abi >= 4:
        attr = struct.pack("QQ", fs_all, LL_NET_BIND_TCP | LL_NET_CONNECT_TCP)
    else:
        attr = struct.pack("Q", fs_all)
    buf = ctypes.create_string_buffer(attr, len(attr))
    rfd = _check(libc.syscall(SYS_LANDLOCK_CREATE_RULESET, buf, ctypes.c_size_t(len(attr)), ctypes.c_uint32(0)),
                 "landlock_create_ruleset")
    try:
        for paths, rights in ((read, LL_EXECUTE | LL_READ_FILE | LL_READ_DIR), (listing, LL_READ_DIR),
                              (write, fs_all)):
            for p in paths:
                try:
                    fd = os.open(p, O_PATH | os.O_CLOEXEC)
                except OSError:
                    continue
                try:
                    allowed = rights if os.path.isdir(p) else rights & file_rights
                    if not allowed:
                        continue
                    rule = _PathBeneath(allowed, fd)
                    _check(libc.syscall(SYS_LANDLOCK_ADD_RULE, ctypes.c_int(rfd),
                                        ctypes.c_int(LANDLOCK_RULE_PATH_BENEATH), ctypes.byref(rule),
                                        ctypes.c_uint32(0)), f"landlock_add_rule {p}")
                finally:
                    os.close(fd)
        _check(libc.prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0), "no_new_privs")
        _check(libc.syscall(SYS_LANDLOCK_RESTRICT_SELF, ctypes.c_int(rfd), ctypes.c_uint32(0)),
               "landlock_restrict_self")
    finally:
        os.close(rfd)


# --- 4. seccomp -------------------------------------------------------------------------------------------

def _bpf_program(arch, nrs):
    """Classic BPF: deny ``nrs`` except clone() of a thread; clone3 -> ENOSYS (glibc falls back to clone)."""
    LD, JEQ, JGE, JSET, RET = 0x20, 0x15, 0x35, 0x45, 0x06
    ALLOW, DENY, NOSYS = 0x7FFF0000, 0x00050000 | errno.EPERM, 0x00050000 | errno.ENOSYS
    prog = []   # (code, jt_label, jf_label, k)
    prog.append((LD, None, None, 4))                        # arch
    prog.append((JEQ, 0, "deny", arch))
    prog.append((LD, None, None, 0))                        # nr
    if arch == 0xC000003E:
        prog.append((JGE, "deny", 0, 0x40000000))           # x32 system calls
    prog.append((JEQ, "nosys", 0, nrs["clone3"]))
    prog.append((JEQ, "clone", 0, nrs["clone"]))
    for name, nr in nrs.items():
        if name not in ("clone", "clone3"):
            prog.append((JEQ, "deny", 0, nr))
    prog.append((RET, None, None, ALLOW))
    labels = {"clone": len(prog)}
    prog.append((LD, None, None, 16))                       # args[0] (low word): clone flags
    prog.append((JSET, "allow", "deny", CLONE_THREAD))
    labels["allow"] = len(prog)
    prog.append((RET, None, None, ALLOW))
    labels["deny"] = len(prog)
    prog.append((RET, None, None, DENY))
    labels["nosys"] = len(prog)
    prog.append((RET, None, None, NOSYS))
    out = b""
    for i, (code, jt, jf, k) in enumerate(prog):
        def rel(t):
            return 0 if t in (None, 0) else labels[t] - i - 1
        out += struct.pack("HBBI", code, rel(jt), rel(jf), k)
    return out, len(prog)


def seccomp():
    machine = os.uname().machine
    if machine not in SECCOMP_ARCH:
        raise OSError(errno.ENOSYS, f"no seccomp filter for {machine}")
    code, n = _bpf_program(*SECCOMP_ARCH[machine])
    filt = ctypes.create_string_buffer(code, len(code))

    class _Prog(ctypes.Structure):
        _fields_ = [("len", ctypes.c_ushort), ("filter", ctypes.c_void_p)]
    prog = _Prog(n, ctypes.cast(filt, ctypes.c_void_p))
    _check(libc.prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0), "no_new_privs")
    _check(libc.prctl(PR_SET_SECCOMP, SECCOMP_MODE_FILTER, ctypes.byref(prog), 0, 0), "seccomp")


# --- 5. resource limits -----------------------------------------------------------------------------------

def limits(req, applied, problems):
    if resource is None:
        problems.append("no resource limits on this system")
        return
    names = {"as": "RLIMIT_AS", "cpu": "RLIMIT_CPU", "fsize": "RLIMIT_FSIZE", "nproc": "RLIMIT_NPROC",
             "core": "RLIMIT_CORE", "nofile": "RLIMIT_NOFILE"}
    for key, value in req["rlimits"].items():
        res = getattr(resource, names[key], None)
        if res is None:
            continue
        soft, hard = value if isinstance(value, list) else (value, value)
        try:
            cur_soft, cur_hard = resource.getrlimit(res)
            if cur_hard != resource.RLIM_INFINITY:
                hard = min(hard, cur_hard)
                soft = min(soft, hard)
            resource.setrlimit(res, (soft, hard))
        except (ValueError, OSError) as exc:
            problems.append(f"limit {key} not set ({exc})")
    applied.append("rlimits")


# --- probes -----------------------------------------------------------------------------------------------

def _readable(path):
    try:
        fd = os.open(path, os.O_RDONLY | os.O_CLOEXEC)
    except OSError:
        return False
    try:
        os.read(fd, 1)
        return True
    except OSError:
        return False
    finally:
        os.close(fd)


def _writable(directory, tag):
    p = os.path.join(directory, f".mutext-probe-{tag}")
    try:
        fd = os.open(p, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o600)
    except OSError:
        return False
    os.close(fd)
    try:
        os.unlink(p)
    except OSError:
        pass
    return True


def confine(req):
    """Apply everything the request asks for; return the ``confined`` event (without the nonce)."""
    applied, problems = [], []
    fatal = None
    skip = set(req.get("skip") or ())
    if req["mode"] == "root":
        if LINUX and "namespaces" not in skip:
            namespaces(req, applied, problems)
        try:
            drop_privileges(req["uid"], req["gid"])
            applied.append(f"uid {req['uid']}")
        except (OSError, AttributeError) as exc:
            fatal = f"could not switch to the unprivileged user {req['uid']}: {exc}"
    if fatal is None and LINUX:
        try:
            libc.prctl(PR_SET_PDEATHSIG, 9, 0, 0, 0)
            if os.getppid() != req["parent_pid"]:
                os._exit(70)
            _check(libc.prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0), "no_new_privs")
        except OSError as exc:
            problems.append(str(exc))
        abi = landlock_abi() if "landlock" not in skip else 0
        if abi:
            # of /proc only this process and the machine's description: not the grader's environment
            read = [p for p in req["read"] if p != "/proc"]
            if "/proc" in req["read"]:
                read += [f"/proc/{os.getpid()}", "/proc/cpuinfo", "/proc/meminfo", "/proc/stat"]
            try:
                landlock(read, req["list"], req["write"], abi)
                applied.append(f"landlock (ABI {abi})")
            except OSError as exc:
                problems.append(f"Landlock not applied ({exc})")
        else:
            problems.append("no Landlock" + (" (the kernel offers none)" if "landlock" not in skip else ""))
        try:
            if "seccomp" in skip:
                raise OSError(errno.ENOSYS, "left out")
            seccomp()
            applied.append("seccomp (no new processes)")
        except OSError as exc:
            problems.append(f"no seccomp filter ({exc})")
    elif fatal is None:
        problems.append(f"no Landlock or seccomp on {sys.platform}")
    if fatal is None:
        limits(req, applied, problems)
        for p in req["python_dirs"]:
            if not os.access(p, os.R_OK | os.X_OK):
                fatal = (f"the Python installation ({p}) cannot be read by the unprivileged user "
                         f"{req.get('uid')}; install Python where every user can read it (docs/grading.md)")
                break
    readable = [p for p in req["probe_read"] if _readable(p)]
    writable = [d for d in req["probe_write"] if _writable(d, req["nonce"][:12])]
    return {"event": "confined", "applied": applied, "problems": problems, "readable": readable,
            "writable": writable, "fatal": fatal, "uid": os.getuid() if hasattr(os, "getuid") else None}


def main(request_path):
    with open(request_path) as fh:
        req = json.load(fh)
    with open(req["runner"]) as fh:
        runner_source = fh.read()
    if req.get("results_fd") is not None:
        out = os.fdopen(req["results_fd"], "w", buffering=1)
    else:   # pragma: no cover - Windows: no descriptors to pass
        out = open(req["results_path"], "a", buffering=1)
    os.umask(0o077)
    boot = confine(req)
    boot["nonce"] = req["nonce"]
    out.write(json.dumps(boot) + "\n")
    out.flush()
    if boot["fatal"]:
        os._exit(71)
    os.chdir(req["box"])
    site.main()
    for p in req["extra_paths"]:
        if p not in sys.path:
            sys.path.append(p)
    sys.path.insert(0, req["lib"])
    namespace = {"__name__": "_mutext_runner", "__builtins__": __builtins__}
    exec(compile(runner_source, "<grader runner>", "exec"), namespace)
    namespace["serve"](req, out)


if __name__ == "__main__":
    main(sys.argv[1])
