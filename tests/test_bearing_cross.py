"""A bearing's cross-coupled stiffness: the model file's kxy/kyx, and the diagnosis kind that finds it.

Default run: the [[bearing]] keys read, written and read back, the sign convention (force = -K q, kxy
the x-y entry of the bearing block), bad values named; the hypothesis at every bearing of a two-plane
rotor; its change of dynamic stiffness against the model file's own (the extended file read back, its
matrices' difference).  Slow: the hidden effect found on two-plane data of the plain
rotor of tests/rotor_plain.py (written apart from mutext.rotor), the extended model read back and
compared with the data's response.
"""
from __future__ import annotations

import math
import os
import time
import tomllib

import numpy as np
import pytest

from mutext.diagnose import diagnose
from mutext.diagnose._extend import extended_model_text
from mutext.diagnose._hypotheses import hypotheses
from mutext.diagnose._result import Finding
from mutext.diagnose.faults import bearing_cross
from mutext.diagnose.faults._base import local_change
from mutext.errors import ModelError
from mutext.hide import example_path
from mutext.rig import Noise, measure, sweep_frequencies, write_frf
from mutext.rotor import load_model
from mutext.rotor.model import loads_model
from mutext.rotor.model_writer import ModelFile
from mutext.rotor.units import to_si

# a small two-plane rotor (inline stations), bearings at both ends, spinning
ROTOR = """name = "small rotor"
planes = 2
speed_rpm = 600
[shaft]
shear_modulus = 81.2e9
""" + "".join("""
[[station]]
length = 0.25
outer_diameter = 0.05
youngs_modulus = 211e9
density = 7810
""" for _ in range(4)) + """
[[station]]
[[disk]]
station = 3
mass = 8.0
[[bearing]]
station = 1
stiffness = 1e6     # N/m, left
damping = 20.0
[[bearing]]
name = "right"
station = 5
stiffness = 2e6     # N/m, right
damping = 0.0
[[force]]
station = 3
[[force]]
station = 3
direction = "y"
[[sensor]]
station = 3
[[sensor]]
station = 3
direction = "y"
[damping]
modal = 0.01
"""


def _bearing(text, **keys):
    """ROTOR with ``keys`` added to the right bearing's entry."""
    extra = "".join(f"\n{k} = {v}" for k, v in keys.items())
    out = text.replace('name = "right"', 'name = "right"' + extra)
    assert out != text
    return out


def _block(model, station):
    K = model.matrices()[2]
    u, v = model.layout.dof(station, "u"), model.layout.dof(station, "v")
    return K[np.ix_([u, v], [u, v])]


def _frf(station, out_dir, in_dir="x"):
    f = np.array([20.0, 40.0])
    return measure(lambda w: np.full(w.size, 1e-6 + 0j), 0, 0, f, input_station=3, output_station=station,
                   input_direction=in_dir, output_direction=out_dir)


def test_kxy_kyx_are_read_signed_and_written_back():
    model0 = loads_model(ROTOR, source="small.toml")
    model = loads_model(_bearing(ROTOR, kxy=3.0e4, kyx=-1.0e4), source="small.toml")
    el = next(e for e in model.elements if e.name == "right")
    assert (el.nominal("kxy"), el.nominal("kyx")) == (3.0e4, -1.0e4)
    assert "right.kxy" in model.parameter_names and "right.kyx" in model.parameter_names
    # force = -K q: kxy is the (u, v) entry of the bearing block, kyx the (v, u) one
    dK = _block(model, 5) - _block(model0, 5)
    assert np.array_equal(dK, [[0.0, 3.0e4], [-1.0e4, 0.0]])
    # the rest of the stiffness matrix is untouched
    D = model.matrices()[2] - model0.matrices()[2]
    assert np.count_nonzero(D) == 2
    # written by the model writer, read back bit for bit, comments kept
    mf = ModelFile(ROTOR, "small.toml")
    sel = lambda t: t.get("name") == "right"               # noqa: E731
    assert mf.set("bearing", sel, "kxy", -2.5e4, "cross") is None
    mf.set("bearing", sel, "kyx", 7.0e3, "cross")
    out = mf.text()
    assert "# N/m, right" in out
    back = loads_model(out, source="back")
    assert np.array_equal(_block(back, 5) - _block(model0, 5), [[0.0, -2.5e4], [7.0e3, 0.0]])
    assert tomllib.loads(out)["bearing"][1]["kxy"] == -2.5e4


def test_undamped_modes_keep_the_circulatory_part():
    """Without damping and rotation the modes are not those of the symmetric part of K: a skew
    cross-coupling splits each pair into a decaying and a growing whirl (flutter)."""
    t = (ROTOR.replace("speed_rpm = 600", "speed_rpm = 0").replace("[damping]\nmodal = 0.01\n", "")
         .replace("damping = 20.0", "damping = 0.0"))
    m = loads_model(_bearing(t, kxy=2.0e5, kyx=-2.0e5), source="undamped")
    M, _, K, _ = m.matrices()
    n = M.shape[0]
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), np.zeros((n, n))]])
    lam = np.linalg.eigvals(A)
    lam = lam[lam.imag > 0]
    lam = lam[np.argsort(lam.imag)][:4]
    ev = m.modes().eigenvalues[:4]
    assert np.allclose(np.sort_complex(ev), np.sort_complex(lam), rtol=1e-9)
    assert max(ev.real) > 0 > min(ev.real)


def test_bad_cross_coupling_values_are_named():
    with pytest.raises(ModelError, match=r"\[\[bearing\]\] #2, kxy.*finite number"):
        loads_model(_bearing(ROTOR, kxy='"stiff"'), source="small.toml")
    with pytest.raises(ModelError, match=r"\[\[bearing\]\] #2, kyx.*finite number"):
        loads_model(_bearing(ROTOR, kyx="nan"), source="small.toml")
    with pytest.raises(ModelError, match=r"\[\[bearing\]\] #2, kxy.*planes = 2"):
        loads_model(_bearing(ROTOR.replace("planes = 2", "planes = 1"), kxy=1.0), source="small.toml")
    with pytest.raises(ModelError, match=r"\[\[bearing\]\] #2.*unknown key 'k_xy'"):
        loads_model(_bearing(ROTOR, k_xy=1.0), source="small.toml")


def test_offered_at_every_bearing_of_a_two_plane_rotor():
    model = loads_model(ROTOR, source="small.toml")
    found = lambda m, frfs=None: [(h.station, h.element, tuple(h.dofs)) for h in hypotheses(m, frfs)   # noqa: E731
                                  if h.kind == "cross_coupling"]
    lay = model.layout
    both = [(1, "bearing1", (lay.dof(1, "u"), lay.dof(1, "v"))), (5, "right", (lay.dof(5, "u"), lay.dof(5, "v")))]
    assert found(model) == both
    assert found(model, [_frf(3, "x")]) == both          # x-only data too: the screen's test decides
    one_plane = ROTOR.replace("planes = 2", "planes = 1").replace("speed_rpm = 600", "speed_rpm = 0")
    one_plane = one_plane.replace('[[force]]\nstation = 3\ndirection = "y"\n', "").replace(
        '[[sensor]]\nstation = 3\ndirection = "y"\n', "")
    one = loads_model(one_plane, source="one plane")
    assert found(one) == []


def test_change_of_dynamic_stiffness_is_the_model_files():
    """The hypothesis's change on (u, v) is the difference of the dynamic stiffness of the model file
    with the written kxy/kyx and without (modal damping follows the symmetric part of K, unchanged)."""
    model = loads_model(ROTOR, source="small.toml")
    for h in bearing_cross.candidates(model):
        q = 0.37 * h.scale
        assert h.added and h.lower == -h.upper and h.scale == pytest.approx(0.1 * h.upper)
        f = Finding(h.kind, h.station, h.element, q, h.unit, 0.1 * q, 0.0, 100.0, h.description, True,
                    hypothesis=h)
        text = extended_model_text(ROTOR, f, model)
        entry = next(t for t in tomllib.loads(text)["bearing"] if t["station"] == h.station)
        assert (entry["kxy"], entry["kyx"]) == (q, -q)
        ext = loads_model(text, source="extended")
        w = 2 * np.pi * np.array([15.0, 80.0, 240.0])
        (M0, C0, K0, G0), (M1, C1, K1, G1) = model.matrices(), ext.matrices()
        Z0 = K0[None] - (w * w)[:, None, None] * M0[None] + 1j * w[:, None, None] * (C0 + model.speed * G0)[None]
        Z1 = K1[None] - (w * w)[:, None, None] * M1[None] + 1j * w[:, None, None] * (C1 + ext.speed * G1)[None]
        want = np.zeros_like(Z0)
        U = np.asarray(h.dofs)
        want[:, U[:, None], U[None, :]] = local_change(h, q, w)
        scale = np.max(np.abs(Z0), axis=(1, 2))[:, None, None]
        assert np.max(np.abs(Z1 - Z0 - want) / scale) < 1e-13, h.label
        # and the response: the extended file's FRF is the engineering model's with the change
        H0 = model.frf(w / (2 * np.pi), inputs=["F3"], outputs=["y3"]).H[0, 0]
        H1 = ext.frf(w / (2 * np.pi), inputs=["F3"], outputs=["y3"]).H[0, 0]
        b = np.zeros(model.ndof)
        b[model.layout.dof(3, "u")] = 1.0
        Hs = np.linalg.solve(Z0 + want, np.broadcast_to(b.astype(complex), (w.size, b.size))[:, :, None])
        assert np.allclose(H1, Hs[:, model.layout.dof(3, "v"), 0], rtol=1e-9, atol=0)
        assert np.max(np.abs(H1 - H0) / np.abs(H0)) > 1e-3         # the change is seen across the planes


def test_an_existing_cross_coupling_is_changed_and_units_are_the_files():
    text = _bearing(ROTOR, kxy=3.0e4, kyx=-1.0e4)
    model = loads_model(text, source="small.toml")
    h = next(h for h in hypotheses(model) if h.kind == "cross_coupling" and h.element == "right")
    assert not h.added and h.nominal == 2.0e4 and "changed" in h.description
    f = Finding(h.kind, h.station, h.element, 5.0e3, h.unit, 1.0, 0.0, 100.0, h.description, True, hypothesis=h)
    entry = tomllib.loads(extended_model_text(text, f, model))["bearing"][1]
    assert (entry["kxy"], entry["kyx"]) == (3.5e4, -1.5e4)
    # an inch-pound file gets lbf/in
    ip = 'units = "inch-pound"\n' + ROTOR
    model = loads_model(ip, source="ip.toml")
    h = next(h for h in hypotheses(model) if h.kind == "cross_coupling" and h.element == "right")
    f = Finding(h.kind, h.station, h.element, 1.0e4, h.unit, 1.0, 0.0, 100.0, h.description, True, hypothesis=h)
    out = extended_model_text(ip, f, model)
    lbf_per_in = to_si(1.0, "stiffness", "inch-pound")                 # N/m
    assert tomllib.loads(out)["bearing"][1]["kxy"] == pytest.approx(1.0e4 / lbf_per_in, rel=1e-12)
    el = next(e for e in loads_model(out, source="back").elements if e.name == "right")
    assert (el.nominal("kxy"), el.nominal("kyx")) == (pytest.approx(1.0e4, rel=1e-12), pytest.approx(-1.0e4, rel=1e-12))


# ------------------------------------------------------------------------------------------------
# the hidden effect on independent two-plane data
# ------------------------------------------------------------------------------------------------

NOISE = 0.01
N_SUB = 2                                  # the plain model's finer mesh (a small model-form error)
TRUE_Q = 2.0e5                             # N/m, 2 % of the bearing's direct stiffness
F_FIT = sweep_frequencies()                # 20-225 Hz, 0.5 Hz
F_VAL = F_FIT[:-1] + 0.25
# (input: exciter current i12 in x, or a unit force at station 12 in y; output station, direction)
FIT = ((None, 13, "x"), (None, 13, "y"), ((12, "y"), 13, "x"), ((12, "y"), 13, "y"))
VALIDATE = ((None, 15, "x"), (None, 15, "y"), ((12, "y"), 24, "x"))


def _two_plane_files(extra, seed, out_dir):
    """FRF files of the plain rotor with ``extra``: the planar channels 12 -> 13 to fit, others to validate."""
    import sys
    sys.path.insert(0, os.path.dirname(__file__))
    from rotor_plain import plain_frf, plain_rotor
    r = plain_rotor(extra, n_sub=N_SUB)
    rng = np.random.default_rng(seed)
    paths = {"fit": [], "validate": []}
    for what, chans, f in (("fit", FIT, F_FIT), ("validate", VALIDATE, F_VAL)):
        for k, (force, s, d) in enumerate(chans):
            H = plain_frf(f, s, d, rotor=r, force_at=force)
            frf = measure(lambda w, H=H: H, 0, 0, f, noise=Noise(relative=NOISE), rng=rng, input_station=12,
                          output_station=s, input_quantity="current" if force is None else "force",
                          input_direction="x" if force is None else force[1], output_direction=d,
                          speed_hz=10.0)
            p = os.path.join(out_dir, f"{what}{k}_{'i12' if force is None else 'F12y'}_{d}{s}.csv")
            write_frf(p, frf)
            paths[what].append(p)
    return paths, r


@pytest.mark.slow
def test_cross_coupling_found_on_independent_two_plane_data(tmp_path):
    from rotor_plain import plain_frf
    paths, r = _two_plane_files([("cross", 29, TRUE_Q)], 105, str(tmp_path))
    t0 = time.perf_counter()
    d = diagnose(example_path("rotor"), paths["fit"], validate=paths["validate"], out_dir=str(tmp_path / "out"))
    dt = time.perf_counter() - t0
    v = d.verdict
    print(f"\ntruth cross_coupling at 29 = {TRUE_Q:g} N/m; verdict {v.kind} at {v.station} = {v.value:.6g} +- "
          f"{v.std:.3g} {v.unit}; status {d.status}; held-out gain {d.gain:.3g}; {dt:.1f} s\n{d.report()}")
    assert (v.kind, v.station, v.element) == ("cross_coupling", 29, "bearing29"), d.report()
    assert abs(v.value - TRUE_Q) <= 3 * v.std, d.report()
    assert d.status == "explained" and d.gain > 2.0, d.report()
    # the extended model file, read back as a user reads it, gives the data's response
    assert d.extended_model and os.path.basename(d.extended_model) == "model_extended.toml"
    ext = load_model(d.extended_model)
    b = next(t for t in tomllib.load(open(d.extended_model, "rb"))["bearing"] if t["station"] == 29)
    assert b["kxy"] == -b["kyx"] == pytest.approx(v.value, rel=1e-12)
    base = load_model(example_path("rotor"))
    for (force, s, dd), f in [(c, F_VAL) for c in VALIDATE] + [(c, F_FIT) for c in FIT]:
        truth = plain_frf(f, s, dd, rotor=r, force_at=force)
        got = _response(ext, f, force, s, dd)
        before = _response(base, f, force, s, dd)
        err, err0 = _rms_rel(got, truth), _rms_rel(before, truth)
        print(f"  {force or 'i12'} -> {dd}{s}: rms relative error {err:.2e} (engineering model {err0:.2e})")
        assert err < 3e-3 and err < 0.2 * err0, (force, s, dd, err, err0)


def _response(model, f, force, s, d):
    """The model's response (its matrices at its speed) from i12 (``force`` None) or a unit force at ``force``
    to ``d`` at ``s``."""
    lay = model.layout
    w = 2 * np.pi * np.asarray(f, float)
    M, C, K, G = model.matrices()
    Z = K[None] - (w * w)[:, None, None] * M[None] + 1j * w[:, None, None] * (C + model.speed * G)[None]
    if force is None:
        b = model.input_matrix()[:, model.input_names.index("i12")]
    else:
        b = np.zeros(model.ndof)
        b[lay.dof(force[0], "u" if force[1] == "x" else "v")] = 1.0
    X = np.linalg.solve(Z, np.broadcast_to(b.astype(complex), (w.size, b.size))[:, :, None])[:, :, 0]
    return X[:, lay.dof(s, "u" if d == "x" else "v")]


def _rms_rel(a, b):
    return float(math.sqrt(np.mean(np.abs(a / b - 1) ** 2)))
