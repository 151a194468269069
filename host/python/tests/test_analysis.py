"""FRF estimation and modes: the numbers of `vibid frf-estimate` and `vibid modes --json` on the
same recording (the LADISK impact hammer record, testdata/), and H1 / coherence against
scipy.signal.csd / welch on the same segments."""
import time

import numpy as np
import pytest
import scipy.signal

import vibid
from conftest import ROOT, cli_json, run_cli

LADISK = ROOT / "testdata" / "ladisk_impact_hammer" / "impact_acceleration_force.csv"


def test_frf_estimate_equals_cli(tmp_path):
    out = tmp_path / "frf.csv"
    r = run_cli("frf-estimate", LADISK, "--force", "force_N", "--response", "acceleration_g:g",
                "-o", out)
    assert r.returncode == 0, r.stderr
    # The FRF file is a plain CSV (its facts in frf.csv.json beside it): numpy's default reader
    # takes it and gives back the values exactly.
    cli = np.genfromtxt(out, delimiter=",", names=True)
    py = vibid.frf_estimate(LADISK, force="force_N", responses="acceleration_g:g")
    assert py.impact  # the force is a train of hits: per-hit records, as the CLI decided
    assert py.frd.h.shape[:2] == (1, 1)
    np.testing.assert_array_equal(py.frd.h[0, 0].real, cli["acceleration_g_re"])
    np.testing.assert_array_equal(py.frd.h[0, 0].imag, cli["acceleration_g_im"])
    np.testing.assert_array_equal(py.frd.coherence[0, 0], cli["acceleration_g_coh"])
    assert all(isinstance(h, vibid.Hit) for h in py.hits) and any(h.used for h in py.hits)


def test_modes_equal_cli_json():
    cli = cli_json("modes", LADISK, "--force", "force_N", "--response", "acceleration_g:g",
                   "--json")
    py = vibid.modes(LADISK, force="force_N", responses="acceleration_g:g")
    assert py.json == cli
    assert py.freq_hz[0] == cli["modes"][0]["freq_hz"]
    assert py.stabilization is not None and py.stabilization["order"].size > 0
    assert py.ci95["zeta"].shape == (len(cli["modes"]), 2)


def test_modes_of_an_estimate_in_memory_equal_the_files():
    # An array already in memory: the estimate's own FRF gives exactly what `vibid modes` gives
    # on the recording (the CLI's JSON, notes aside: no file was read).
    cli = cli_json("modes", LADISK, "--force", "force_N", "--response", "acceleration_g:g",
                   "--json")
    est = vibid.frf_estimate(LADISK, force="force_N", responses="acceleration_g:g")
    py = vibid.modes(est)
    cli.pop("notes")
    mine = dict(py.json)
    mine.pop("notes")
    assert mine == cli
    # An Frd holds the FRF only, not the hits' ring-downs: no amplitude check, the rest equal.
    assert vibid.modes(est.frd).json["modes"] == [
        {k: v for k, v in m.items() if k != "zeta_amplitude"} for m in cli["modes"]]


def test_modes_of_an_frd_from_arrays_are_the_model_s():
    # A closed-form receptance (vibid.frf of the example chain, coherence 1) as a user would
    # bring one: the modes are the model's undamped frequencies (vibid.modal), to 0.1 %.
    model = vibid.load_model(ROOT / "examples" / "rig_nominal.json")
    frd = vibid.frf(model, np.arange(0.1, 30.0, 0.05), input=2)
    frd = vibid.Frd(freq_hz=frd.freq_hz, h=frd.h, kind=frd.kind, outputs=frd.outputs,
                    inputs=frd.inputs)
    found = sorted(m["freq_hz"] for m in vibid.modes(frd, method="fit").json["modes"])
    expected = sorted(vibid.modal(model).freq_hz)
    assert len(found) == len(expected)
    for f, e in zip(found, expected):
        assert abs(f - e) < 1e-3 * e, (found, expected)


def test_h1_and_coherence_equal_scipy_on_the_same_segments():
    rng = np.random.default_rng(11)
    fs = 1000.0
    f = rng.normal(size=8192)
    b, a = scipy.signal.butter(2, 0.1)
    x = np.vstack([scipy.signal.lfilter(b, a, f) + 0.1 * rng.normal(size=f.size),
                   np.roll(f, 3) + 0.2 * rng.normal(size=f.size)])
    est = vibid.frf_estimate_arrays(f, x, fs, welch=True, segment=512, overlap=256,
                                    window="hann", kind="accelerance", sensor="acc")
    kw = dict(fs=fs, window="hann", nperseg=512, noverlap=256, detrend=False)
    _, gff = scipy.signal.welch(f, **kw)
    for i in range(2):
        _, gfx = scipy.signal.csd(f, x[i], **kw)  # E[F* X], as the library's G_fx
        _, gxx = scipy.signal.welch(x[i], **kw)
        np.testing.assert_allclose(est.frd.h[i, 0], gfx / gff, rtol=1e-9)
        np.testing.assert_allclose(est.frd.coherence[i, 0], np.abs(gfx) ** 2 / (gff * gxx),
                                   rtol=1e-9, atol=1e-12)


BAD_INPUTS = [
    # (call, exception, message fragment: the library's message, as the CLI prints it)
    (lambda: vibid.frf_estimate_arrays(np.array([1.0, np.nan, 2.0] * 100), np.ones((1, 300)),
                                       1000.0, welch=True, segment=64, sensor="acc"),
     ValueError, "the force signal holds NaN or infinite samples"),
    (lambda: vibid.frf_estimate_arrays(np.ones(300), np.ones((1, 299)), 1000.0, sensor="acc"),
     ValueError, "samples"),
    (lambda: vibid.frf_estimate_arrays(np.ones((2, 300)), np.ones((1, 300)), 1000.0,
                                       sensor="acc"),
     ValueError, "force must be 1-D (samples,), not 2-D"),
    (lambda: vibid.frf_estimate_arrays(np.ones(300), np.ones((1, 1, 300)), 1000.0, sensor="acc"),
     ValueError, "responses must be 2-D (channels, samples), not 3-D"),
    (lambda: vibid.frf_estimate_arrays(np.zeros(0), np.zeros((1, 0)), 1000.0, sensor="acc"),
     ValueError, "the force signal is empty"),
    (lambda: vibid.frf_estimate_arrays(np.ones(300), np.ones((1, 300)), 1000.0, estimator="h3",
                                       sensor="acc"),
     ValueError, "h3"),
    (lambda: vibid.frf_estimate_arrays(np.array(["a"] * 300), np.ones((1, 300)), 1000.0,
                                       sensor="acc"),
     TypeError, "force: expected real numbers (float64), got dtype <U1"),
    (lambda: vibid.frf_estimate_arrays(np.ones(300), np.ones((1, 300), dtype=complex), 1000.0,
                                       sensor="acc"),
     TypeError, "responses: expected real numbers (float64), got dtype complex128"),
    (lambda: vibid.dob_compare(np.ones(10), np.ones(9), 100.0), ValueError, "length"),
    (lambda: vibid.frf_estimate(LADISK, force="nope", responses="acceleration_g:g"),
     ValueError, "nope"),
    (lambda: vibid.read_recording(ROOT / "no_such_file.csv"), FileNotFoundError, "no such file"),
    (lambda: vibid.Model([[1.0]], [[-5.0]]), ValueError, "semidefinite"),
    (lambda: vibid.simulate(vibid.Model.chain([1.0], [100.0]), 0.001, 0.1, force="step:dof=1,amp=1",
                            method="leapfrog"),
     ValueError, "leapfrog"),
    (lambda: vibid.frf(vibid.Model.chain([1.0], [100.0]), [1.0], input=2),
     ValueError, "--input 2 is out of range 1..1"),
    (lambda: vibid.modes(LADISK, force="force_N", responses="acceleration_g:g", method="magic"),
     ValueError, "magic"),
    (lambda: vibid.Recording.from_sep005([]), ValueError, "no channels"),
    (lambda: vibid.Recording(["x1_m"], np.zeros((1, 0)), 100.0).write_csv("/tmp/never.csv"),
     ValueError, "the recording is empty (no samples)"),
    (lambda: vibid.Board("bogus://x"), ValueError, "bogus://x"),
    (lambda: vibid.dob_design(vibid.load_model(ROOT / "examples" / "rig_nominal.json"),
                              input_dof=3), ValueError, "--input-dof 3 is out of range 1..2"),
    (lambda: vibid.dob_design(vibid.load_model(ROOT / "examples" / "rig_nominal.json"),
                              form="mixed"), ValueError, "--form 'mixed' is not one of siso, mimo"),
    (lambda: vibid.decay([], position="x1_m"), ValueError, "no recordings"),
]


@pytest.mark.parametrize("call,exc,message", BAD_INPUTS)
def test_bad_input_raises_with_message(call, exc, message):
    with pytest.raises(exc) as e:
        call()
    assert message in str(e.value)


def test_a_long_computation_lets_other_python_threads_run():
    # The GIL is released while the library computes: a Python thread beside a 2^22-sample FRF
    # estimation keeps running. With the GIL held it would stop for the whole call (its longest
    # pause would be the call's length); released, its pauses stay near the interpreter's 5 ms
    # switch interval.
    import threading
    rng = np.random.default_rng(1)
    n = 1 << 22
    force = rng.standard_normal(n)
    responses = np.ascontiguousarray(np.vstack([np.convolve(force, [0.5, 0.25])[:n]] * 2))
    done = threading.Event()
    timing = {}

    def compute():
        t0 = time.perf_counter()
        try:
            vibid.frf_estimate_arrays(force, responses, 1000.0, welch=True, sensor="disp")
            timing["call_s"] = time.perf_counter() - t0
        finally:
            done.set()

    worker = threading.Thread(target=compute)
    longest = 0.0
    last = time.perf_counter()
    worker.start()
    while not done.is_set():
        now = time.perf_counter()
        longest = max(longest, now - last)
        last = now
    worker.join()
    assert timing["call_s"] > 0.05, timing  # long enough to tell the two apart
    assert longest < 0.5 * timing["call_s"], (longest, timing)
