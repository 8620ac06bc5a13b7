"""mutext: robust control and model-based identification, taught through a cracked rotor.

Modules
-------
lti
    State-space models from M, C, K with named ports, LFTs, star products,
    frequency responses and the H-infinity norm.
hinf
    H-infinity synthesis written as linear matrix inequalities (cvxpy + Clarabel),
    with an independent check of every controller.
uncertain
    Uncertain physical parameters pulled out of M, C, K models as LFTs.
mu
    Structured singular value: D / D-G upper bounds (LMI, Osborne), lower bounds.
dk
    D-K iteration (mu-synthesis) with rational D-scale fits.
mbi
    Model-based identification: the unmodeled dynamics as a mu-controller.
response
    One frequency-response type (a channel with its stations, directions,
    port names and units) for measured and modelled data, and the frequency
    grids (``frequency_grid``).
frfit
    Stable rational models of measured frequency responses (vector fitting).
rig
    Virtual test rig and FRF files.
sysid
    Parameters from free-decay records.
diagnose
    From measured FRFs to what a model gets wrong, its cause, the extended
    model and the gain on held-out data (``mutext diagnose``).
hide
    Data sets with a hidden effect (``mutext rig hide``): exercises and tests.
rotor
    Finite-element rotors, cracks, reduction and tuning (CasADi, IPOPT).
examples
    The thesis examples (two-mass, three-mass, rotor), shared by the book,
    demos, exercises and tests.

The modules form layers, each importing only from its own and lower ones
(checked by ``tests/test_layering.py``): errors, jsonio; lti, response;
hinf, mu, frfit; dk, uncertain, rotor; mbi, rig, sysid, diagnose, hide, uff,
batch, report; examples; demos, plots, grading, commands; cli.
"""

from .errors import (IllPosedError, InfeasibleError, ModelError, MutextError,
                     SolverError)

__version__ = "0.1.0"

__all__ = ["MutextError", "ModelError", "IllPosedError", "InfeasibleError",
           "SolverError", "__version__"]
