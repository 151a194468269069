"""System identification: `vibid.arx`, `pem`, `tfest` and `compare` equal the CLI's JSON on the
DAISY robot arm (testdata/), and the OE model's fit is the one docs/sysid.md quotes."""
import json

import numpy as np
import pytest

import vibid
from conftest import ROOT, cli_json, run_cli

ARM = ROOT / "testdata" / "daisy_robot_arm" / "robot_arm.csv"
COLS = dict(fs_hz=1.0, input="u_reaction_torque", output="y_arm_acceleration")
CLI_COLS = ["--fs-hz", 1, "--input", "u_reaction_torque", "--output", "y_arm_acceleration"]


def cli_model_json(*args):
    """A model the CLI wrote: exit 0, with the residual tests it fails as cautions named on stderr
    (the arm's ARX and OE residuals are not white); Python returns them as ``cautions`` and raises
    nothing."""
    r = run_cli(*args)
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    assert ("vibid: caution:" in r.stderr) == bool(j["cautions"]), r.stderr
    return j


def test_arx_equals_cli():
    cli = cli_model_json("arx", ARM, *CLI_COLS, "--na", 4, "--nb", 5, "--nk", 0, "--estimate-range",
                   "0:512", "--validate-range", "512:", "--json")
    py = vibid.arx(ARM, na=4, nb=5, nk=0, estimate_range="0:512", validate_range="512:", **COLS)
    assert py.json == cli
    assert py.cautions and "not white" in py.cautions[0]


def test_pem_and_compare_equal_cli(tmp_path):
    args = ["--structure", "oe", "--orders", "nb=5,nf=4,nk=0", "--estimate-range", "0:512"]
    cli = cli_model_json("pem", ARM, *CLI_COLS, *args, "--json")
    py = vibid.pem(ARM, structure="oe", orders="nb=5,nf=4,nk=0", estimate_range="0:512", **COLS)
    assert py.json == cli
    py.save(tmp_path / "oe4.json")
    cli_cmp = cli_json("compare", ARM, *CLI_COLS, "--model", tmp_path / "oe4.json", "--json")
    py_cmp = vibid.compare(ARM, model=py, **COLS)
    assert py_cmp.json == cli_cmp
    # The fit is of the simulated output: recomputed here from the signals (NRMSE fit).
    y, ym = py_cmp.y, py_cmp.y_model
    assert py_cmp.fit_percent == pytest.approx(
        100 * (1 - np.linalg.norm(y - ym) / np.linalg.norm(y - y.mean())), rel=1e-12)


def test_tfest_equals_cli():
    cli = cli_model_json("tfest", ARM, *CLI_COLS, "--np", 4, "--nz", 2, "--json")
    py = vibid.tfest(ARM, np=4, nz=2, **COLS)
    assert py.json == cli


def test_sysid_refusals_are_the_clis():
    with pytest.raises(ValueError, match="arx needs --na and --nb"):
        vibid.arx(ARM, **COLS)
    with pytest.raises(ValueError, match="--detrend 'cubic'"):
        vibid.arx(ARM, na=2, nb=2, detrend="cubic", **COLS)
    with pytest.raises(ValueError, match="--orders"):
        vibid.pem(ARM, structure="oe", orders="nb=x", **COLS)
