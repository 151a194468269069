"""Models: every number equals `vibid modal --json`, `vibid frf` and `vibid simulate` on the same
model file (the same library functions; the CSV's shortest round-trip numbers read back exact)."""
import numpy as np
import pytest

import vibid
from conftest import ROOT, cli_json, run_cli

NOMINAL = ROOT / "examples" / "rig_nominal.json"


def test_modal_equals_cli_json():
    cli = cli_json("modal", NOMINAL, "--json")
    py = vibid.modal(vibid.load_model(NOMINAL))
    assert py.damping == cli["damping"]
    for i, mode in enumerate(cli["modes"]):
        assert py.omega_rad_s[i] == mode["omega_rad_s"]
        assert py.freq_hz[i] == mode["freq_hz"]
        assert py.zeta[i] == mode["zeta"]
        assert py.ratio[i] == mode["ratio"]
        np.testing.assert_array_equal(py.shapes[:, i], mode["shape"])


def test_modal_of_one_mass_closed_form():
    # omega = sqrt(k/m) (closed form), zeta = c / (2 sqrt(k m)).
    m = vibid.Model.chain([2.0], [800.0], [4.0])
    r = vibid.modal(m)
    assert r.omega_rad_s[0] == pytest.approx(20.0, rel=1e-14)
    assert r.zeta[0] == pytest.approx(4.0 / (2 * np.sqrt(800.0 * 2.0)), rel=1e-12)
    assert np.isnan(r.ratio[0])


def test_frf_equals_cli_csv(tmp_path):
    out = tmp_path / "frf.csv"
    r = run_cli("frf", NOMINAL, "--input", 2, "--output", "1,2", "--f-min-hz", 1, "--f-max-hz", 20,
                "--points", 50, "-o", out)
    assert r.returncode == 0, r.stderr
    cli = vibid.read_recording(out, time_column="freq_hz", fs_hz=1.0)
    f = np.linspace(1.0, 20.0, 50)
    py = vibid.frf(vibid.load_model(NOMINAL), f, input=2, outputs=[1, 2])
    assert py.h.shape == (2, 1, 50)
    np.testing.assert_array_equal(py.h[0, 0].real, cli["re_receptance_2_1"])
    np.testing.assert_array_equal(py.h[1, 0].imag, cli["im_receptance_2_2"])


def test_frf_static_closed_form():
    # At 0 Hz the receptance of a single spring is 1/k (closed form).
    py = vibid.frf(vibid.Model.chain([1.0], [500.0]), [0.0])
    assert py.h[0, 0, 0] == pytest.approx(1 / 500.0, rel=1e-15)


def test_simulate_equals_cli_csv(tmp_path):
    out = tmp_path / "sim.csv"
    spec = "halfsine:dof=2,amp=100,width=0.001"
    r = run_cli("simulate", NOMINAL, "--method", "exact", "--dt-s", 0.001, "--t-end-s", 0.5,
                "--force", spec, "-o", out)
    assert r.returncode == 0, r.stderr
    cli = vibid.read_recording(out)
    py = vibid.simulate(vibid.load_model(NOMINAL), 0.001, 0.5, force=spec, method="exact")
    np.testing.assert_array_equal(py.x_m[:, 1], cli["x2_m"])
    np.testing.assert_array_equal(py.a_m_s2[:, 0], cli["a1_m_s2"])


def test_model_dict_round_trip():
    m = vibid.load_model(NOMINAL)
    back = vibid.Model.from_dict(m.to_dict())
    np.testing.assert_array_equal(back.k_n_per_m, m.k_n_per_m)
    assert "Model(dofs=2" in repr(m)
