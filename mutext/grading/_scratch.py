"""The child's files: measured and removed whatever their depth, names or permissions, and the parent's
watch over the disk a child uses (:class:`_Scratch`)."""
from __future__ import annotations

import os

from ._settings import SCRATCH_BYTES, SCRATCH_FILES

_DIR_FLAGS = os.O_RDONLY | getattr(os, "O_DIRECTORY", 0) | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)


class _TreeChanged(OSError):
    """A directory was moved while the tree was walked."""


def _fix_perms() -> bool:
    # as root nothing needs it (and a chmod must never follow a link the child swapped in); as the
    # child's own user, restoring the owner's rights is how the grader gets back into a chmod 000 directory
    return not (hasattr(os, "geteuid") and os.geteuid() == 0)


def _open_dir(name, dir_fd, fix):
    try:
        return os.open(name, _DIR_FLAGS, dir_fd=dir_fd)
    except PermissionError:
        if not fix or not hasattr(os, "O_PATH"):
            raise
        # through a descriptor of what is there now: a link swapped in is not followed
        pfd = os.open(name, os.O_PATH | os.O_NOFOLLOW | os.O_CLOEXEC, dir_fd=dir_fd)
        try:
            os.chmod(f"/proc/self/fd/{pfd}", 0o700)
        finally:
            os.close(pfd)
        return os.open(name, _DIR_FLAGS, dir_fd=dir_fd)


def _list_fd(fd, fix):
    if fix and (os.fstat(fd).st_mode & 0o700) != 0o700:
        os.fchmod(fd, 0o700)
    return os.listdir(fd)


def _walk_tree(top, fix=None):
    """Every entry below the directory ``top``, children before their directory, as
    ``(dir_fd, name, stat, depth)`` (``dir_fd`` is the open directory that holds ``name``, valid until the
    next step; ``depth`` 0 for entries of ``top`` itself).

    Iterative and descriptor-based: one directory is open at a time (going up through ``..``, checked to be
    the directory it came from), names are relative to it, so neither the depth of the tree (recursion,
    path length) nor links (never followed) stop or mislead it; a directory without rights for its owner
    gets them back first (see :func:`_fix_perms`).  Entries on another file system are reported, not entered.
    """
    import stat as st_
    fix = _fix_perms() if fix is None else fix
    fd = os.open(top, _DIR_FLAGS)
    try:
        here = os.fstat(fd)
        dev = here.st_dev
        ident = (here.st_dev, here.st_ino)
        names = _list_fd(fd, fix)
        stack = []          # (name, sibling names still to visit, identity) of the directories above
        while True:
            if names:
                name = names.pop()
                try:
                    est = os.stat(name, dir_fd=fd, follow_symlinks=False)
                except FileNotFoundError:
                    continue
                if st_.S_ISDIR(est.st_mode) and est.st_dev == dev:
                    try:
                        child = _open_dir(name, fd, fix)
                    except FileNotFoundError:
                        continue
                    cst = os.fstat(child)
                    if (cst.st_dev, cst.st_ino) != (est.st_dev, est.st_ino):
                        os.close(child)
                        raise _TreeChanged(f"{name} changed while the tree was walked")
                    try:
                        sub = _list_fd(child, fix)
                    except OSError:
                        os.close(child)
                        raise
                    stack.append((name, names, ident))
                    os.close(fd)
                    fd, ident, names = child, (cst.st_dev, cst.st_ino), sub
                    continue
                yield fd, name, est, len(stack)
                continue
            if not stack:
                return
            name, names, up = stack.pop()
            parent = os.open("..", _DIR_FLAGS, dir_fd=fd)
            pst = os.fstat(parent)
            if (pst.st_dev, pst.st_ino) != up:
                os.close(parent)
                raise _TreeChanged("a directory was moved while the tree was walked")
            done = os.fstat(fd)
            os.close(fd)
            fd, ident = parent, up
            yield fd, name, done, len(stack)
    finally:
        os.close(fd)


def _remove_tree(top, keep=(), fix=None) -> bool:
    """Remove ``top`` and everything in it (or, with ``keep``, everything in it but the names ``keep`` of
    its own entries); True if that was done.  Unlike :func:`shutil.rmtree`, no depth, path length or
    permissions left by the child stop it (:func:`_walk_tree`, given ``fix``)."""
    import stat as st_
    top = os.fspath(top)
    if not os.path.lexists(top):
        return True
    try:
        if os.path.islink(top) or not os.path.isdir(top):
            os.unlink(top)
            return True
        for _ in range(3):      # a tree that changed under the walk (it cannot once the child is gone)
            try:
                for dir_fd, name, est, depth in _walk_tree(top, fix):
                    if depth == 0 and name in keep:
                        continue
                    try:
                        if st_.S_ISDIR(est.st_mode):
                            os.rmdir(name, dir_fd=dir_fd)
                        else:
                            os.unlink(name, dir_fd=dir_fd)
                    except FileNotFoundError:
                        pass
                break
            except _TreeChanged:
                continue
        if not keep:
            os.rmdir(top)
        return True
    except OSError:
        return False


def _tree_use(top, max_bytes, max_files, seen=None) -> tuple:
    """``(bytes, files)`` below ``top`` (disk blocks, entries), counting stops as soon as either exceeds its
    maximum (a child's flood of files costs the grader no more than that)."""
    import stat as st_
    seen = set() if seen is None else seen
    used = files = 0
    for _fd, _name, est, _depth in _walk_tree(top):
        files += 1
        if st_.S_ISREG(est.st_mode):
            if est.st_nlink > 1:
                if (est.st_dev, est.st_ino) in seen:
                    continue
                seen.add((est.st_dev, est.st_ino))
            used += max(getattr(est, "st_blocks", 0) * 512, 0) or est.st_size
        if used > max_bytes or files > max_files:
            break
    return used, files


def _held_deleted(pid) -> int:
    """Bytes of deleted files the process ``pid`` still holds open or mapped (they take disk space that
    no listing of the directory shows)."""
    import stat as st_
    total, seen = 0, set()
    try:
        for n in os.listdir(f"/proc/{pid}/fd"):
            try:
                est = os.stat(f"/proc/{pid}/fd/{n}")
            except OSError:
                continue
            if st_.S_ISREG(est.st_mode) and est.st_nlink == 0 and (est.st_dev, est.st_ino) not in seen:
                seen.add((est.st_dev, est.st_ino))
                total += est.st_blocks * 512
        with open(f"/proc/{pid}/maps") as fh:
            for line in fh:
                if line.endswith(" (deleted)\n") and "/memfd:" not in line and "/SYSV" not in line:
                    lo, hi = line.split(None, 1)[0].split("-")
                    total += int(hi, 16) - int(lo, 16)
    except OSError:
        pass
    return total


class _Scratch:
    """The parent's watch over the disk a child uses: its scratch directory, deleted files it holds, and
    (as root, when neither a mount namespace nor Landlock kept it out of them) what the unprivileged user
    created in the shared temporary directories during the run."""

    SHARED = ("/tmp", "/var/tmp", "/dev/shm")

    def __init__(self, box, uid):
        self.box, self.uid = str(box), uid
        self.shared = uid is not None and os.name == "posix"
        self.before = {d: self._names(d) for d in self.SHARED} if self.shared else {}
        self.failures = 0
        self.others = self._others(None) if self.shared else False   # processes of the user besides ours
        self.left = []

    def _others(self, pid):
        """Does any process of the child's user run besides ``pid``?  (Then what that user created in the
        shared directories may not be the child's, and is not removed.)"""
        try:
            names = os.listdir("/proc")
        except OSError:
            return True
        for n in names:
            if n.isdigit() and int(n) != pid:
                try:
                    if os.stat(f"/proc/{n}").st_uid == self.uid:
                        return True
                except OSError:
                    pass
        return False

    @staticmethod
    def _names(d):
        try:
            return set(os.listdir(d))
        except OSError:
            return set()

    def strays(self):
        """Entries of the shared temporary directories that the child's user created during the run."""
        out = []
        for d, before in self.before.items():
            for n in self._names(d) - before:
                p = os.path.join(d, n)
                try:
                    if os.lstat(p).st_uid == self.uid:
                        out.append(p)
                except OSError:
                    pass
        return out

    def over(self, pid):
        """Why the child uses too much disk, or None."""
        try:
            seen = set()
            used, files = _tree_use(self.box, SCRATCH_BYTES, SCRATCH_FILES, seen)
            if self.shared and not self.others:
                self.others = self._others(pid)
            for p in (self.strays() if self.shared else []):
                if os.path.isdir(p) and not os.path.islink(p):
                    b, f = _tree_use(p, SCRATCH_BYTES - used, SCRATCH_FILES - files, seen)
                else:
                    est = os.lstat(p)
                    b, f = est.st_blocks * 512, 0
                used, files = used + b, files + f + 1
            used += _held_deleted(pid)
            self.failures = 0
        except OSError:
            self.failures += 1       # a tree changing all the time cannot hide from the measurement
            return (None if self.failures < 3 else
                    "its files could not be measured (they kept changing)")
        if used > SCRATCH_BYTES:
            return f"it wrote more than {SCRATCH_BYTES // 2 ** 20} MiB of files"
        if files > SCRATCH_FILES:
            return f"it created more than {SCRATCH_FILES} files and directories"
        return None

    def clean(self, keep=("submission.py",)):
        """Empty the scratch directory (but ``keep``) and remove what the child left in shared places
        (only when no other process of its user ran meanwhile; otherwise :attr:`left` lists it)."""
        ok = _remove_tree(self.box, keep=keep)
        strays = self.strays() if self.shared else []
        if strays and (self.others or self._others(None)):
            self.others = True
            self.left = sorted(set(self.left + strays))
            return False
        for p in strays:
            ok = _remove_tree(p) and ok
        return ok

