"""The model writer (mutext.rotor.model_writer) and the extended model files the diagnosis writes with it.

Every kind's extended file is read back with the package's own model reader (loads_model), and the
parameter it holds is compared with the finding's value computed here from the file's original number
(nominal + change, or the added element's value); the original file's comments must all survive.
"""
from __future__ import annotations

import tomllib

import numpy as np
import pytest

from mutext.diagnose._extend import extended_model_text
from mutext.diagnose._hypotheses import hypotheses
from mutext.diagnose._result import Finding
from mutext.errors import ModelError
from mutext.rotor import data_path
from mutext.rotor.model import loads_model
from mutext.rotor.model_writer import ModelFile

THREE_MASS = data_path("three_mass.toml")

# a small rotor written in the file's inline form, with comments in awkward places
ROTOR = """# a test rotor: 4 elements, disk at 3
name = "small rotor"   # trailing comment
[shaft]
shear_modulus = 81.2e9
""" + "".join("""
[[station]]   # element
length = 0.25
outer_diameter = 0.05
youngs_modulus = 211e9
density = 7810
""" for _ in range(4)) + """
[[station]]
[[disk]]
station = 3
mass = 8.0      # kg
[[bearing]]
station = 1
stiffness = 1e6 # N/m, left
damping = 20.0
[[bearing]]
station = 5
stiffness = 2e6 # N/m, right
damping = 0.0
[[force]]
station = 3
[[sensor]]
station = 3
"""


def _comments(text: str) -> list:
    return [ln[ln.index("#"):].strip() for ln in text.splitlines() if "#" in ln]


def test_set_keeps_every_other_line_and_comment():
    text = ('# rig\n[[spring]]\nname = "a"\nstiffness = 1.0   # N/m\n\n'
            '[[spring]]   # second\nname = "b"\nstiffness = 3.0   # N/m, keep\nbetween = ["m", "ground"]\n\n'
            '[[mass]]\nname = "m"\nmass = 2\n')
    mf = ModelFile(text)
    assert mf.set("spring", lambda t: t["name"] == "b", "stiffness", 4.25, "changed") == 3.0
    out = mf.text()
    doc = tomllib.loads(out)
    assert [s["stiffness"] for s in doc["spring"]] == [1.0, 4.25]
    assert doc["mass"][0]["mass"] == 2
    # only the changed line differs
    assert len(out.splitlines()) == len(text.splitlines())
    diff = [(a, b) for a, b in zip(text.splitlines(), out.splitlines()) if a != b]
    assert len(diff) == 1 and diff[0][1].startswith("stiffness = 4.25") and "was 3.0" in diff[0][1]
    assert "# N/m, keep" in diff[0][1]


def test_tables_of_one_name_apart_in_the_file_keep_their_order_and_comments():
    # TOML appends a later [[spring]] to the same array; the writer groups the entries (a known property
    # of the round-trip parser) without changing what the file says
    text = ('# rig\n[[spring]]\nname = "a"\nstiffness = 1.0   # N/m\n\n[[mass]]\nname = "m"\nmass = 2\n\n'
            '[[spring]]   # second\nname = "b"\nstiffness = 3.0   # N/m, keep\nbetween = ["m", "ground"]\n')
    mf = ModelFile(text)
    mf.set("spring", lambda t: t["name"] == "b", "stiffness", 4.25, "changed")
    a, b = tomllib.loads(text), tomllib.loads(mf.text())
    a["spring"][1]["stiffness"] = 4.25
    assert a == b
    assert all(c in mf.text() for c in _comments(text))


def test_set_adds_a_missing_key_and_values_keep_full_precision():
    mf = ModelFile('[[bearing]]\nstation = 2\nstiffness = 1e7\n')
    v = 1.234567890123456e-3
    assert mf.set("bearing", lambda t: t["station"] == 2, "damping", v) is None
    assert tomllib.loads(mf.text())["bearing"][0]["damping"] == v


def test_append_creates_the_table_and_keeps_types():
    mf = ModelFile('name = "x"\n[[mass]]\nname = "m1"\nmass = 1.0\n')
    mf.append("spring", {"name": "k", "stiffness": 10.0, "between": ["m1", "ground"]}, "added spring")
    mf.append("mass", {"name": "m2", "mass": 0.5}, "added mass")
    out = mf.text()
    doc = tomllib.loads(out)
    assert doc["spring"] == [{"name": "k", "stiffness": 10.0, "between": ["m1", "ground"]}]
    assert [m["name"] for m in doc["mass"]] == ["m1", "m2"]
    assert "# added spring" in out and "# added mass" in out
    mf = ModelFile("[[bearing]]\nstation = 2\n")
    mf.append("bearing", {"station": 3, "stiffness": 1.0})
    assert tomllib.loads(mf.text())["bearing"][1]["station"] == 3       # an int stays an int
    assert isinstance(tomllib.loads(mf.text())["bearing"][1]["station"], int)


def test_scale_multiplies_listed_keys_in_arrays_and_plain_tables():
    text = ('[[damper]]\nname = "c1"\ndamping = 2.0 # N s/m\n[[damper]]\nname = "c2"\ndamping = 4\n'
            '[damping]\nmodal = 0.01\n')
    mf = ModelFile(text)
    assert mf.scale({"damper": ("damping",), "damping": ("modal", "alpha")}, 1.5) == 3
    doc = tomllib.loads(mf.text())
    assert [d["damping"] for d in doc["damper"]] == [3.0, 6.0]
    assert doc["damping"]["modal"] == pytest.approx(0.015, rel=1e-15)


@pytest.mark.parametrize("text,call,match", [
    ("[[spring\n", None, "not valid TOML"),
    ('[[spring]]\nname = "a"\nstiffness = 1.0\n', ("set", "spring", "b"), "no \\[\\[spring\\]\\] entry"),
    ('[[spring]]\nname = "a"\nstiffness = "soft"\n', ("set", "spring", "a"), "not a number"),
    ('[[spring]]\nname = "a"\nstiffness = 1.0\n', ("nan", "spring", "a"), "finite real number"),
    ('[[damper]]\nname = "a"\ndamping = true\n', ("scale", "damper", "a"), "not a plain number"),
    ('spring = 3\n', ("append", "spring", "a"), "not an array of tables"),
])
def test_bad_input_gets_named_errors(text, call, match):
    with pytest.raises(ModelError, match=match):
        mf = ModelFile(text, source="rig.toml")
        what, table, name = call
        if what == "set":
            mf.set(table, lambda t: t["name"] == name, "stiffness", 2.0)
        elif what == "nan":
            mf.set(table, lambda t: t["name"] == name, "stiffness", float("nan"))
        elif what == "scale":
            mf.scale({table: ("damping",)}, 2.0)
        else:
            mf.append(table, {"name": name})


def _finding(h, value):
    new = None if (h.added or h.gain is not None) else h.nominal + value
    return Finding(h.kind, h.station, h.element, value, h.unit, 0.0, 0.0, 0.0, h.description, True, False, new, h)


def _value_in_file(text, h, model):
    """The parameter's value in the extended file, read back by the model reader."""
    ext = loads_model(text, source="extended")
    return float(ext.values()[ext.parameter_names.index(h.parameter)])


def test_every_lumped_kind_is_written_and_read_back():
    text = open(THREE_MASS, encoding="utf-8").read()
    model = loads_model(text, source=THREE_MASS)
    original = tomllib.loads(text)
    hyps = [h for h in hypotheses(model) if h.gain is None and h.glob is None and not h.params and not h.run]
    assert {h.kind for h in hyps} == {"stiffness", "damping", "mass"} and any(h.added for h in hyps)
    for h in hyps:
        value = 0.37 * h.scale
        out = extended_model_text(text, _finding(h, value), model)
        # the expected number from the original file (not from the model the package built)
        table, key = {"stiffness": ("spring", "stiffness"), "damping": ("damper", "damping"),
                      "mass": ("mass", "mass")}[h.kind]
        old = next((t[key] for t in original.get(table, []) if t["name"] == h.element), None)
        want = value if h.added else old + value
        assert (old is None) == h.added
        assert _value_in_file(out, h, model) == pytest.approx(want, rel=1e-14), h.label
        assert all(c in out for c in _comments(text)), h.label


def test_every_rotor_kind_is_written_and_read_back():
    model = loads_model(ROTOR, source="small.toml")
    original = tomllib.loads(ROTOR)
    hyps = [h for h in hypotheses(model) if h.gain is None and h.glob is None]
    assert {h.kind for h in hyps} == {"bearing", "cross_coupling", "stiffness", "damping", "mass", "crack"}
    for h in hyps:
        value = 0.21 if h.kind == "crack" else 0.37 * h.scale
        out = extended_model_text(ROTOR, _finding(h, value), model)
        doc = tomllib.loads(out)
        if h.kind == "bearing":
            key = "stiffness" if h.order == 0 else "damping"
            old = next(b[key] for b in original["bearing"] if b["station"] == h.station)
            new = next(b[key] for b in doc["bearing"] if b["station"] == h.station)
            assert new == pytest.approx(old + value, rel=1e-14)
        if h.kind == "crack":
            assert doc["crack"] == [{"station": h.station, "depth_ratio": value}]
        else:
            ext = loads_model(out, source="extended")
            names = ext.parameter_names
            assert h.parameter in names or h.kind != "bearing", h.label
        assert all(c in out for c in _comments(ROTOR)), h.label
    # an added element is a new entry read back with its value, and the modes move the way it says
    h = next(h for h in hyps if h.kind == "mass" and h.station == 2)
    ext = loads_model(extended_model_text(ROTOR, _finding(h, 3.0), model), source="extended")
    M0, M1 = model.matrices()[0], ext.matrices()[0]
    dofs = h.dofs
    dM = M1 - M0
    assert np.allclose(dM[np.ix_(dofs, dofs)], 3.0 * np.eye(len(dofs)), rtol=1e-12)
    dM[np.ix_(dofs, dofs)] = 0.0
    assert np.max(np.abs(dM)) <= 1e-12 * np.max(np.abs(M0))


def test_damping_scale_writes_every_damping_value():
    text = open(THREE_MASS, encoding="utf-8").read()
    model = loads_model(text, source=THREE_MASS)
    from mutext.diagnose.faults import structure
    h = next(h for h in structure.candidates(model) if h.glob == "damping_scale")
    out = extended_model_text(text, _finding(h, 0.25), model)
    a, b = tomllib.loads(text), tomllib.loads(out)
    assert [d["damping"] * 1.25 for d in a["damper"]] == pytest.approx([d["damping"] for d in b["damper"]],
                                                                       rel=1e-15)
    assert all(c in out for c in _comments(text))


def test_an_absorber_is_written_as_a_mass_with_its_spring_and_damper():
    text = open(THREE_MASS, encoding="utf-8").read()
    model = loads_model(text, source=THREE_MASS)
    h = next(h for h in hypotheses(model) if h.kind == "absorber" and h.station == 2)
    f = _finding(h, 0.2)
    f.values, f.stds = (0.2, 150.0, 0.5), (0.0, 0.0, 0.0)
    out = extended_model_text(text, f, model)
    ext = loads_model(out, source="extended")
    n = model.layout.n_nodes
    assert ext.layout.n_nodes == n + 1
    M0, C0, K0, _ = model.matrices()
    M1, C1, K1, _ = ext.matrices()
    u = np.zeros(n + 1)
    u[1], u[n] = 1.0, -1.0                  # host m2 (index 1), the absorber last
    for X0, X1, v in ((K0, K1, 150.0), (C0, C1, 0.5)):
        want = np.zeros((n + 1, n + 1))
        want[:n, :n] = X0
        want += v * np.outer(u, u)
        assert np.allclose(X1, want, rtol=1e-14, atol=0)
    assert M1[n, n] == 0.2 and np.allclose(M1[:n, :n], M0)
    assert all(c in out for c in _comments(text))


def test_a_distributed_change_is_written_into_every_spring_of_its_run():
    text = open(THREE_MASS, encoding="utf-8").read()
    model = loads_model(text, source=THREE_MASS)
    original = {t["name"]: t["stiffness"] for t in tomllib.loads(text)["spring"]}
    runs = [h for h in hypotheses(model) if h.kind == "distributed_stiffness"]
    assert sorted(h.run for h in runs) == [("k1", "k2"), ("k1", "k2", "k3"), ("k2", "k3")]
    for h in runs:
        out = extended_model_text(text, _finding(h, -0.08), model)
        got = {t["name"]: t["stiffness"] for t in tomllib.loads(out)["spring"]}
        assert got == pytest.approx({k: v * (0.92 if k in h.run else 1.0) for k, v in original.items()},
                                    rel=1e-14)
        ext = loads_model(out, source="extended")
        # the screen's pattern is the stiffness change of the file read back
        dK = ext.matrices()[2] - model.matrices()[2]
        assert np.allclose(dK[np.ix_(h.dofs, h.dofs)], -0.08 * h.pattern, rtol=1e-12, atol=1e-12)
        assert all(c in out for c in _comments(text))


# ---------------------------------------------------------------------------
# [[impedance]]: a rational dynamic stiffness to ground, written and read back
# ---------------------------------------------------------------------------

def _three_mass_text() -> str:
    with open(THREE_MASS, encoding="utf-8") as fh:
        return fh.read()


def _with_impedance(num, den, mass="m2") -> str:
    mf = ModelFile(_three_mass_text())
    mf.append("impedance", {"name": "K_test", "mass": mass, "numerator": list(num), "denominator": list(den)},
              "a rational impedance")
    return mf.text()


def test_impedance_round_trip_keeps_coefficients_bit_for_bit():
    # coefficients with many digits: the file must hold the same doubles
    num = [0.123456789012345678, 21.987654321, 903.0000000001]
    den = [1.0, 8.33333333333333, 401.1111111111]
    text = _with_impedance(num, den)
    doc = tomllib.loads(text)
    assert doc["impedance"][0]["numerator"] == num and doc["impedance"][0]["denominator"] == den
    el = loads_model(text).element_by_name["K_test"]
    assert el.numerator.tolist() == num and el.denominator.tolist() == den
    assert el.nodes == (2,) and el.order == 2
    # the comments of the original file survive
    assert set(_comments(_three_mass_text())) <= set(_comments(text))


def test_impedance_frf_and_state_space_equal_the_base_model_with_k_in_feedback():
    import control as ct
    num, den = [1.0, 60.0, 7000.0], [1.0, 6.0, 350.0]
    base = loads_model(_three_mass_text())
    ext = loads_model(_with_impedance(num, den))
    f = np.linspace(0.3, 6.0, 80)
    # independent: python-control closes u = -K(s) x2 around the base model's state space with a force at m2
    plant = loads_model(_three_mass_text() + '\n[[force]]\nname = "u_K"\nmass = "m2"\n[[sensor]]\nname = "y_K"\n'
                        'mass = "m2"\n').state_space(inputs=["f1", "u_K"], outputs=["x1", "x3", "y_K"])
    Kblk = ct.ss(ct.tf([[[0.0], [0.0], [0.0]], [[0.0], [0.0], num]],
                       [[[1.0], [1.0], [1.0]], [[1.0], [1.0], den]]))
    closed = ct.feedback(plant, Kblk, sign=-1)
    ref = closed.frequency_response(2 * np.pi * f).frdata[:2, 0, :]
    H = ext.frf(f, inputs=["f1"], outputs=["x1", "x3"]).H[:, 0, :]
    assert np.max(np.abs(H - ref) / np.abs(ref)) < 1e-9
    S = ext.state_space(inputs=["f1"], outputs=["x1", "x3"])
    assert S.nstates == base.state_space().nstates + 2
    Hs = S.frequency_response(2 * np.pi * f).frdata[:, 0, :]
    assert np.max(np.abs(Hs - ref) / np.abs(ref)) < 1e-9
    # the element changes the response (the check above is not trivially the base model)
    H0 = base.frf(f, inputs=["f1"], outputs=["x1", "x3"]).H[:, 0, :]
    assert np.max(np.abs(H0 - ref) / np.abs(ref)) > 0.1


@pytest.mark.parametrize("num, den, match", [
    ([1.0, 2.0, 3.0], [1.0, 2.0], "numerator: degree 2 exceeds"),
    ([1.0], [0.0, 1.0], "denominator: the leading coefficient"),
    ([0.0, 0.0], [1.0, 1.0], "numerator: all coefficients are 0"),
    ([1.0], [1.0, 0.0, 4.0], "denominator: a pole on the imaginary axis"),
    ([1.0], [], r"\[\[impedance\]\] #1, denominator"),
    ([1.0, "a"], [1.0, 1.0], r"\[\[impedance\]\] #1, numerator\[1\]"),
])
def test_impedance_bad_coefficients_name_the_field(num, den, match):
    text = _three_mass_text() + (f'\n[[impedance]]\nname = "Kbad"\nmass = "m1"\nnumerator = {_toml_list(num)}\n'
                                 f'denominator = {_toml_list(den)}\n')
    with pytest.raises(ModelError, match=match):
        loads_model(text)


def _toml_list(v) -> str:
    return "[" + ", ".join(f'"{x}"' if isinstance(x, str) else repr(float(x)) for x in v) + "]"


def test_impedance_unknown_mass_and_key_are_named():
    bad_mass = _three_mass_text() + '\n[[impedance]]\nname = "K"\nmass = "m9"\nnumerator = [1.0]\ndenominator = [1.0]\n'
    with pytest.raises(ModelError, match=r"\[\[impedance\]\] #1, mass: unknown mass 'm9'"):
        loads_model(bad_mass)
    bad_key = bad_mass.replace('mass = "m9"', 'mass = "m1"\nnumerater = [1.0]')
    with pytest.raises(ModelError, match="unknown key 'numerater'"):
        loads_model(bad_key)


def test_impedance_writer_refuses_non_finite_coefficients():
    mf = ModelFile(_three_mass_text())
    with pytest.raises(ModelError, match=r"new \[\[impedance\]\] entry, 'numerator'\[1\]"):
        mf.append("impedance", {"name": "K", "mass": "m1", "numerator": [1.0, float("nan")],
                                "denominator": [1.0, 1.0]})


def test_modes_of_a_model_with_an_impedance_are_refused_by_name():
    ext = loads_model(_with_impedance([1.0, 10.0], [1.0, 5.0]))
    with pytest.raises(ModelError, match="impedance element 'K_test'"):
        ext.natural_frequencies()


def test_impedance_in_an_inch_pound_file_is_a_stiffness_in_lbf_per_inch():
    # K(s) = 2 lbf/in (a constant): 2 * 4.4482216152605 N / 0.0254 m, the exact definitions
    text = ('units = "inch-pound"\n[[mass]]\nname = "m1"\nmass = 10.0\n[[spring]]\nname = "k1"\nstiffness = 50.0\n'
            'between = ["m1", "ground"]\n[[impedance]]\nname = "K"\nmass = "m1"\nnumerator = [2.0]\n'
            'denominator = [1.0]\n')
    el = loads_model(text).element_by_name["K"]
    assert el.response(np.array([3.0]))[0] == pytest.approx(2 * 4.4482216152605 / 0.0254, rel=1e-12)


def test_impedance_belongs_to_a_lumped_chain():
    from mutext.rotor.assembly import Structure
    from mutext.rotor.lumped_elements import Impedance, Spring
    with pytest.raises(ModelError, match="impedance element belongs to a lumped chain"):
        Structure([Spring(1, k=1.0), Impedance(1, [1.0], [1.0, 1.0])], layout="plane", n_nodes=1)


def test_diagnosis_receptance_holds_the_impedance_and_tune_refuses_it(tmp_path):
    # a model extended by model-based identification is diagnosed again: the screen's receptance must
    # include K(jw) (checked against python-control's feedback loop), and tune(), which fits M, C, K
    # alone, must say so instead of leaving the element out
    import control as ct
    from mutext.diagnose._screen import _Receptance
    from mutext.rotor.tuning import tune
    num, den = [1.0, 60.0, 7000.0], [1.0, 6.0, 350.0]
    ext = loads_model(_with_impedance(num, den))
    f = np.linspace(0.3, 6.0, 40)
    rec = _Receptance(ext, ext.values(), 0.0, 2 * np.pi * f)
    plant = loads_model(_three_mass_text() + '\n[[force]]\nname = "u_K"\nmass = "m2"\n[[sensor]]\nname = "y_K"\n'
                        'mass = "m2"\n').state_space(inputs=["f1", "u_K"], outputs=["x1", "x3", "y_K"])
    Kblk = ct.ss(ct.tf([[[0.0], [0.0], [0.0]], [[0.0], [0.0], num]],
                       [[[1.0], [1.0], [1.0]], [[1.0], [1.0], den]]))
    ref = ct.feedback(plant, Kblk, sign=-1).frequency_response(2 * np.pi * f).frdata[:2, 0, :]
    b = rec.input_vector(("port", ext.input_names.index("f1")))
    H = np.einsum("kij,j->ik", rec.R, b)[[0, 2]]          # x1, x3: DOFs 0 and 2 of the chain
    assert np.max(np.abs(H - ref) / np.abs(ref)) < 1e-9
    frf = ext.frf(f, inputs=["f1"], outputs=["x1"]).channel("x1", "f1")
    with pytest.raises(ModelError, match="impedance element 'K_test'"):
        tune(ext, [frf], ["k1"])


# ----------------------------------------------------------------------------- files in inch-pound units

#: SI per inch-pound unit, from the definitions (1 in = 0.0254 m, 1 lb = 0.45359237 kg, g0 = 9.80665 m/s^2)
LB, LBF_PER_IN = 0.45359237, 0.45359237 * 9.80665 / 0.0254


def _inch_pound_three_mass() -> str:
    """three_mass.toml with its numbers in lb and lbf/in, lbf s/in (converted here, not by the package)."""
    doc = tomllib.loads(open(THREE_MASS, encoding="utf-8").read())
    lines = [f'name = "{doc["name"]} in inch-pound"', 'units = "inch-pound"']
    for table, key, f in (("mass", "mass", LB), ("spring", "stiffness", LBF_PER_IN),
                          ("damper", "damping", LBF_PER_IN)):
        for t in doc.get(table, []):
            lines += [f"[[{table}]]", f'name = "{t["name"]}"', f"{key} = {t[key] / f!r}"]
            if "between" in t:
                lines.append(f"between = {t['between']!r}".replace("'", '"'))
    for table in ("force", "sensor"):
        for t in doc.get(table, []):
            lines.append(f"[[{table}]]")
            lines += [f"{k} = {v!r}".replace("'", '"') for k, v in t.items()]
    return "\n".join(lines) + "\n"


def test_findings_are_written_in_the_units_of_an_inch_pound_file():
    # the diagnosis's sizes are SI; written into an inch-pound file they must read back as the same SI values
    text = _inch_pound_three_mass()
    model = loads_model(text, source="ip.toml")
    si = loads_model(open(THREE_MASS, encoding="utf-8").read(), source=THREE_MASS)
    np.testing.assert_allclose(model.values(), si.values(), rtol=1e-12)        # the file itself converts right
    hyps = [h for h in hypotheses(model) if h.gain is None and h.glob is None and not h.run]
    kinds = {h.kind for h in hyps}
    assert {"stiffness", "damping", "mass", "absorber", "pedestal"} <= kinds
    for h in hyps:
        if h.params:                       # absorber, pedestal: several parameters, compared in the matrices
            continue
        value = 0.37 * h.scale
        out = extended_model_text(text, _finding(h, value), model)
        want = value if h.added else h.nominal + value
        assert _value_in_file(out, h, model) == pytest.approx(want, rel=1e-12), h.label
    for h in (h for h in hyps if h.params):
        values = np.array([0.37 * p.scale for p in h.params])
        f = _finding(h, float(values[0]))
        f.values, f.stds = values, np.zeros_like(values)
        ip = loads_model(extended_model_text(text, f, model), source="ip")
        ref = loads_model(extended_model_text(open(THREE_MASS, encoding="utf-8").read(), f, si), source="si")
        for a, b in zip(ip.matrices(), ref.matrices()):
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12 * np.max(np.abs(b))), h.label


def test_si_values_need_a_known_unit():
    mf = ModelFile('units = "inch-pound"\n[[spring]]\nname = "k1"\nstiffness = 2.0\n', source="f.toml")
    mf.set("spring", lambda t: t["name"] == "k1", "stiffness", LBF_PER_IN * 3.0, si=True)
    assert tomllib.loads(mf.text())["spring"][0]["stiffness"] == pytest.approx(3.0, rel=1e-14)
    with pytest.raises(ModelError, match="no unit is known"):
        mf.set("spring", lambda t: t["name"] == "k1", "colour", 1.0, si=True)
