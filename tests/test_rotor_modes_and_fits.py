"""Modes under stiffness-proportional damping, what ``beta`` damps, and the crack screen's bounds.

1. :func:`mutext.rotor.analysis.modes` once dropped every root below ``1e-6`` times the largest
   root of the damped problem as "rigid".  With ``[damping] beta`` the largest root is the
   overdamped :math:`-\\beta\\omega^2` of the top mode of the mesh, so the thesis rotor lost its
   34 Hz pair at ``beta = 1e-4``, and with its station table halved (59 stations) every mode
   below 1 kHz at ``beta = 3e-5``.  The reference here is tests/rotor_plain.py (numpy Timoshenko
   elements written apart from the package, with ``n_sub`` sub-elements per table row) with the
   same damping :math:`C = \\beta K_s`.
2. ``beta`` damps the structure's own members only, not the grounded springs and bearings the
   diagnosis adds (``[[bearing]] ... damping = 0.0``, ``[[spring]] between = [m, "ground"]``).
3. The crack screen scans the depth ratio up to its bound 0.5 (the log grid stopped at 0.464).
"""
from __future__ import annotations

import os
import tomllib
from types import SimpleNamespace

import numpy as np
import pytest
import scipy.linalg as sla

from mutext.diagnose import hypotheses
from mutext.diagnose._screen import _Data, _Evaluator, _fit_size, _Receptance
from mutext.hide import example_path
from mutext.rotor import ProportionalDamping, Rotor, ShaftElement
from mutext.rotor.analysis import modes
from mutext.rotor.model import load_model, loads_model
from mutext.rotor.table import read_station_table

from rotor_plain import plain_rotor

ROTOR = example_path("rotor")
BASE = os.path.dirname(ROTOR)
BAND = 2 * np.pi * 1000.0            # modes whose |lambda| (undamped frequency) is below 1 kHz


def rotor_text(n_sub: int, damping: str) -> str:
    """The shipped thesis rotor as a model file with inline stations, every table row split in ``n_sub``.

    Station s of the table becomes station (s - 1) n_sub + 1; the ports from the table's flags,
    the bearings and the exciter move with it.  ``damping`` is the body of the [damping] table.
    """
    with open(ROTOR, "rb") as fh:
        doc = tomllib.load(fh)
    table = read_station_table(os.path.join(BASE, doc["shaft"]["station_table"]))
    new = lambda s: (s - 1) * n_sub + 1                                   # noqa: E731
    out = [f'name = "thesis rotor, {n_sub} elements per table row"', "planes = 2",
           f'speed_rpm = {doc["speed_rpm"]}', "[shaft]", f'poisson_ratio = {doc["shaft"]["poisson_ratio"]}']
    for b in doc["bearing"]:
        out.append(f'[[bearing]]\nstation = {new(b["station"])}\nstiffness = {b["stiffness"]}\n'
                   f'damping = {b["damping"]}')
    for e in doc["exciter"]:
        out.append(f'[[exciter]]\nstation = {new(e["station"])}\nforce_per_ampere = {e["force_per_ampere"]}\n'
                   f'name = "{e["name"]}"')
    out.append(f"[damping]\n{damping}")
    flags = (("translational_input", "force_input"), ("translational_output", "displacement_output"),
             ("rotational_input", "moment_input"), ("rotational_output", "rotation_output"))
    for k, st in enumerate(table.stations):
        last = k == len(table.stations) - 1
        for j in range(1 if last else n_sub):
            row = ["[[station]]"]
            if not last:
                row += [f"length = {st.length / n_sub!r}", f"outer_diameter = {st.outer_diameter!r}",
                        f"inner_diameter = {st.inner_diameter!r}", f"youngs_modulus = {st.youngs_modulus!r}",
                        f"density = {st.density!r}"]
            if j == 0:
                row += [f"added_mass = {st.added_mass!r}", f"added_polar_inertia = {st.added_polar_inertia!r}",
                        f"added_transverse_inertia = {st.added_transverse_inertia!r}"]
                row += [f"{key} = true" for f, key in flags if getattr(st, f)]
            out.append("\n".join(row))
    return "\n".join(out) + "\n"


def plain_roots(n_sub: int, beta: float) -> np.ndarray:
    """Roots (Im > 0, |lambda| < 1 kHz) of the plain model with C = beta (K - bearings), at 600 rpm."""
    r = plain_rotor(n_sub=n_sub)
    Kb = np.zeros_like(r.K)
    for s in (2, 29):                       # the bearings of mutext/data/rotor.toml
        for d in r.translational(s):
            Kb[d, d] += 1e7
    n = r.ndof
    A = np.block([[np.zeros((n, n)), np.eye(n)],
                  [-np.linalg.solve(r.M, r.K), -np.linalg.solve(r.M, beta * (r.K - Kb) + r.speed * r.G)]])
    lam = np.linalg.eigvals(A)
    lam = lam[(lam.imag > 0) & (np.abs(lam) < BAND)]
    return lam[np.argsort(lam.imag)]


def band_roots(model) -> np.ndarray:
    ev = modes(model).eigenvalues
    return ev[np.abs(ev) < BAND]


# ------------------------------------------------------------------------------------------
# 1. modes with overdamped top modes
# ------------------------------------------------------------------------------------------

@pytest.mark.parametrize("n_sub, beta", [(1, 1e-4), (2, 3e-5)])
def test_overdamped_top_modes_do_not_push_out_the_vibration_modes(n_sub, beta):
    # before: (1, 1e-4) kept 8 of these 10 roots (the 34 Hz pair was cut at 1e-6 * 5.8e8 rad/s = 92 Hz),
    # (2, 3e-5) none of them (cut at 1e-6 * 6.2e9 rad/s = 1 kHz)
    model = loads_model(rotor_text(n_sub, f"beta = {beta}"), source=f"refined x{n_sub}", base_dir=BASE)
    assert model.n_stations == 29 * n_sub + 1
    ours, ref = band_roots(model), plain_roots(n_sub, beta)
    assert ref.size == 10                          # 5 forward/backward pairs below 1 kHz
    assert ours.size == ref.size
    np.testing.assert_allclose(ours, ref, rtol=1e-6)
    # the largest root is far beyond the band: the overdamped -beta omega^2 of the top mode
    M, C, K, G = model.matrices()
    assert np.max(np.abs(sla.eigvals(C, M))) > 100 * BAND


def test_refined_mesh_has_the_coarse_modes():
    # the 59-station rotor with beta = 3e-5: every mode below 1 kHz of the 30-station one, within 0.1 %
    coarse = band_roots(loads_model(rotor_text(1, "beta = 3e-5"), source="coarse", base_dir=BASE))
    fine = band_roots(loads_model(rotor_text(2, "beta = 3e-5"), source="fine", base_dir=BASE))
    assert coarse.size == fine.size == 10
    np.testing.assert_allclose(fine.imag, coarse.imag, rtol=1e-3)
    np.testing.assert_allclose(np.abs(fine), np.abs(coarse), rtol=1e-3)


def test_overdamped_roots_made_complex_by_the_gyroscopics_are_not_modes():
    # at 600 rpm the overdamped roots near -1/beta = -1e5 1/s couple across the planes into
    # -1e5 +/- j O(speed): before, 21 of them were reported as natural frequencies of 9.7-15 Hz
    model = loads_model(rotor_text(1, "beta = 1e-5"), source="beta 1e-5", base_dir=BASE)
    md = modes(model)
    f = md.frequencies_hz
    assert f[0] == pytest.approx(33.89, abs=0.01)
    assert np.sum(f < 1000.0) == 10 and np.all(md.damping_ratio[f < 1000.0] < 0.05)
    # the same roots are there, and rejected for their shapes' more-than-critical damping
    M, C, K, G = model.matrices()
    n = M.shape[0]
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C + model.speed * G)]])
    lam = sla.eigvals(A)
    creep = lam[(lam.imag > 0) & (lam.real < -5e4) & (lam.imag < 2 * np.pi * 20)]
    assert creep.size > 10


def test_free_free_with_damping_drops_only_the_rigid_body_modes():
    L, d, n_el = 1.0, 0.05, 6
    els = [ShaftElement(k + 1, L / n_el, d, E=211e9, rho=7810.0, nu=0.3) for k in range(n_el)]
    free = Rotor(els, name="free beam")
    damped = Rotor(els, damping=ProportionalDamping(beta=1e-7), name="free beam, beta")
    w = 2 * np.pi * free.natural_frequencies(speed=0.0)
    assert w.size == free.ndof - 4                              # 2 rigid-body modes per plane
    md = damped.modes(speed=0.0)
    assert md.eigenvalues.size == w.size                        # every elastic mode, no rigid one
    np.testing.assert_allclose(np.abs(md.eigenvalues), w, rtol=1e-8)
    np.testing.assert_allclose(md.damping_ratio, 1e-7 * w / 2, rtol=1e-6)


# ------------------------------------------------------------------------------------------
# 2. beta and the elements the diagnosis adds
# ------------------------------------------------------------------------------------------

ADDED_BEARING = '\n[[bearing]]\nname = "k_added"\nstation = 9\nstiffness = 3.0e5\ndamping = 0.0\n'
ADDED_SPRING = '\n[[spring]]\nname = "k_added"\nstiffness = 150.0\nbetween = ["m2", "ground"]\n'


def test_beta_leaves_an_added_bearing_undamped():
    text = open(ROTOR).read().replace("modal = 0.01", "alpha = 0.5\nbeta = 2e-5")
    base = loads_model(text, source="rotor, beta", base_dir=BASE)
    ext = loads_model(text + ADDED_BEARING, source="rotor, beta, added bearing", base_dir=BASE)
    Mb, Cb, Kb, _ = base.matrices()
    Me, Ce, Ke, _ = ext.matrices()
    assert np.abs(Ke - Kb).max() == pytest.approx(3.0e5)        # the spring is there ...
    np.testing.assert_array_equal(Ce, Cb)                       # ... and adds no damping
    # the rule: alpha M + beta K of the shaft only (the bearings of the file are not damped either)
    Ksup = np.zeros_like(Kb)
    for s in (2, 29):
        for d in ("u", "v"):
            Ksup[base.layout.dof(s, d), base.layout.dof(s, d)] = 1e7
    np.testing.assert_allclose(Cb, 0.5 * Mb + 2e-5 * (Kb - Ksup), rtol=0, atol=1e-12 * np.abs(Cb).max())
    assert base.parameter_names[-2:] == ["damping.alpha", "damping.beta"]


def test_beta_leaves_an_added_grounded_spring_undamped():
    text = open(example_path("three_mass")).read() + "\n[damping]\nbeta = 0.01\n"
    base = loads_model(text, source="three-mass, beta")
    ext = loads_model(text + ADDED_SPRING, source="three-mass, beta, added spring")
    np.testing.assert_array_equal(ext.matrices().C, base.matrices().C)
    assert ext.matrices().K[1, 1] - base.matrices().K[1, 1] == pytest.approx(150.0)
    # springs between masses are members (k1, k2); the one to ground (k3) is a support
    C = base.matrices().C
    dampers = np.diag([5.2992, 1.9467, 10.7375])
    np.testing.assert_allclose(C - dampers, 0.01 * np.array([[842.3, -842.3, 0.0],
                                                             [-842.3, 842.3 + 806.5, -806.5],
                                                             [0.0, -806.5, 806.5]]), rtol=1e-12)


def test_beta_is_a_tunable_parameter():
    text = open(example_path("three_mass")).read() + "\n[damping]\nbeta = 0.01\n"
    m = loads_model(text, source="three-mass, beta")
    C1, C2 = m.matrices().C, m.matrices({"damping.beta": 0.02}).C
    np.testing.assert_allclose(C2 - C1, C1 - np.diag([5.2992, 1.9467, 10.7375]), rtol=1e-12)   # beta doubled


# ------------------------------------------------------------------------------------------
# 3. the crack screen reaches its bound
# ------------------------------------------------------------------------------------------

def test_crack_screen_reaches_depths_near_its_bound():
    model = load_model(ROTOR)
    h = next(h for h in hypotheses(model, stations=[15]) if h.kind == "crack")
    assert (h.lower, h.upper) == (0.0, 0.5)
    f = np.concatenate([np.linspace(28.0, 36.0, 9), np.linspace(180.0, 200.0, 9)])
    rec = _Receptance(model, None, model.speed, 2 * np.pi * f)
    b = rec.input_vector(("port", model.input_names.index("i12")))
    out = model.layout.dof(13, "u")
    Rb = np.einsum("kij,j->ki", rec.R, b)
    idx = np.arange(f.size)
    data = _Data([SimpleNamespace(out_dof=out)], [idx], [None], [Rb[:, out]], [b], [f],
                 {0: (Rb, rec.R[:, out, :])})
    ev = _Evaluator(rec, data, h)
    data.meas = [ev.responses(0.49)[0]]                         # a crack of depth ratio 0.49 at station 15
    assert np.abs(np.log(data.meas[0] / data.H0[0])).max() > 0.1
    depth, rss = _fit_size(ev)
    assert depth == pytest.approx(0.49, abs=1e-4)              # was 0.4642, the grid's last point
    assert rss < 1e-10
    # and at the bound itself
    data.meas = [ev.responses(0.5)[0]]
    depth, rss = _fit_size(ev)
    assert depth == pytest.approx(0.5, abs=1e-4) and rss < 1e-10
