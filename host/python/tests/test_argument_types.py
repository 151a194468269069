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
    with pytest.raises(ValueError, match=r"masses_kg\[1\] is nan: every value must be a finite "
                                         r"number"):
        vibid.Model.chain([2.0, math.nan], [4000.0, 3000.0])
    with pytest.raises(ValueError, match=r"springs_n_per_m\[0\] is inf"):
        vibid.Model.chain([2.0], [math.inf])
    with pytest.raises(TypeError, match=r"masses_kg\[0\]: expected a number, got str"):
        vibid.Model.chain(["2"], [4000.0])


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
