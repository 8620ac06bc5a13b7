"""Exceptions raised by mutext.

Every error names the violated assumption so that a user can act on it
without reading solver internals.
"""


class MutextError(Exception):
    """Base class of all mutext errors."""


class ModelError(MutextError, ValueError):
    """A model (matrices, ports, files) is malformed or inconsistent."""


class IllPosedError(MutextError, ValueError):
    """A synthesis or analysis problem violates a mathematical assumption
    (stabilizability, detectability, well-posedness of an interconnection)."""


class InfeasibleError(MutextError):
    """A convex program (LMI) is infeasible at the requested level."""


class SolverError(MutextError, RuntimeError):
    """A numerical solver failed or returned an inaccurate answer."""


class UsageError(MutextError, ValueError):
    """A command was called wrongly (missing or conflicting arguments); the command line exits with code 2."""
