"""Running a student's file confined, and checking it locally.

The grader itself (reference solutions, graded inputs, answers and scores)
is the instructor's distribution ``mutext-grader`` (package
``mutext_grader``, in the repository's ``instructor/`` directory); it is not
installed with ``mutext``, so nothing a student installs holds an answer.
What is here is public:

sandbox, _jail, _runner
    The confined child process that imports a submission and calls its
    functions (kernel isolation: user switch, mount namespace, Landlock,
    seccomp, resource limits), used by the grader.
spec
    The public description of every exercise: its functions, the kind and
    shape of value each returns, the points, the modules it blocks, and
    plausible sample inputs drawn afresh (never the graded ones).
check
    ``mutext check EXERCISE FILE``: runs a student's file confined, on
    sample inputs of :mod:`.spec`, and says per function whether it runs,
    raises, times out, or returns a value of the wrong kind or shape. It
    never computes or prints a reference value or a score; whether the
    values are right is for the instructor's grader to say.
"""
from __future__ import annotations

__all__ = ["cli_grade", "CheckReport", "CheckError", "EXERCISES"]

# the function is ``mutext.grading.check.check`` (the name ``check`` here is its module)
_LAZY = {"CheckReport": ".check", "CheckError": ".check", "EXERCISES": ".spec"}


def __getattr__(name):
    # imported on first use: the grader needs only the sandbox
    if name in _LAZY:
        import importlib
        return getattr(importlib.import_module(_LAZY[name], __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def cli_grade(argv) -> int:
    """``mutext grade ...``: the instructor's grader if it is installed, else a pointer to ``mutext check``.

    Parameters
    ----------
    argv : list of str
        The command line after ``grade``.
    """
    import sys
    try:
        from mutext_grader import cli_grade as grader_cli
    except ImportError:
        print("mutext grade: the grader is the instructor's package (mutext-grader: reference solutions and "
              "graded inputs), which is not installed with mutext.\n"
              "  students: check that your file runs and returns the right kinds of values with\n"
              "            mutext check EXERCISE FILE   (mutext check --list shows the exercises)\n"
              "  instructors: pip install ./instructor from the mutext repository (docs/grading.md)",
              file=sys.stderr)
        return 2
    return grader_cli(argv)
