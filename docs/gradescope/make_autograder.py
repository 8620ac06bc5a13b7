"""Build a Gradescope autograder zip for one exercise of mutext.

Usage (from a checkout)::

    python docs/gradescope/make_autograder.py ex03_free_decay [autograder-ex03.zip]

The zip holds ``setup.sh`` and ``run_autograder`` (this directory), a file
``exercise`` naming the exercise, and the package source in ``mutext-src/``
(the tracked and untracked files of the checkout, without ignored ones).
Upload it as the autograder of a Gradescope assignment on the Ubuntu 24.04
base image; see docs/grading.md.
"""
from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]


def build(exercise: str, out: Path) -> Path:
    sys.path.insert(0, str(REPO / "instructor"))
    from mutext_grader.core import GradingError, get_exercise
    try:
        name = get_exercise(exercise).name
    except GradingError as exc:
        sys.exit(f"make_autograder: {exc}")
    files = subprocess.run(["git", "-C", str(REPO), "ls-files", "-co", "--exclude-standard", "-z"],
                           check=True, capture_output=True).stdout.decode().split("\0")
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
        for script in ("setup.sh", "run_autograder"):
            info = zipfile.ZipInfo(script)
            info.external_attr = 0o755 << 16
            z.writestr(info, (HERE / script).read_bytes())
        z.writestr("exercise", name + "\n")
        for f in files:
            p = REPO / f
            if f and p.is_file() and not f.startswith(("book/_build/", ".venv/")):
                z.write(p, f"mutext-src/{f}")
    return out


if __name__ == "__main__":
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    ex = sys.argv[1]
    out = Path(sys.argv[2] if len(sys.argv) == 3 else f"autograder-{ex}.zip")
    print(build(ex, out))
