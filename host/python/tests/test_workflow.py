"""The demo's workflow against vibid-emu, each step from Python beside the CLI on the same files:
identify's updated model and report data, the observer design file, the board's d_hat equal to
the Python replay bit for bit and following the disturbance a second load cell measures
(scripts/workflow's steps and figures, shorter tests)."""
import dataclasses
import json

import numpy as np
import pytest

import vibid
from conftest import ROOT, Emulator, run_cli

NOMINAL = ROOT / "examples" / "rig_nominal.json"
SENSORS = ROOT / "examples" / "sensors.json"
FORCE_FS_N = json.loads(SENSORS.read_text())["channels"]["force1"]["full_scale"]


def ok(*args, device=None):
    r = run_cli(*args, device=device)
    assert r.returncode == 0, r.stderr
    return r


@pytest.fixture(scope="module")
def tests(tmp_path_factory):
    """Mass tests (each mass alone, 10 blows) and two modal tests (6 blows on m2), recorded by
    `vibid acquire` from a calibrated emulator, as scripts/workflow records them."""
    d = tmp_path_factory.mktemp("workflow")
    emu = Emulator(d, seed=1)
    try:
        ok("dob", "design", NOMINAL, "--force-fs-n", FORCE_FS_N, "--fs-hz", 1000,
           "-o", d / "design_nominal.json")
        ok("cal", "upload", NOMINAL, "--design", d / "design_nominal.json", "--sensors", SENSORS,
           device=emu.url)
        ok("cal", "commit", device=emu.url)
        for m in (1, 2):
            ok("acquire", "--seconds", 50, "--rate-hz", 5000, "--channels", f"force1,acc{m}",
               "--no-dob", "--scenario", "hammer", "--scenario-param", f"{m},200,5,{m}",
               "-o", d / f"mass{m}.csv", device=emu.url)
        for t in (1, 2):
            ok("acquire", "--seconds", 72, "--rate-hz", 5000, "--channels", "force1,acc1,acc2",
               "--no-dob", "--scenario", "hammer", "--scenario-param", "2,200,12,0",
               "-o", d / f"modal{t}.csv", device=emu.url)
        yield d, emu
    finally:
        emu.stop()


def test_identify_equals_cli(tests):
    d, _ = tests
    ok("identify", "--nominal", NOMINAL, "--mass-test", f"1={d / 'mass1.csv'}",
       "--mass-test", f"2={d / 'mass2.csv'}", "--mass-spring", "1=fit", "--mass-spring", "2=fit",
       "--modal-test", d / "modal1.csv", "--modal-test", d / "modal2.csv", "--exp-window", 0.1,
       "-o", d / "updated.json", "--report", d / "report")
    py = vibid.identify(vibid.load_model(NOMINAL),
                        mass_tests={1: d / "mass1.csv", 2: d / "mass2.csv"},
                        mass_springs={1: "fit", 2: "fit"},
                        modal_tests=[d / "modal1.csv", d / "modal2.csv"], exp_window=0.1)
    assert py.report == json.loads((d / "report" / "report.json").read_text())
    assert py.validation == (d / "report" / "validation.txt").read_text()
    cli_model = vibid.load_model(d / "updated.json")
    np.testing.assert_array_equal(py.updated.m_kg, cli_model.m_kg)
    np.testing.assert_array_equal(py.updated.k_n_per_m, cli_model.k_n_per_m)
    # The emulator's rig is m1 = 1.82 kg, m2 = 1.53 kg (vibid-emu --print-truth): within 1 %.
    np.testing.assert_allclose(np.diag(py.updated.m_kg), [1.82, 1.53], rtol=0.01)


def test_modes_of_a_modal_test_equal_cli(tests):
    d, _ = tests
    r = ok("modes", d / "modal1.csv", "--force", "force1_n", "--response", "acc1_m_s2,acc2_m_s2",
           "--exp-window", 0.1, "--json")
    py = vibid.modes(d / "modal1.csv", force="force1_n", responses="acc1_m_s2,acc2_m_s2",
                     exp_window=0.1)
    assert py.json == json.loads(r.stdout)
    assert py.freq_hz.size == 2 and np.all(np.isfinite(py.ci95["omega_rad_s"]))


def test_observer_design_equals_cli_and_the_board_equals_the_replay(tests):
    d, emu = tests
    model = vibid.load_model(NOMINAL)
    design = vibid.dob_design(model, force_fs_n=FORCE_FS_N, fs_hz=1000)
    assert design.json == json.loads((d / "design_nominal.json").read_text())
    with vibid.Board(emu.url) as board:
        staged = board.cal_upload(NOMINAL, design, sensors=SENSORS, label="python")
        assert staged["label"] == "python"
        board.cal_commit()
        board.dob_start()
        push = board.acquire(seconds=5, rate_hz=1000, scenario="shaker",
                             scenario_params=[16, 10, 10])
        board.dob_stop()
    run = vibid.dob_run(design, push["x2_m"], push["force1_n"])
    # The board's kernel and the host's replay are the same code: equal to the last bit.
    np.testing.assert_array_equal(run.d_hat_q31, push["d_hat_q31"])


def push_fit(emu, model):
    """The fit (%) of the board's d_hat, designed from `model`, to the disturbance the shaker
    scenario pushes m2 with, measured on its own by the second load cell (force2_n): after the
    4 Hz low-pass that takes off the 16 Hz shaker's residue, 0.5 s left out at each end, as
    scripts/workflow scores it."""
    design = vibid.dob_design(model, sensors=SENSORS, fs_hz=1000)
    with vibid.Board(emu.url) as board:
        board.cal_upload(model, design, sensors=SENSORS)
        board.cal_commit()
        board.dob_start()
        push = board.acquire(seconds=6, rate_hz=1000, scenario="shaker",
                             scenario_params=[16, 10, 10])
        board.dob_stop()
    skip = 500
    lp = vibid.lowpass(push["d_hat_n"], 4, 1000)
    return vibid.dob_compare(lp[skip:-skip], push["force2_n"][skip:-skip], 1000.0)


def test_the_board_s_d_hat_follows_the_measured_disturbance(tests):
    # Scored against force2, not against itself: with the identified model d_hat follows the push
    # (scripts/workflow's 30 s run: 98.6 %); with the nominal one (m1 +9 %, springs +10 %) its
    # model-error term Q(G_A^-1 - G_R^-1)y remains (69.8 % there), so the update must show.
    d, emu = tests
    updated = vibid.identify(vibid.load_model(NOMINAL),
                             mass_tests={1: d / "mass1.csv", 2: d / "mass2.csv"},
                             mass_springs={1: "fit", 2: "fit"},
                             modal_tests=[d / "modal1.csv", d / "modal2.csv"],
                             exp_window=0.1).updated
    identified = push_fit(emu, updated)
    nominal = push_fit(emu, vibid.load_model(NOMINAL))
    assert identified.fit_percent > 95.0, identified
    assert identified.correlation > 0.99 and abs(identified.delay_s) <= 0.002, identified
    assert nominal.fit_percent < identified.fit_percent - 10.0, (nominal, identified)


def test_report_equals_cli(tests):
    d, emu = tests
    ok("identify", "--nominal", NOMINAL, "--mass-test", f"1={d / 'mass1.csv'}",
       "--mass-test", f"2={d / 'mass2.csv'}", "--mass-spring", "1=fit", "--mass-spring", "2=fit",
       "--modal-test", d / "modal1.csv", "--exp-window", 0.1, "-o", d / "updated_r.json",
       "--report", d / "report_r")
    with vibid.Board(emu.url) as board:
        board.dob_start()  # d_hat is logged while the observer runs
        push = board.acquire(seconds=3, rate_hz=1000, scenario="shaker",
                             scenario_params=[16, 10, 10])
        board.dob_stop()
    push.write_csv(d / "push.csv")
    args = dict(identify=d / "report_r", dob=d / "push.csv", measured="force2_n",
                estimates=["d_hat_n=board"], skip_s=0.5, notes=["seed 1"])
    ok("report", "--identify", d / "report_r", "--dob", d / "push.csv", "--measured", "force2_n",
       "--estimate", "d_hat_n=board", "--skip-s", 0.5, "--note", "seed 1",
       "-o", d / "cli.html")
    vibid.report(d / "py.html", **args)
    html = (d / "py.html").read_text()
    assert html == (d / "cli.html").read_text()
    for heading in ("Identification", "Frequency response functions", "Disturbance observer"):
        assert f"<h2>{heading}</h2>" in html
    assert html.count("<svg") == 4  # FRFs (2), stabilization diagram, observer traces


def test_observer_replay_lowpass_and_compare_equal_cli(tests):
    d, emu = tests
    design = vibid.dob_design(vibid.load_model(NOMINAL), force_fs_n=FORCE_FS_N, fs_hz=1000)
    design.save(d / "design_py.json")
    with vibid.Board(emu.url) as board:
        push = board.acquire(seconds=4, rate_hz=1000, scenario="shaker",
                             scenario_params=[16, 10, 10])
    push.write_csv(d / "push_r.csv")
    ok("dob", "run", d / "push_r.csv", "--design", d / "design_py.json", "--force", "force1_n",
       "--response", "x2_m", "--name", "host", "--lowpass-hz", 4, "-o", d / "replay.csv")
    cli = vibid.read_recording(d / "replay.csv")
    run = vibid.dob_run(design, push["x2_m"], push["force1_n"])
    np.testing.assert_array_equal(run.d_hat_n, cli["host_n"])
    np.testing.assert_array_equal(run.d_hat_q31, cli["host_q31"])
    lp = vibid.lowpass(run.d_hat_n, 4, 1000)
    np.testing.assert_array_equal(lp, cli["host_lp_n"])
    r = ok("dob", "compare", d / "replay.csv", "--estimate", "host_lp_n", "--measured",
           "force2_n", "--skip-s", 0.5, "--json")
    skip = 500
    agreement = vibid.dob_compare(lp[skip:-skip], push["force2_n"][skip:-skip], 1000.0)
    assert dataclasses.asdict(agreement) == json.loads(r.stdout)
