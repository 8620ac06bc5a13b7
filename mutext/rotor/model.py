r"""Model files (TOML): rotors on bearings, and lumped mass-spring-damper chains.

A model file is read with :func:`load_model` and becomes a
:class:`~mutext.rotor.assembly.Rotor` or a
:class:`~mutext.rotor.assembly.Structure` (lumped chain).  Numbers are SI
unless the top-level key ``units = "inch-pound"`` says otherwise (then: in,
lb (mass), lb in^2, lb/in^3, psi, lbf/in, lbf s/in, lbf/A; see
:mod:`mutext.rotor.units`).  A station table file keeps its own fixed
inch-pound units (:mod:`mutext.rotor.table`) whatever ``units`` says.

Rotor files
-----------
.. code-block:: toml

    name = "thesis healthy rotor"
    units = "SI"                 # or "inch-pound"
    planes = 2                   # 2: both bending planes + gyroscopics; 1: x-z plane
    speed_rpm = 600              # or speed = 62.83 (rad/s); default 0

    [shaft]
    station_table = "rotor_healthy.txt"   # path relative to this file
    poisson_ratio = 0.3                   # or shear_modulus = ... (the table has neither)
    ports_from_flags = true               # table flags -> ports F<s>, x<s>, M<s>, psi<s>

    # ... or inline stations instead of station_table (length = element to the next station):
    # [[station]]
    # length = 0.25
    # outer_diameter = 0.05
    # inner_diameter = 0.0        # optional
    # youngs_modulus = 211e9
    # density = 7810
    # shear_modulus = 81.2e9      # optional; else [shaft] poisson_ratio / shear_modulus
    # added_mass = 0.0            # optional, also added_polar_inertia, added_transverse_inertia
    # force_input = false         # optional port flags: force_input, displacement_output,
    #                             #   moment_input, rotation_output

    [[disk]]                      # mass, polar_inertia, transverse_inertia ... or geometry:
    station = 3                   # width, outer_diameter, inner_diameter, density
    width = 0.07
    outer_diameter = 0.28
    inner_diameter = 0.05
    density = 7810

    [[bearing]]
    station = 2
    stiffness = 1.0e7             # N/m; stiffness_y for anisotropic bearings
    damping = 0.0                 # N s/m; damping_y
    kxy = 0.0                     # N/m, optional, either sign: cross-coupled stiffness, force in x
    kyx = 0.0                     #   per displacement in y (kyx: y per x); planes = 2 only.  The
                                  #   bearing's force is f = -K (u, v), K = [[k, kxy], [kyx, k_y]];
                                  #   kxy = -kyx = q > 0 (seals, fluid films) drives forward whirl

    [[exciter]]
    station = 12
    force_per_ampere = 40.0       # N/A
    negative_stiffness = 0.0      # N/m (magnetic actuator), optional
    name = "i12"                  # input name, optional; direction = "x" optional

    [[force]]                     # force input (N) named F<station>[y] unless name given
    station = 5

    [[sensor]]                    # displacement output (m) named x<station> / y<station>
    station = 13
    direction = "x"

    [damping]
    modal = 0.01                  # same ratio in every mode ... or alpha = ..., beta = ...
                                  # (proportional: see "Damping" below)

    [[crack]]                     # needs mutext.rotor.crack
    station = 15
    depth_ratio = 0.4
    perpendicular = true          # optional, default true: both bending compliances (c55, c44);
                                  # false: c55 only, the one-compliance (hinge) model
    breathing = "mayes"           # optional: the crack turns with the shaft; orientation = its angle
                                  # at t = 0 [rad].  "gaping" (also "open", "notch"): always open,
                                  # stiffness varying at 2x only (a slot whose faces never touch);
                                  # "mayes", "gasch": opens and closes under weight (1x, 2x, 3x ...);
                                  # "auto": chosen from slot_width [m] (gap between the faces at rest,
                                  # 0 for a fatigue crack) against the faces' movement under the
                                  # rotor's weight (mutext.rotor.crack.choose_breathing; closing_law =
                                  # "mayes" (default) or "gasch" when they touch).  The choice and why:
                                  # rotor.breathing_choices[name].  Time-invariant analyses use the
                                  # revolution average; the time-periodic rotor is mutext.rotor.periodic

Lumped chains
-------------
.. code-block:: toml

    name = "three-mass rig"
    [[mass]]
    name = "m1"
    mass = 2.8113
    [[spring]]
    name = "k1"
    stiffness = 842.3
    between = ["m1", "m2"]        # or ["m3", "ground"]
    [[damper]]
    name = "c1"
    damping = 5.2992
    between = ["m1", "ground"]
    [[force]]
    name = "f1"
    mass = "m1"
    [[sensor]]
    name = "x1"
    mass = "m1"
    [[impedance]]                 # a rational dynamic stiffness K(s) to ground at a mass (optional)
    name = "K_m2"
    mass = "m2"
    numerator = [0.5, 40.0, 900.0]    # coefficients of s^2, s, 1: K(s) in N/m
    denominator = [1.0, 20.0]         # coefficients of s, 1 (degree >= the numerator's)

``[[impedance]]`` applies the force :math:`-K(s)\,x` to its mass
(:class:`~mutext.rotor.lumped_elements.Impedance`): the frequency response
adds :math:`K(j\omega)` to the dynamic stiffness and the state space gains
its states.  It is how :mod:`mutext.diagnose` writes what model-based
identification found when that is not a mass, a damper and a spring.  It has
no tunable parameter; undamped modes and tuning refuse a model that holds one.
In an inch-pound file :math:`K` is in lbf/in (the numerator is converted).

Damping
-------
``[damping] modal = z`` gives every mode of the undamped structure the damping
ratio *z* (:class:`~mutext.rotor.assembly.ModalDamping`, recomputed from the
modes of the model as built, added elements included).

``[damping] alpha = a, beta = b`` is proportional damping
(:class:`~mutext.rotor.elements.StructuralDamping`): :math:`C \mathrel{+}=
\alpha M + \beta K_s`.  ``alpha`` [1/s] multiplies the whole mass matrix;
``beta`` [s] multiplies :math:`K_s`, the stiffness of the structure's own
members only -- the shaft elements and the cracks in them (rotors), the
springs between two masses (lumped chains).  The connections to ground --
``[[bearing]]``, ``[[exciter]]`` (its negative stiffness) and a ``[[spring]]``
with one end on ``"ground"`` -- carry only the damping they are given (a
bearing's ``damping``, a ``[[damper]]``): a grounded spring or bearing added
to the file, e.g. ``damping = 0.0`` by :mod:`mutext.diagnose`, leaves the
damping matrix unchanged.  (A structural spring to ground that should share
the material damping needs its own ``[[damper]]``, of value
:math:`\beta k`.)  A mode of a structure without such connections gets
:math:`\zeta = \alpha/(2\omega) + \beta\omega/2`; with them the
:math:`\beta` term is about :math:`\beta\omega/2` times the share of the
mode's strain energy stored in the members.

The parameter of a lumped element is called by the element's name (``"m1"``,
``"k1"``, ``"c1"``).  In rotors: ``"E"`` and ``"rho"`` (one each when all
shaft elements share the value, else ``"shaft<s>.E"``), ``"nu"`` or ``"G"``,
``"shaft<s>.L"``, ``".do"``, ``".di"``, ``"disk<s>.m"``, ``".Ip"``, ``".Id"``,
``"bearing<s>.k"``, ``".c"`` (``".kyy"``, ``".cyy"``, ``".kxy"``, ``".kyx"`` when given),
``"exciter<s>.ki"``, ``".kx"``; proportional damping: ``"damping.alpha"``, ``"damping.beta"``.

Errors name the file, the table (``[[bearing]] #2``) and key, and the problem.
"""
from __future__ import annotations

import os
import tomllib

from ..errors import ModelError
from . import units as U
# the reader: shared checks and keys, rotors, lumped chains
from ._model_ctx import DEFAULT_POISSON_RATIO, _Ctx
from ._model_lumped import _load_lumped
from ._model_rotor import _load_rotor, rotor_from_table

__all__ = ["load_model", "loads_model", "rotor_from_table", "DEFAULT_POISSON_RATIO"]


# ---------------------------------------------------------------------------
# entry points
# ---------------------------------------------------------------------------

def loads_model(text: str, *, source: str = "<string>", base_dir: str = ".", station_table=None):
    """Build a model from TOML text (see the module docstring).

    Parameters
    ----------
    text : str
        The model file's contents (TOML): a rotor (``[shaft]`` or
        ``[[station]]`` tables) or a lumped chain (``[[mass]]`` tables).
    source : str, optional
        Name of the text in error messages (a file name).
    base_dir : str, optional
        Directory against which a station-table path in the text is resolved.
    station_table : str, path-like or StationTable, optional
        Use this station table instead of the one the text names.

    Returns
    -------
    Rotor or Structure

    Raises
    ------
    ModelError
        Invalid TOML, or a table or field that breaks the format's rules
        (named with its table and key).

    Examples
    --------
    >>> from mutext.rotor import loads_model
    >>> chain = loads_model('''
    ... [[mass]]
    ... name = "m1"
    ... mass = 1.0
    ... [[spring]]
    ... name = "k1"
    ... between = ["m1", "ground"]
    ... stiffness = 100.0
    ... ''')
    >>> chain.natural_frequencies().round(4)            # sqrt(100 / 1) / 2 pi Hz
    array([1.5915])
    """
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(f"{source}: not valid TOML: {exc}") from None
    system = doc.get("units", "SI")
    if system not in U.SYSTEMS:
        raise ModelError(f"{source}: units: expected one of {sorted(U.SYSTEMS)}, got {system!r}")
    ctx = _Ctx(source, system)
    rotor_keys = {"shaft", "station"} & set(doc)
    lumped_keys = {"mass", "spring", "damper"} & set(doc)
    if rotor_keys and lumped_keys:
        raise ctx.err("top level", f"mixes rotor tables ({', '.join(sorted(rotor_keys))}) and lumped tables "
                      f"({', '.join(sorted(lumped_keys))})")
    if lumped_keys:
        if station_table is not None:
            raise ctx.err("top level", "station_table given for a lumped model")
        return _load_lumped(ctx, doc)
    if rotor_keys or station_table is not None:
        return _load_rotor(ctx, doc, base_dir, station_table)
    raise ctx.err("top level", "neither a rotor ([shaft] or [[station]]) nor a lumped chain ([[mass]])")


def load_model(path: str | os.PathLike, *, station_table: str | os.PathLike | None = None):
    """Read a model file (TOML) and build a :class:`Rotor` or lumped :class:`Structure`.

    Parameters
    ----------
    path : path-like
        The model file.
    station_table : path-like, optional
        Use this station table instead of the one the file names (e.g. the
        cracked rotor's table with the healthy rotor's bearings and exciter).

    Examples
    --------
    The three-mass rig shipped with the package (a lumped chain):

    >>> from mutext.rotor import data_path, load_model
    >>> rig = load_model(data_path("three_mass.toml"))
    >>> rig.dof_names, rig.input_names, rig.output_names
    (['m1', 'm2', 'm3'], ['f1', 'f3'], ['x1', 'x3'])
    >>> rig.natural_frequencies().round(3)              # Hz
    array([0.952, 3.12 , 4.919])
    """
    path = os.fspath(path)
    try:
        with open(path, "rb") as fh:
            raw = fh.read()
    except OSError as exc:
        raise ModelError(f"cannot read model file '{path}': {exc.strerror}") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise ModelError(f"{path}: not UTF-8 text") from None
    return loads_model(text, source=path, base_dir=os.path.dirname(os.path.abspath(path)),
                       station_table=station_table)
