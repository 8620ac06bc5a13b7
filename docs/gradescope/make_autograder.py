"""Build the Gradescope autograder zip of one exercise of a course.

Usage (from a checkout)::

    python docs/gradescope/make_autograder.py EXERCISE OUT.zip [--secret-file FILE]

The zip holds

* ``setup.sh`` and ``run_autograder`` (this directory) and a file ``exercise``
  naming the exercise;
* ``mutext-src/``: what installing needs and nothing else, the committed
  (``git ls-files``) files of the ``mutext`` package (``pyproject.toml``,
  ``README.md``, ``LICENSE``, ``mutext/``) and of the instructor's package
  ``mutext_grader`` (``instructor/``: reference solutions, graded inputs).
  Files git does not track are never packed (a ``diagnosis/`` written by the
  quick start, an ``answer_key.json``, an exercise not yet committed: commit
  it first); a tracked file is packed as it is in the working tree;
* ``secret``: the course secret, from which and a submission's content its
  inputs are drawn (``mutext grade --secret-file``).  Without
  ``--secret-file`` a fresh one is made (``secrets.token_hex(32)``); to grade
  several exercises or a regrade with the same secret, keep one file and pass
  it (``unzip -p OUT.zip secret > course.secret`` recovers a fresh one).

Upload the zip as the autograder of a Gradescope assignment on the Ubuntu
24.04 base image; see docs/grading.md.
"""
from __future__ import annotations

import argparse
import os
import secrets
import stat
import subprocess
import sys
import zipfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
#: what is packed of the checkout (and only the files of these git tracks)
PACKED = ("pyproject.toml", "README.md", "LICENSE", "mutext/", "instructor/")
#: never packed, tracked or not: build and run outputs
EXCLUDED_PARTS = {"__pycache__", ".pytest_cache", ".hypothesis", "build", "dist", "diagnosis", "results"}


def packed_files(repo: Path = REPO) -> list[str]:
    """The files of ``repo`` that go into the zip: tracked by git, under :data:`PACKED`, no outputs."""
    try:
        out = subprocess.run(["git", "-C", str(repo), "ls-files", "-z", "--", *PACKED], check=True,
                             capture_output=True).stdout
    except (OSError, subprocess.CalledProcessError) as exc:
        raise SystemExit(f"make_autograder: {repo} must be a git checkout (git ls-files: "
                         f"{getattr(exc, 'stderr', b'').decode(errors='replace').strip() or exc})") from None
    files = []
    for f in out.decode().split("\0"):
        parts = f.split("/")
        if not f or EXCLUDED_PARTS & set(parts[:-1]) or f.endswith((".pyc", ".egg-info")) \
                or any(p.endswith(".egg-info") for p in parts):
            continue
        if (repo / f).is_file() and not (repo / f).is_symlink():
            files.append(f)
    return files


def untracked(repo: Path = REPO) -> list[str]:
    """Files under :data:`PACKED` that git does not track and does not ignore (left out of the zip)."""
    out = subprocess.run(["git", "-C", str(repo), "ls-files", "-z", "--others", "--exclude-standard", "--",
                          *PACKED], capture_output=True).stdout
    return [f for f in out.decode().split("\0") if f]


def _importable():
    """The checkout's grader (and its mutext, if no other is installed) importable here."""
    for d in (REPO, REPO / "instructor"):
        if str(d) not in sys.path:
            sys.path.insert(0, str(d))


def new_secret() -> bytes:
    return secrets.token_hex(32).encode() + b"\n"


def build(exercise: str, out: Path, secret: bytes | None = None, repo: Path = REPO) -> Path:
    """Write the autograder zip of ``exercise`` to ``out``; return ``out``.

    ``secret`` is the course secret's content (checked as ``mutext grade --secret-file`` checks it);
    None makes a fresh one."""
    _importable()
    from mutext_grader.core import SECRET_MIN_BYTES, GradingError, get_exercise
    try:
        name = get_exercise(exercise).name
    except GradingError as exc:
        raise SystemExit(f"make_autograder: {exc}") from None
    if secret is None:
        secret = new_secret()
    if len(secret.strip()) < SECRET_MIN_BYTES:
        raise SystemExit(f"make_autograder: the course secret holds {len(secret.strip())} bytes; at least "
                         f"{SECRET_MIN_BYTES} are needed")
    files = packed_files(repo)
    if not any(f.startswith("instructor/mutext_grader/") for f in files):
        raise SystemExit(f"make_autograder: no tracked instructor/mutext_grader in {repo}")
    out = Path(out)
    tmp = out.with_name(out.name + ".part")
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)   # it holds the secret
    with os.fdopen(fd, "wb") as fh, zipfile.ZipFile(fh, "w", zipfile.ZIP_DEFLATED) as z:
        for script in ("setup.sh", "run_autograder"):
            _add(z, script, (HERE / script).read_bytes(), 0o755)
        _add(z, "exercise", (name + "\n").encode(), 0o644)
        _add(z, "secret", secret, 0o600)
        for f in files:
            p = repo / f
            _add(z, f"mutext-src/{f}", p.read_bytes(), 0o755 if p.stat().st_mode & stat.S_IXUSR else 0o644)
    os.replace(tmp, out)
    return out


def _add(z: zipfile.ZipFile, arcname: str, data: bytes, mode: int):
    info = zipfile.ZipInfo(arcname, date_time=(2020, 1, 1, 0, 0, 0))
    info.external_attr = (stat.S_IFREG | mode) << 16
    info.compress_type = zipfile.ZIP_DEFLATED
    z.writestr(info, data)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="make_autograder.py", description=__doc__.split("\n\n")[0],
                                epilog="See docs/grading.md, 'Setting up a course'.")
    p.add_argument("exercise", help="exercise name (mutext grade --list); a unique prefix such as ex03 works")
    p.add_argument("out", nargs="?", help="the zip to write (default autograder-EXERCISE.zip)")
    p.add_argument("--secret-file", metavar="FILE",
                   help="the course secret to pack (the same for every exercise and regrade of a course); "
                        "default: a fresh one")
    args = p.parse_args(argv)
    secret = None
    if args.secret_file:
        _importable()
        from mutext_grader.core import GradingError, read_secret
        try:
            read_secret(args.secret_file)
        except GradingError as exc:
            raise SystemExit(f"make_autograder: {exc}") from None
        secret = Path(args.secret_file).read_bytes()
    out = Path(args.out or f"autograder-{args.exercise}.zip")
    left = untracked()
    if left:
        print(f"make_autograder: not packed, git does not track them: {', '.join(left[:10])}"
              + (" ..." if len(left) > 10 else ""), file=sys.stderr)
    build(args.exercise, out, secret)
    if secret is None:
        print(f"make_autograder: a fresh course secret is in {out} (file 'secret'); to reuse it for other "
              f"exercises or a regrade: unzip -p {out} secret > course.secret, keep that file private, and "
              f"pass --secret-file course.secret", file=sys.stderr)
    print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
