"""A chain of three masses from Python: vibid-emu with the shipped rigs/chain3.json (masses 1 and 2
on the accelerometers, mass 3 on encoder x1, the hammer on mass 3), one hammer test acquired
through vibid.Board, and the chain's three modes from vibid.modes at the rig truth's frequencies
(the model library's modes of the truth `vibid-emu --print-truth` states)."""
import json
import subprocess

import numpy as np

import vibid
from conftest import EMU, ROOT

RIG = ROOT / "host" / "emulator" / "rigs" / "chain3.json"


def test_three_mass_chain_from_python(make_emulator):
    truth = json.loads(subprocess.run([str(EMU), "--rig", str(RIG), "--print-truth"],
                                      capture_output=True, text=True, check=True).stdout)
    truth_hz = vibid.modal(vibid.Model.from_dict(truth)).freq_hz
    assert truth_hz.size == 3

    emulator = make_emulator(seed=4, rig=RIG)
    with vibid.Board(emulator.url) as board:
        # The rig's hammer mass and hit spacing (parameters 0); the load cell, both accelerometers
        # and the encoder: 10-byte records, which the link carries at 5 kHz.
        rec = board.acquire(seconds=60, rate_hz=5000, channels=["force1", "acc1", "acc2", "x1"],
                            no_dob=True, scenario="hammer", scenario_params=[0, 150, 0, 0])
    # This board stays uncalibrated and records converter counts (the next test calibrates it). The modes' frequencies do not depend on the
    # responses' scale; each response is what it measures (accelerations, a displacement).
    assert rec.names == ["force1_counts", "acc1_counts", "acc2_counts", "x1_counts"]
    assert np.ptp(rec["x1_counts"]) > 100  # the encoder on the hit mass moves by > 1 mm
    m = vibid.modes(rec, force="force1_counts",
                    responses=["acc1_counts", "acc2_counts", "x1_counts"], sensor="acc,acc,disp",
                    exp_window=0.1)
    assert m.freq_hz.size == 3
    np.testing.assert_allclose(m.freq_hz, truth_hz, rtol=0.01)


def test_three_mass_chain_calibrated_with_its_observer(make_emulator):
    """The board calibrated for the chain: its record holds the three masses' model, each
    sensor on its mass (x1 on mass 3) and an observer on mass 3 fed by that encoder; the hammer
    test then records SI columns, and the modes come out at the truth's frequencies."""
    truth = json.loads(subprocess.run([str(EMU), "--rig", str(RIG), "--print-truth"],
                                      capture_output=True, text=True, check=True).stdout)
    truth_hz = vibid.modal(vibid.Model.from_dict(truth)).freq_hz
    sensors = json.loads((ROOT / "examples" / "sensors.json").read_text())
    for name, dof in (("force1", 3), ("force2", 3), ("acc1", 1), ("acc2", 2), ("x1", 3)):
        sensors["channels"][name]["dof"] = dof
    del sensors["channels"]["x2"]["dof"]  # on no mass of this rig
    nominal = vibid.load_model(ROOT / "examples" / "chain3_nominal.json")
    design = vibid.dob_design(nominal, fs_hz=5000, input_dof=3, output_dof=3, sensors=sensors)
    # The sensors alone place it there, as `cal upload` with them accepts it (load cell force1's
    # mass, fed by its encoder x1): the same design, bit for bit.
    assert vibid.dob_design(nominal, fs_hz=5000, sensors=sensors).json == design.json
    emulator = make_emulator(seed=4, rig=RIG)
    with vibid.Board(emulator.url) as board:
        staged = board.cal_upload(nominal, design, sensors, label="chain3")
        assert staged["bytes"] == 1020  # calibration record version 3 (docs/protocol.md)
        board.cal_commit()
        rec = board.acquire(seconds=60, rate_hz=5000, channels=["force1", "acc1", "acc2", "x1"],
                            no_dob=True, scenario="hammer", scenario_params=[0, 150, 0, 0])
    assert rec.names == ["force1_n", "acc1_m_s2", "acc2_m_s2", "x1_m"]
    m = vibid.modes(rec, force="force1_n", responses=["acc1_m_s2", "acc2_m_s2", "x1_m"],
                    exp_window=0.1)
    assert m.freq_hz.size == 3
    np.testing.assert_allclose(m.freq_hz, truth_hz, rtol=0.01)
