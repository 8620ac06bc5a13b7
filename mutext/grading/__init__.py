"""Offline autograder for the exercises in ``exercises/``.

``mutext grade EXERCISE SUBMISSION [--json] [--output results.json]`` scores a
student's file and prints per-question points with feedback; ``--json``
writes the Gradescope ``results.json`` schema instead (``{"score": ...,
"tests": [{"name", "score", "max_score", "output"}, ...]}``).  No network,
no containers.

How a submission is run
-----------------------
The submission is copied to a private temporary directory and imported in a
child process (:mod:`mutext.grading.sandbox`, :mod:`mutext.grading._runner`)
that only calls the student's functions on given inputs and sends back
plain matrices and numbers.  All scores are computed in the grading process
from those numbers: models are compared through their frequency responses,
a controller is closed around the reference plant here.  The importing and
each question have a wall-clock time limit; a question that hangs or
crashes scores 0 and the remaining questions run in a fresh child.

Integrity
---------
Before the submission is imported, the child installs an audit hook that
blocks opening files of :mod:`mutext.grading` (with the reference
solutions), :mod:`mutext.examples` and :mod:`mutext.demos` (and, in a source
checkout, of ``.git`` and ``tests``; for an exercise whose answer the library
computes, also that library module, e.g. :mod:`mutext.rotor` for ex04),
importing those packages, writing into
the installed package, starting processes and loading native code with
:mod:`ctypes`.
Students may use numpy, scipy, control, :mod:`mutext.lti` and
:mod:`mutext.hinf`.  A blocked attempt inside a question's function scores
that question 0; one at import time (module level) scores every question 0.
The hook keeps honest students honest and catches casual copying; it is not
a security boundary against deliberate attacks (run the grader in a
container for that).

Modules
-------
core
    Exercises, questions, :func:`grade` and reports.
sandbox
    The child process and its time limits.
compare
    Frequency-response comparison with feedback per channel.
ex01_two_mass_hinf
    Grader of the first exercise.
ex04_beam_element
    Grader of the beam-element exercise (numpy only; :mod:`mutext.rotor` is blocked).
solutions
    Reference solutions (each one a full-marks submission).
"""
from __future__ import annotations

from .core import EXERCISES, GradingError, Report, get_exercise, grade

__all__ = ["grade", "cli_grade", "Report", "GradingError", "EXERCISES", "get_exercise"]


def cli_grade(argv) -> int:
    """``mutext grade ...``; returns the exit code (0 once grading completed, 2 on misuse)."""
    from .cli import main
    return main(argv)
