"""The instructor's autograder for the exercises in ``exercises/`` (distribution ``mutext-grader``).

This package holds what students must not have: the reference solutions,
the graded inputs and the answers computed from them.  It is not part of the
``mutext`` distribution students install (``pip install mutext`` gives them
:mod:`mutext.grading.check`, which says whether a file runs and returns
values of the right kind, never whether they are right); instructors install
it from the repository's ``instructor/`` directory
(``pip install ./instructor``) or ship it in the autograder zip
(``docs/gradescope/make_autograder.py``).

Inputs are drawn per run: in course mode (``--secret-file``) from a seed that
an HMAC of the course secret and the submission's content gives
(:func:`mutext_grader.core.input_seed`), otherwise afresh; so no table of
inputs to answers can be built from public files, and feedback names a
mistake without printing the expected value.

``mutext grade EXERCISE SUBMISSION [--json] [--output results.json]`` scores a
student's file and prints per-question points with feedback; ``--json``
writes the Gradescope ``results.json`` schema instead (``{"score": ...,
"tests": [{"name", "score", "max_score", "output"}, ...]}``).  No network,
no containers.  ``mutext grade EXERCISE DIR [--jobs N]`` grades every
``*.py`` file in a directory, each as one, and writes a results file per
submission and a class ``summary.csv`` (:mod:`mutext.grading.batch`).

How a submission is run
-----------------------
The submission is copied to a private temporary directory and imported in a
child process (:mod:`mutext.grading.sandbox`, :mod:`mutext.grading._jail`,
:mod:`mutext.grading._runner`, public: they hold no answers) that only calls the student's functions on
given inputs and sends back plain matrices and numbers (JSON, validated on
arrival).  The child holds no reference answers and no solution code; all
scores are computed in the grading process from those numbers: models are
compared through their frequency responses, a controller is closed around
the reference plant here.  The importing and each question have a
wall-clock time limit; a question that hangs or crashes scores 0 and the
remaining questions run in a fresh child.

Isolation
---------
The rules are enforced by the kernel, outside the student's interpreter:

* as root (a Gradescope or CI container), the child runs as the user
  ``nobody`` in its own mount and network namespaces, where the package,
  the source checkout, ``/root``, ``/home`` and the temporary directories
  are empty except for the Python installation and the child's own
  directory (``isolation: uid`` in the report);
* for everyone, where the kernel offers them, Landlock (read only Python,
  the system and the child's own files; write only its directory; no TCP)
  and a seccomp filter (no new processes); a plain user gets
  ``isolation: landlock``;
* resource limits: memory (address space), CPU time, file size, processes.

The child checks from the inside that it cannot read the solutions nor
write into site-packages; if it can, or nothing could be applied (macOS,
an old kernel), the report says ``isolation: none``.  Grade a course as root
in a container (``docs/grading.md``).

Before the submission is imported the child also installs an audit hook
that reports the usual attempts (importing ``mutext.grading``,
``mutext.examples``, ``mutext.demos`` or an exercise's blocked module such
as :mod:`mutext.rotor` for ex04, opening their files, starting processes,
loading native code with :mod:`ctypes`) as integrity violations: one inside
a question's function scores that question 0, one at import time every
question.  Students may use numpy, scipy, control, :mod:`mutext.lti` and
:mod:`mutext.hinf`.  The hook only names the attempt; what blocks it is the
isolation above.

Modules
-------
core
    Exercises, questions, :func:`grade` and reports.
sandbox
    The child process, its isolation and its time limits.
compare
    Frequency-response comparison with feedback per channel.
batch
    A directory of submissions: results per file, ``summary.csv``, parallel workers.
ex01_two_mass_hinf
    Grader of the first exercise.
ex04_beam_element
    Grader of the beam-element exercise (numpy only; :mod:`mutext.rotor` is blocked).
solutions
    Reference solutions (each one a full-marks submission).
"""
from __future__ import annotations

from .core import EXERCISES, GradingError, Report, get_exercise, grade, input_seed, read_secret

__all__ = ["grade", "cli_grade", "Report", "GradingError", "EXERCISES", "get_exercise", "read_secret",
           "input_seed"]


def cli_grade(argv) -> int:
    """``mutext grade ...``; returns the exit code (0 once grading completed, 2 on misuse)."""
    from .cli import main
    return main(argv)
