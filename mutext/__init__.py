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
    FRF files (``read_frf``, ``write_frf``, ``read_frfs``) and, in modules of
    their own, the virtual test rig (``measure``, ``measure_rotor``, ``with_noise``).
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

The common entry points are importable from the top level, each loaded on
first use (``from mutext import hinfsyn, mu_upper, measure``; the list is
``mutext.__all__``).

The modules form layers, each importing only from its own and lower ones
(checked by ``tests/test_layering.py``): errors, jsonio and the solver seam
(``_solver``: every convex program goes to the conic solver through it, with its
options for the accuracy asked for); lti, response;
hinf, mu, frfit; dk, uncertain, rotor; mbi, rig, sysid, diagnose, hide, uff,
batch, report; examples; demos, plots, grading, commands; cli and, above all, this
facade, whose entry points are named as strings and imported on first use (the
layering test reads such registries as imports).
"""

from .errors import (IllPosedError, InfeasibleError, ModelError, MutextError,
                     SolverError)

__version__ = "0.1.0"

#: The common entry points, importable from the top level (``from mutext import hinfsyn``), with the
#: module (relative to the package) that holds each.  Each is
#: loaded on first use: ``import mutext`` stays light, and cvxpy, slycot or CasADi are imported only
#: by the modules that need them.
_ENTRY_POINTS = {
    # state space and frequency response
    "ss": ".lti", "mck_to_ss": ".lti", "lft_lower": ".lti", "lft_upper": ".lti", "freqresp": ".lti",
    "hinf_norm": ".lti", "stability": ".lti",
    "FRF": ".response", "FRFMatrix": ".response", "frequency_grid": ".response",
    "sweep_frequencies": ".response",
    # robust control
    "hinfsyn": ".hinf", "BlockStructure": ".mu", "mu_upper": ".mu", "mu_lower": ".mu", "mu_bounds": ".mu",
    "mu_sweep": ".mu", "dk_iteration": ".dk", "dgk_iteration": ".dk", "refine_controller": ".dk",
    "UncertainParameter": ".uncertain", "uncertain_mck": ".uncertain",
    # identification and fitting
    "identify": ".mbi", "wz_floor": ".mbi", "fit_frf": ".frfit", "resonances": ".frfit",
    # models, measurements, diagnosis
    "load_model": ".rotor", "loads_model": ".rotor", "read_frf": ".rig", "write_frf": ".rig",
    "read_frfs": ".rig", "measure": ".rig", "measure_rotor": ".rig", "read_uff58": ".uff",
    # (the diagnosis is ``mutext.diagnose.diagnose``: the package ``mutext.diagnose`` holds the name)
}

__all__ = ["MutextError", "ModelError", "IllPosedError", "InfeasibleError",
           "SolverError", "__version__"] + sorted(_ENTRY_POINTS)


def __getattr__(name):
    """Load an entry point of ``_ENTRY_POINTS`` from its module on first use (PEP 562)."""
    module = _ENTRY_POINTS.get(name)
    if module is None:
        raise AttributeError(f"module 'mutext' has no attribute {name!r}")
    import importlib
    value = getattr(importlib.import_module(module, __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_ENTRY_POINTS))
