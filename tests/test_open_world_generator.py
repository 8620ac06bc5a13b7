"""The open-world data generator of the diagnosis benchmark (benchmarks/_open_world.py): written apart from
the code under test, and right.

Its responses are checked against the package's own model of the shipped chains (an independent
cross-check, the package being the thing the generator must not use), its channels and grids against
mutext.hide's, and each out-of-library effect's physics against a limit where it is known exactly.
"""
import ast
import math
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"
sys.path.insert(0, str(BENCH))

import _open_world as ow  # noqa: E402

NOISE = 0.01

# the checks that draw cases of every kind (each draw sizes its effect by fits of the generator's own): in the
# default run on the three-mass chain, the cheapest; on the four-story chain with the slow tests
BY_COST = [pytest.param(e, marks=pytest.mark.slow) if e == "four_story" else e for e in sorted(ow.EXAMPLES)]
assert "three_mass" in BY_COST


def _pkg_frf(path, f, chans):
    """The package's model (mutext.rotor.model) at the channels ``(force, sensor)``."""
    from mutext.rotor.model import load_model
    model = load_model(path)
    forces = sorted({fo for fo, _ in chans})
    sensors = sorted({se for _, se in chans})
    H = model.frf(f, inputs=forces, outputs=sensors)
    return [H(se, fo) for fo, se in chans]


def _rms_log(a, b):
    r = np.concatenate([np.log(np.asarray(x) / np.asarray(y)) for x, y in zip(a, b)])
    return float(np.sqrt(np.mean(np.abs(r) ** 2)))


# ----------------------------------------------------------------------------------------------
# written apart
# ----------------------------------------------------------------------------------------------

def test_generator_is_written_apart_from_the_code_under_test():
    tree = ast.parse((BENCH / "_open_world.py").read_text(encoding="utf-8"))
    mods = {n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}
    mods |= {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
    assert {m for m in mods if m and m.startswith("mutext")} == {"mutext.rig"}
    forbidden = ("mutext.diagnose", "mutext.hide", "mutext.rotor", "mutext.frfit")
    assert not any(m and m.startswith(forbidden) for m in mods)
    # nothing pulled in by name at run time either
    calls = [n for n in ast.walk(tree) if isinstance(n, ast.Call)
             and getattr(n.func, "attr", getattr(n.func, "id", None)) in ("import_module", "__import__")]
    assert not calls


# ----------------------------------------------------------------------------------------------
# the chain, the channels, the grid
# ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("example", sorted(ow.EXAMPLES))
def test_no_effect_equals_the_package_model(example):
    """Noise-free responses of the plain assembly = the package's model of the shipped file."""
    path = ow.example_path(example)
    chain = ow.read_chain(path)
    M, C, K = chain.matrices()
    meas, val = ow.channels(chain)
    f = ow.band_grid(M, K)
    for chans, grid in ((meas, f), (val, f + 0.5 * (f[1] - f[0]))):
        mine = [ow.solve_response(M, C, K, chain.forces[fo], [chain.sensors[se]], grid)[0] for fo, se in chans]
        for h, ref in zip(mine, _pkg_frf(path, grid, chans)):
            np.testing.assert_allclose(h, ref, rtol=1e-9, atol=0)
    # and through make_case (negligible noise): stations, grid and values
    case = ow.make_case(example, "none", "none", seed=0, noise=1e-12)
    for frf, ref in zip(case.measured, _pkg_frf(path, f, meas)):
        np.testing.assert_array_equal(frf.freq_hz, f)
        np.testing.assert_allclose(frf.response, ref, rtol=1e-9)


@pytest.mark.parametrize("example", sorted(ow.EXAMPLES))
def test_channels_and_grids_are_those_of_hide(example):
    from mutext.hide import hidden_effect_data
    hid = hidden_effect_data(example, seed=0, kind="none", noise=NOISE)
    case = ow.make_case(example, "none", "none", seed=0, noise=NOISE)
    for mine, theirs in ((case.measured, hid.measured), (case.validate, hid.validate)):
        assert len(mine) == len(theirs)
        for a, b in zip(mine, theirs):
            assert (a.input_station, a.output_station, a.input_quantity, a.output_quantity, a.input_direction,
                    a.output_direction, a.input_name, a.output_name) == \
                   (b.input_station, b.output_station, b.input_quantity, b.output_quantity, b.input_direction,
                    b.output_direction, b.input_name, b.output_name)
            np.testing.assert_allclose(a.freq_hz, b.freq_hz, rtol=0, atol=1e-12)


def test_written_model_reads_back_and_loads_in_the_package():
    from mutext.rotor.model import load_model
    chain = ow.read_chain(ow.example_path("four_story"))
    with tempfile.TemporaryDirectory() as d:
        p = ow.write_chain(chain, Path(d) / "m.toml")
        back = ow.read_chain(p)
        for X, Y in zip(chain.matrices(), back.matrices()):
            np.testing.assert_array_equal(X, Y)
        assert (back.forces, back.sensors) == (chain.forces, chain.sensors)
        f = np.array([1.0, 3.0, 7.0])
        a = _pkg_frf(p, f, [("f4", "x2")])[0]
        b = _pkg_frf(ow.example_path("four_story"), f, [("f4", "x2")])[0]
        np.testing.assert_allclose(a, b, rtol=1e-12)


def test_noise_is_relative_circular_and_of_the_level_asked():
    rng = np.random.default_rng(5)
    H = np.exp(1j * np.linspace(0, 6, 200000)) * np.logspace(-6, -2, 200000)
    e = ow.add_noise(H, 0.02, rng) / H - 1
    assert abs(np.std(e.real) - 0.02 / math.sqrt(2)) < 2e-4 and abs(np.std(e.imag) - 0.02 / math.sqrt(2)) < 2e-4
    assert abs(np.mean(e.real * e.imag)) < 1e-5 and abs(np.mean(e)) < 2e-4


def test_cases_are_reproducible_and_the_draw_does_not_depend_on_the_noise():
    a = ow.make_case("three_mass", "two_effect", "pair", seed=7, noise=NOISE)
    b = ow.make_case("three_mass", "two_effect", "pair", seed=7, noise=NOISE)
    for x, y in zip(a.measured + a.validate, b.measured + b.validate):
        np.testing.assert_array_equal(x.response, y.response)
    c = ow.make_case("three_mass", "two_effect", "pair", seed=7, noise=0.003)
    assert [(e["kind"], e["station"]) for e in a.key["effects"]] == [(e["kind"], e["station"])
                                                                      for e in c.key["effects"]]


# ----------------------------------------------------------------------------------------------
# in-library effects: named as the library names them, sized as hide sizes them
# ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("example", BY_COST)
def test_in_library_keys_name_hypotheses_of_the_library(example):
    from mutext.diagnose import hypotheses
    for kind in ow.IN_LIBRARY:
        case = ow.make_case(example, "in_library", kind, seed=2, noise=NOISE)
        hyps = {(h.kind, h.station, h.element) for h in hypotheses(case.model_path, case.measured)}
        (e,) = case.key["effects"]
        assert (e["kind"], e["station"], e["element"]) in hyps, (kind, e)
        assert case.key["change"] >= ow.DETECTABLE
        # the generator's own single-hypothesis fit finds the effect and leaves only rounding (a file's scale
        # and its sensor's gain are the same on the measured data when the sensor has one measured channel)
        fit = case.key["single_fit"]
        assert fit["misfit"] < 1e-3, (kind, fit)
        assert fit["station"] == e["station"], (kind, fit)
        assert fit["kind"] == e["kind"] or {fit["kind"], e["kind"]} == {"sensor_gain", "channel_scale"}, (kind, fit)
        # the key's claim is the true system
        assert ow.equivalence_error(case, case.key["effects"])["error"] < 1e-12


def test_sensor_delay_and_unit_slip_are_in_library_with_the_library_names():
    assert {"sensor_delay", "unit_slip"} <= set(ow.IN_LIBRARY)
    assert not {"sensor_delay", "unit_slip"} & set(ow.OUT_OF_LIBRARY)
    for seed in range(3):
        case = ow.make_case("three_mass", "in_library", "sensor_delay", seed=seed, noise=0.03)
        (e,) = case.key["effects"]
        chain = ow.read_chain(case.model_path)
        assert (e["kind"], e["element"], e["unit"]) == ("sensor_delay", e["element"], "s")
        assert e["station"] == chain.sensors[e["element"]] + 1
        assert 0 < e["value"] < ow.DELAY_BOUNDS[1]
        case = ow.make_case("four_story", "in_library", "unit_slip", seed=seed, noise=NOISE)
        (e,) = case.key["effects"]
        fo, se = e["element"].split("->")
        assert e["kind"] == "channel_scale" and e["station"] == ow.read_chain(case.model_path).sensors[se] + 1
        assert e["value"] in ow.UNIT_SLIPS


@pytest.mark.parametrize("seeds", [range(0, 10),                          # the default run: 10 draws
                                   pytest.param(range(10, 40), marks=pytest.mark.slow)])
def test_a_file_scale_and_its_sensor_gain_are_not_drawn_together(seeds):
    for seed in seeds:
        case = ow.make_case("three_mass", "two_effect", "unit_slip+sensor_gain", seed=seed, noise=NOISE)
        a, b = case.key["effects"]
        assert (a["kind"], b["kind"]) == ("channel_scale", "sensor_gain")
        assert a["station"] != b["station"]


def test_equivalent_explanations_are_told_from_wrong_ones():
    """Proportional damping C -> (1 + a) C is every damper changed by a; a stiffness loss every spring changed
    by -d: equivalent (to rounding).  Part of it, or a file's scale on the wrong file, is not."""
    chain = ow.read_chain(ow.example_path("three_mass"))
    case = ow.make_case("three_mass", "out_of_library", "stiffness_loss", seed=0, noise=NOISE)
    d = case.key["details"]["value"]
    every = [{"kind": "stiffness", "station": chain.station(e["between"]), "element": e["name"],
              "value": -d * e["value"]} for e in chain.springs]
    assert ow.equivalence_error(case, every)["error"] < 1e-9
    assert ow.equivalence_error(case, every[:2])["error"] > ow.DETECTABLE * NOISE / 10
    assert ow.equivalence_error(case, [])["error"] >= ow.DETECTABLE * NOISE
    for seed in range(6):
        case = ow.make_case("three_mass", "out_of_library", "rayleigh_damping", seed=seed, noise=NOISE)
        if case.key["details"]["form"] == "C -> (1 + a) C":
            break
    a = case.key["details"]["value"]
    every = [{"kind": "damping", "station": chain.station(e["between"]), "element": e["name"],
              "value": a * e["value"]} for e in chain.dampers]
    assert ow.equivalence_error(case, every)["error"] < 1e-9
    assert ow.equivalence_error(case, every[1:])["error"] > NOISE * ow.EQUIVALENT
    # kinds of the whole structure: all damping scaled, the frequency axis, a mass moving with the sensor
    scale = [{"kind": "damping_scale", "station": None, "element": "damping", "value": a}]
    assert ow.equivalence_error(case, scale)["error"] < 1e-9
    for kind, claim in (("frequency_scale", "frequency_scale"), ("roving_mass", "sensor_mass")):
        case = ow.make_case("four_story", "out_of_library", kind, seed=1, noise=NOISE)
        v = case.key["details"]["value"]
        claimed = [{"kind": claim, "station": None, "element": "-", "value": v}]
        assert ow.equivalence_error(case, claimed)["error"] < 1e-9, kind
        assert ow.equivalence_error(case, [{**claimed[0], "value": 0.5 * v}])["error"] > NOISE * ow.EQUIVALENT
    # a unit slip: the measured file's scale shows on the measured files only
    case = ow.make_case("three_mass", "in_library", "unit_slip", seed=0, noise=NOISE)
    (e,) = case.key["effects"]
    fo, se = e["element"].split("->")
    other = next(f"{a}->{b}" for a, b in case.channels[0] if (a, b) != (fo, se))
    wrong = [{**e, "element": other}]
    err = ow.equivalence_error(case, wrong)
    assert err["validate"] < 1e-12 and err["measured"] > 0.1
    # the sensor's gain instead of its measured file's scale: the same measured files, other validation files
    gain = [{"kind": "sensor_gain", "station": e["station"], "element": se, "value": e["value"]}]
    err = ow.equivalence_error(case, gain)
    assert err["measured"] < 1e-12 and err["validate"] > 0.1
    with pytest.raises(ValueError):
        ow.equivalence_error(case, [{"kind": "crack", "station": 1, "element": "x", "value": 0.1}])


@pytest.mark.parametrize("seeds", [range(0, 2),                           # the default run: 2 draws
                                   pytest.param(range(2, 4), marks=pytest.mark.slow)])
def test_two_effects_are_two_places_each_detectable(seeds):
    for seed in seeds:
        case = ow.make_case("four_story", "two_effect", "pair", seed=seed, noise=NOISE)
        eff = case.key["effects"]
        assert len(eff) == 2
        assert (eff[0]["kind"], eff[0]["station"]) != (eff[1]["kind"], eff[1]["station"])
        assert eff[0]["element"] != eff[1]["element"]
    case = ow.make_case("three_mass", "two_effect", "mass+spring_change", seed=1, noise=NOISE)
    assert [e["kind"] for e in case.key["effects"]] == ["mass", "stiffness"]


# ----------------------------------------------------------------------------------------------
# out-of-library physics
# ----------------------------------------------------------------------------------------------

def test_cubic_spring_tends_to_the_linear_response_as_the_force_vanishes():
    chain = ow.read_chain(ow.example_path("three_mass"))
    M, C, K = chain.matrices()
    f = ow.band_grid(M, K)
    lin = ow.solve_response(M, C, K, 0, [0, 2], f)
    d = ow.solve_response(M, C, K, 0, [0, 1], f)
    dmax = float(np.max(np.abs(d[0] - d[1])))
    k3 = 0.3 * 842.3 / (0.75 * dmax ** 2)          # 30 % of k1 at 1 N and the largest elongation
    errs = []
    for force in (1.0, 1e-1, 1e-2, 1e-3, 1e-4):
        H = ow.cubic_response(M, C, K, (0, 1), k3, force, 0, [0, 2], f)
        errs.append(float(np.max(np.abs(H - lin) / np.abs(lin))))
    assert errs[0] > 1e-2                          # a real effect at 1 N
    assert errs[-1] < 1e-7                         # linear as F -> 0
    for a, b in zip(errs[1:], errs[2:]):           # the describing function: a change of order F^2
        assert 0.005 * a < b < 0.02 * a
    # the harmonic balance holds: k_eff = k + 3/4 k3 |delta|^2 at every frequency (checked by residual)
    force = 1.0
    x = ow.cubic_response(M, C, K, (0, 1), k3, force, 0, [0, 1, 2], f) * force
    delta = x[0] - x[1]
    w = 2 * np.pi * f
    for m in range(0, f.size, 37):
        Km = K.copy()
        dk = 0.75 * k3 * abs(delta[m]) ** 2
        Km[0, 0] += dk; Km[1, 1] += dk; Km[0, 1] -= dk; Km[1, 0] -= dk
        Z = Km - w[m] ** 2 * M + 1j * w[m] * C
        r = Z @ x[:, m] - np.array([force, 0, 0])
        assert np.max(np.abs(r)) < 1e-9 * force


def test_tuned_absorber_with_a_rigid_spring_is_a_mass_change():
    chain = ow.read_chain(ow.example_path("four_story"))
    M, C, K = chain.matrices()
    f = ow.band_grid(M, K)
    i, ma = 2, 0.15
    M2 = M.copy()
    M2[i, i] += ma
    ref = ow.solve_response(M2, C, K, 3, [0, 1, 3], f)
    errs = []
    for ka in (1e5, 1e7, 1e9):          # stiffer: the absorber moves with its mass (error ~ w^2 ma / ka)
        Ma, Ca, Ka = ow.with_absorber(M, C, K, i, ma, ka, 0.0)
        assert Ma.shape == (5, 5)
        H = ow.solve_response(Ma, Ca, Ka, 3, [0, 1, 3], f)
        errs.append(float(np.max(np.abs(H - ref) / np.abs(ref))))
    assert errs[-1] < 1e-6
    assert 0.005 * errs[0] < errs[1] < 0.02 * errs[0] and 0.005 * errs[1] < errs[2] < 0.02 * errs[1]


@pytest.mark.parametrize("example", BY_COST)
def test_unit_slip_scales_one_measured_file_exactly(example):
    for seed in range(4):
        case = ow.make_case(example, "in_library", "unit_slip", seed=seed, noise=1e-12)
        chain = ow.read_chain(case.model_path)
        meas, val = ow.channels(chain)
        M, C, K = chain.matrices()
        f = ow.band_grid(M, K)
        (e,) = case.key["effects"]
        factor = e["value"]
        assert factor in (1e-3, 1e-6, 25.4, -1.0)
        ratios = [frf.response / ref for frf, ref in zip(case.measured, _pkg_frf(case.model_path, f, meas))]
        slipped = [k for k, r in enumerate(ratios) if np.max(np.abs(r - 1)) > 1e-9]
        assert len(slipped) == 1
        np.testing.assert_allclose(ratios[slipped[0]], factor, rtol=1e-9)
        assert e["element"] == "->".join(meas[slipped[0]])
        assert e["station"] == chain.sensors[meas[slipped[0]][1]] + 1
        fv = f + 0.5 * (f[1] - f[0])
        for frf, ref in zip(case.validate, _pkg_frf(case.model_path, fv, val)):   # the other files are right
            np.testing.assert_allclose(frf.response, ref, rtol=1e-9)


def test_frequency_scale_and_sensor_delay_are_what_they_say():
    case = ow.make_case("three_mass", "out_of_library", "frequency_scale", seed=3, noise=NOISE)
    eps = case.key["details"]["value"]
    chain = ow.read_chain(case.model_path)
    meas, _ = ow.channels(chain)
    f = case.measured[0].freq_hz
    for h, ref in zip(case.clean, _pkg_frf(case.model_path, f * (1 + eps), meas)):
        np.testing.assert_allclose(h, ref, rtol=1e-9)
    case = ow.make_case("four_story", "in_library", "sensor_delay", seed=3, noise=NOISE)
    (e,) = case.key["effects"]
    chain = ow.read_chain(case.model_path)
    meas, val = ow.channels(chain)
    for chans, clean, grid in ((meas, case.clean, case.measured[0].freq_hz),
                               (val, case.clean_validate, case.validate[0].freq_hz)):
        for (fo, se), h, ref in zip(chans, clean, _pkg_frf(case.model_path, grid, chans)):
            want = ref * (np.exp(-2j * np.pi * grid * e["value"]) if se == e["element"] else 1.0)
            np.testing.assert_allclose(h, want, rtol=1e-9)


def test_roving_mass_differs_per_channel():
    case = ow.make_case("four_story", "out_of_library", "roving_mass", seed=1, noise=NOISE)
    mr = case.key["details"]["value"]
    chain = ow.read_chain(case.model_path)
    M, C, K = chain.matrices()
    meas, _ = ow.channels(chain)
    f = case.measured[0].freq_hz
    for (fo, se), h in zip(meas, case.clean):
        j = chain.sensors[se]
        M2 = M.copy()
        M2[j, j] += mr
        np.testing.assert_allclose(h, ow.solve_response(M2, C, K, chain.forces[fo], [j], f)[0], rtol=1e-12)


def test_wrong_model_cases_hand_over_another_model(tmp_path):
    case = ow.make_case("three_mass", "out_of_library", "wrong_model_parameters", seed=0, noise=NOISE,
                        workdir=tmp_path)
    assert Path(case.model_path).parent == tmp_path
    shipped, wrong = ow.read_chain(ow.example_path("three_mass")), ow.read_chain(case.model_path)
    for a, b in zip(shipped.springs, wrong.springs):
        assert abs(abs(b["value"] / a["value"] - 1) - 0.15) < 1e-12
    assert sorted(m for _, m in shipped.masses) == sorted(m for _, m in wrong.masses)
    assert [m for _, m in shipped.masses] != [m for _, m in wrong.masses]
    # the data are the shipped model's
    meas, _ = ow.channels(shipped)
    f = case.measured[0].freq_hz
    for h, ref in zip(case.clean, _pkg_frf(ow.example_path("three_mass"), f, meas)):
        np.testing.assert_allclose(h, ref, rtol=1e-9)
    case = ow.make_case("four_story", "out_of_library", "wrong_model_extra_mass", seed=0, noise=NOISE,
                        workdir=tmp_path)
    assert case.model_path == ow.example_path("four_story")
    data_model = ow.read_chain(case.key["data_model"])
    assert len(data_model.masses) == 5
    f = case.measured[0].freq_hz
    meas = ow.channels(data_model)[0]
    for h, ref in zip(case.clean, _pkg_frf(case.key["data_model"], f, meas)):
        np.testing.assert_allclose(h, ref, rtol=1e-9)


@pytest.mark.parametrize("example", BY_COST)
def test_every_out_of_library_effect_is_detectable_and_distinct(example):
    """rms |ln(data/model)| >= 5 x noise against the package's model of the file handed over; the noise
    of the measured files is the level asked; no single library hypothesis explains the data."""
    for kind in ow.OUT_OF_LIBRARY:
        case = ow.make_case(example, "out_of_library", kind, seed=0, noise=NOISE)
        chain = ow.read_chain(case.model_path)
        meas, _ = ow.channels(chain)
        f = case.measured[0].freq_hz
        model = _pkg_frf(case.model_path, f, meas)
        assert _rms_log(case.clean, model) >= ow.DETECTABLE * NOISE, kind
        assert abs(_rms_log([m.response for m in case.measured], case.clean) / NOISE - 1) < 0.1, kind
        assert case.key["single_fit"]["misfit"] >= ow.DISTINCT, (kind, case.key["single_fit"])
        assert case.key["effects"] == [] and case.key["category"] == "out_of_library"


def test_claims_with_an_added_dof_or_a_run_reproduce_the_systems_they_name():
    """claimed_data's absorber, pedestal and distributed stiffness against the generator's own draws of the
    same systems (tuned absorber, every-spring loss) and against a split spring to ground (a pedestal)."""
    case = ow.make_case("three_mass", "out_of_library", "tuned_absorber", 0, 0.01)
    det = case.key["details"]
    ma = det["value"]
    ka = ma * (2 * np.pi * det["tuned_hz"]) ** 2
    ca = 2 * det["zeta"] * np.sqrt(ka * ma)
    claim = {"kind": "absorber", "station": det["station"], "element": None, "value": ma, "values": [ma, ka, ca]}
    assert ow.equivalence_error(case, [claim])["error"] < 1e-10
    assert ow.equivalence_error(case, [{**claim, "values": [ma, 1.02 * ka, ca]}])["error"] > 1e-3
    case = ow.make_case("four_story", "out_of_library", "stiffness_loss", 0, 0.01)
    run = [s["name"] for s in ow.read_chain(case.model_path).springs]
    claim = {"kind": "distributed_stiffness", "station": 1, "element": "..", "value": -case.key["details"]["value"],
             "run": run}
    assert ow.equivalence_error(case, [claim])["error"] < 1e-10
    assert ow.equivalence_error(case, [{**claim, "run": run[1:]}])["error"] > 1e-3
    # a pedestal (m_p, k_p) under k3 is the chain with k3 ending on a mass m_p held by k_p; the split spring
    # k3 -> 2 k3 - mx - 2 k3 - ground is an absorber at m3 (m_a = mx / 4, k_a = k3, no damper) on the model
    from dataclasses import replace as _replace
    chain = ow.read_chain(ow.example_path("three_mass"))
    k3 = next(s for s in chain.springs if s["name"] == "k3")
    meas_ch, _ = ow.channels(chain)
    f = ow.band_grid(*[chain.matrices()[k] for k in (0, 2)])

    def split(ka, kb, mx):
        springs = [dict(s) for s in chain.springs if s["name"] != "k3"] + [
            {"name": "k3a", "between": (k3["between"][0], "mx"), "value": ka},
            {"name": "k3b", "between": ("mx", "ground"), "value": kb}]
        return ow._linear(chain, ow._State(*_replace(chain, masses=chain.masses + [("mx", mx)],
                                                     springs=springs).matrices()))(meas_ch, f)
    mp, kp = 0.7, 2.5 * k3["value"]
    claimed = ow.claimed_data(chain, [{"kind": "pedestal", "station": 3, "element": "k3", "value": mp,
                                       "values": [mp, kp]}])
    assert ow.rms_log_change(claimed(meas_ch, f), split(k3["value"], kp, mp)) < 1e-10
    claimed = ow.claimed_data(chain, [{"kind": "absorber", "station": 3, "element": None, "value": mp / 4,
                                       "values": [mp / 4, k3["value"], 0.0]}])
    assert ow.rms_log_change(claimed(meas_ch, f), split(2 * k3["value"], 2 * k3["value"], mp)) < 1e-10
