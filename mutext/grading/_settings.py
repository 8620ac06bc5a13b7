"""Fixed settings of the sandbox: where the package and the child's programs are, and the limits put on
a child (re-exported by :mod:`mutext.grading.sandbox`)."""
from __future__ import annotations

from pathlib import Path

RUNNER = Path(__file__).with_name("_runner.py")
JAIL = Path(__file__).with_name("_jail.py")
PACKAGE_ROOT = Path(__file__).resolve().parents[1]          # .../mutext
#: a source checkout (its git history and tests hold answers too), or None for an installed package
CHECKOUT = PACKAGE_ROOT.parent if (PACKAGE_ROOT.parent / "pyproject.toml").is_file() else None
#: parts of the package never copied into the child's ``lib`` (``data`` holds the rig's parameters)
UNSTAGED = ("grading", "examples", "demos", "data")
#: time allowed for the child to start Python and import numpy/scipy/control
STARTUP_LIMIT = 120.0
#: bytes a child may write to any file (guards the disk against print loops)
FILE_SIZE_LIMIT = 64 * 2 ** 20
#: address space of a child (guards the machine against runaway allocations)
MEMORY_LIMIT = 3 * 2 ** 30
#: processes and threads of the unprivileged user (a fork bomb stops here even without seccomp)
PROCESS_LIMIT = 64
#: bytes and files (inodes) of the child's scratch directory in all (a tmpfs of this size in the root
#: child's mount namespace; elsewhere the parent measures the directory and stops a child beyond it)
SCRATCH_BYTES = 256 * 2 ** 20
SCRATCH_FILES = 10_000
#: seconds between two measurements of the scratch directory by the parent (where no tmpfs limits it)
SCRATCH_CHECK_INTERVAL = 1.0
#: states (and inputs, outputs) of a returned model, and numbers in a returned array or model: the
#: parent rejects larger values before any computation (the child enforces the same limits)
MAX_STATES = 200
MAX_ELEMENTS = 100_000
#: other ``*.py`` files of the submission's own directory the child's probe tries to read
BATCH_PROBES = 20
#: directories a root child never sees (covered by empty file systems), besides the package and checkout
HIDDEN_DIRS = ("/root", "/home", "/autograder", "/srv", "/mnt", "/media", "/opt", "/var/tmp", "/dev/shm", "/run")
#: system directories a Landlock-confined child may read
SYSTEM_DIRS = ("/usr", "/lib", "/lib32", "/lib64", "/libx32", "/bin", "/sbin", "/etc", "/proc", "/sys")
