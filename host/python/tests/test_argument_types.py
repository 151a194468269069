"""Calls that must work on the package's own types, and fail on others with Python's own kind of
error: a Recording in memory where a recording is taken, TypeError for a path where a Model is
wanted, FileNotFoundError for a file that is not there, ValueError for a NaN in a model, the Model
constructor as documented, and an FRF from arrays only for responses whose quantity is known."""
import math

import numpy as np
import pytest

import vibid
from conftest import ROOT

NOMINAL = ROOT / "examples" / "rig_nominal.json"


def hammer_recording(path=None):
    """A hammer test of the example chain (vibid.simulate, exact discretization), four hits on
    mass 2, accelerations of both masses with 1e-4 m/s^2 of noise: a Recording in memory, and its
    CSV at `path`."""
    model = vibid.load_model(NOMINAL)
    sim = vibid.simulate(model, 1 / 1000, 40.0, [f"halfsine:dof=2,amp=100,width=0.004,t0={t}"
                                                 for t in (0.5, 10.5, 20.5, 30.5)], method="exact")
    rng = np.random.default_rng(3)
    acc = sim.a_m_s2.T + 1e-4 * rng.standard_normal(sim.a_m_s2.T.shape)
    rec = vibid.Recording(names=["force1_n", "acc1_m_s2", "acc2_m_s2"],
                          data=np.vstack([sim.force_n[:, 1][None, :], acc]), fs_hz=1000.0)
    if path is not None:
        rec.write_csv(path)
    return rec


def test_modes_of_a_recording_in_memory_equal_those_of_its_file(tmp_path):
    # vibid.modes(vibid.read_recording(path), force=..., responses=...) is the modes of the
    # recording, not of a list of paths ("unknown column '0'").
    path = tmp_path / "hammer.csv"
    hammer_recording(path)
    args = dict(force="force1_n", responses="acc1_m_s2,acc2_m_s2")
    from_file = vibid.modes(path, **args)
    in_memory = vibid.modes(vibid.read_recording(path), **args)
    assert in_memory.json["modes"] == from_file.json["modes"]
    # The modes are the chain's (vibid.modal, the closed form of its matrices), within 0.5 %.
    truth = vibid.modal(vibid.load_model(NOMINAL)).freq_hz
    np.testing.assert_allclose(np.sort(in_memory.freq_hz), np.sort(truth), rtol=5e-3)


def test_a_path_where_a_model_is_wanted_is_a_type_error():
    for call in (lambda: vibid.modal(str(NOMINAL)), lambda: vibid.modal(NOMINAL),
                 lambda: vibid.frf("rig.json", [1.0]), lambda: vibid.simulate("rig.json", 0.001, 1),
                 lambda: vibid.dob_design("rig.json"),
                 lambda: vibid.identify("rig.json", {}, [])):
        with pytest.raises(TypeError, match=r"expected a vibid\.Model, got (str|PosixPath) \(a "
                                            r"model file: vibid\.load_model\(path\)\)"):
            call()
    with pytest.raises(TypeError, match="model: expected a vibid.Model, got int"):
        vibid.modal(3)


def test_a_missing_file_is_file_not_found(tmp_path):
    missing = tmp_path / "nowhere.csv"
    for call in (lambda: vibid.read_recording(missing), lambda: vibid.load_model(missing),
                 lambda: vibid.frf_estimate(missing, force="f", responses="x"),
                 lambda: vibid.modes(missing, force="f", responses="x"),
                 lambda: vibid.decay(missing, position="x1_m"),
                 lambda: vibid.identify(vibid.load_model(NOMINAL), {}, [missing]),
                 lambda: vibid.dob_design(vibid.load_model(NOMINAL), sensors=missing),
                 lambda: vibid.Recording(["x_m"], np.zeros((1, 8)), 10.0).write_csv(
                     tmp_path / "no_folder" / "r.csv")):
        with pytest.raises(FileNotFoundError) as e:
            call()
        assert e.value.filename in (str(missing), str(tmp_path / "no_folder"))
        assert isinstance(e.value, OSError)  # what `except OSError` around file code catches


def test_a_model_with_a_nan_is_a_value_error_naming_it():
    # Every message counts masses, springs and dampers from 1, as a model file's do: a NaN, a
    # mass <= 0 and a value that is not a number name the same mass the same way.
    def refusal(kind, call):
        with pytest.raises(kind) as e:
            call()
        return str(e.value)
    assert refusal(ValueError, lambda: vibid.Model.chain([2.0, math.nan], [4000.0, 3000.0])) == \
        'Model.chain: field "masses"[2] = nan must be a finite number'
    assert refusal(ValueError, lambda: vibid.Model.chain([2.0, -1.0], [4000.0, 3000.0])) == \
        "Model.chain: masses[2] = -1 must be finite and > 0"
    assert refusal(TypeError, lambda: vibid.Model.chain([2.0, "2"], [4000.0, 3000.0])) == \
        "masses_kg: mass 2: expected a number, got str '2'"
    assert refusal(ValueError, lambda: vibid.Model.chain([2.0], [math.inf])) == \
        'Model.chain: field "springs"[1] = inf must be a finite number'
    assert refusal(ValueError, lambda: vibid.Model.chain([2.0, 1.0], [1.0, 2.0], [0.0, -0.5])) \
        == "Model.chain: dampers[2] = -0.5 must be finite and >= 0"


def test_a_model_dict_with_a_nan_names_the_field():
    # json.dumps' own "Out of range float values are not JSON compliant" names no field.
    chain = {"topology": "chain", "masses": [2.0, 1.0], "springs": [4000.0, -math.inf]}
    with pytest.raises(ValueError) as e:
        vibid.Model.from_dict(chain, "rig.json")
    assert str(e.value) == 'rig.json: field "springs"[2] = -inf must be a finite number'
    matrices = {"M": [[2.0, 0.0], [0.0, 1.0]], "K": [[7000.0, -3000.0], [-3000.0, math.nan]]}
    with pytest.raises(ValueError) as e:
        vibid.Model.from_dict(matrices)
    assert str(e.value) == 'model: field "K"[2][2] = nan must be a finite number'
    # numpy's scalars are floats too
    with pytest.raises(ValueError, match=r'field "masses"\[1\] = nan'):
        vibid.Model.from_dict({"topology": "chain", "masses": [np.float64("nan")],
                               "springs": [1.0]})


def test_identify_names_an_argument_of_the_wrong_type():
    nominal = vibid.load_model(NOMINAL)
    with pytest.raises(TypeError) as e:
        vibid.identify(nominal, [], [])
    assert str(e.value) == ("mass_tests: expected a dict {position: recording} (positions from "
                            "1, e.g. {1: 'mass1.csv'}), got list []")
    with pytest.raises(TypeError, match=r"^mass_springs: expected a dict \{position: N/m or "
                                        r"'fit'\}, got list"):
        vibid.identify(nominal, {}, [], mass_springs=[4000.0])
    with pytest.raises(TypeError, match=r"^modal_tests: expected a recording's path or a list "
                                        r"of them, got int"):
        vibid.identify(nominal, {}, 3)


def test_the_version_is_the_build_s():
    # The CLI's own --version, from the same CMake project version.
    from conftest import run_cli
    r = run_cli("--version")
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == f"vibid {vibid.__version__}"
    assert vibid.__version__.count(".") == 2


def test_the_model_constructor_takes_the_matrices_as_documented():
    # M, K, C as matrices in kg, N/m, N s/m; a 1-D m_kg is the lumped masses' diagonal. The
    # chain's matrices by hand: K = [[k1 + k2, -k2], [-k2, k2]].
    m1, m2, k1, k2, c1, c2 = 2.0, 1.5, 4000.0, 3000.0, 5.0, 3.5
    k = [[k1 + k2, -k2], [-k2, k2]]
    c = [[c1 + c2, -c2], [-c2, c2]]
    chain = vibid.Model.chain([m1, m2], [k1, k2], [c1, c2])
    for model in (vibid.Model(np.diag([m1, m2]), k, c), vibid.Model([m1, m2], k, c)):
        np.testing.assert_array_equal(model.m_kg, chain.m_kg)
        np.testing.assert_array_equal(model.k_n_per_m, chain.k_n_per_m)
        np.testing.assert_array_equal(model.c_ns_per_m, chain.c_ns_per_m)
    undamped = vibid.Model([m1, m2], k)
    np.testing.assert_array_equal(undamped.c_ns_per_m, np.zeros((2, 2)))
    # Springs as a vector are a chain's, not a stiffness matrix: refused, pointing there.
    with pytest.raises(ValueError, match=r"k_n_per_m must be a square matrix .* not shaped "
                                         r"\(2,\) \(springs of a chain: Model\.chain"):
        vibid.Model([m1, m2], [k1, k2])


def test_an_frf_from_arrays_knows_what_its_responses_measure():
    # A spring alone: x = F / k. Its receptance is 1/k at every line, the closed form, when the
    # response is a displacement (named x1_m, or sensor="disp"); read as an acceleration it would
    # be -1/(k omega^2), so a response of unnamed quantity is refused, not assumed.
    k = 2500.0
    rng = np.random.default_rng(7)
    force = rng.standard_normal(1 << 14)
    x = force / k
    by_name = vibid.frf_estimate_arrays(force, x, 1000.0, response_names=["x1_m"], welch=True)
    by_sensor = vibid.frf_estimate_arrays(force, x, 1000.0, sensor="disp", welch=True)
    for e in (by_name, by_sensor):
        h = e.frd.h[0, 0][1:]
        np.testing.assert_allclose(h, 1 / k, rtol=1e-9, atol=1e-15)
    # Named as an acceleration, it is one: receptance -a / (omega^2 F) = -1/(k omega^2).
    as_acc = vibid.frf_estimate_arrays(force, x, 1000.0, response_names=["acc1_m_s2"], welch=True)
    w = 2 * np.pi * as_acc.frd.freq_hz[1:]
    np.testing.assert_allclose(as_acc.frd.h[0, 0][1:], -1 / (k * w ** 2), rtol=1e-9)
    with pytest.raises(ValueError, match=r"what do the responses measure\? response1 names no "
                                         r"unit: give sensor='acc', 'vel' or 'disp'"):
        vibid.frf_estimate_arrays(force, x, 1000.0, welch=True)
