"""mutext: robust control and model-based identification, taught through a cracked rotor.

Modules
-------
lti
    State-space models from M, C, K with named ports, LFTs, star products,
    frequency responses and the H-infinity norm.
hinf
    H-infinity synthesis written as linear matrix inequalities (cvxpy + Clarabel),
    with an independent check of every controller.
examples
    The thesis examples (two-mass system, ...), shared by the book, demos,
    exercises and tests.
"""

from .errors import (IllPosedError, InfeasibleError, ModelError, MutextError,
                     SolverError)

__version__ = "0.1.0"

__all__ = ["MutextError", "ModelError", "IllPosedError", "InfeasibleError",
           "SolverError", "__version__"]
