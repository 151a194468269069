"""The hammer point found, not assumed: `vibid identify` on hammer tests of 2-, 3- and 4-mass chains
simulated independently of vibid (scripts/golden/chain_hammer.py: scipy, exact zero-order-hold
modes, anti-aliased and decimated as a DAQ samples), hit on each mass in turn. Without
--driving-point the hit mass is found and the masses come out at the simulated truth; a driving
point named wrongly is refused naming the one that fits, and no model is written from it."""
import importlib.util
import json

import pytest

import vibid

from conftest import ROOT, run_cli

_spec = importlib.util.spec_from_file_location("chain_hammer",
                                               ROOT / "scripts" / "golden" / "chain_hammer.py")
chain_hammer = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(chain_hammer)

# Truths: the emulator's rigs (host/emulator/rigs: default.json's effective masses, chain3.json,
# chain4.json); nominal models: the examples' (8-15 % off the truths).
CHAINS = {
    2: dict(masses=[1.82, 1.53], springs=[3520.0, 2760.0], dampers=[5.0, 3.5],
            nominal="rig_nominal.json"),
    3: dict(masses=[1.52, 1.2, 0.9], springs=[3200.0, 2600.0, 2100.0], dampers=[3.0, 2.0, 1.5],
            nominal="chain3_nominal.json"),
    4: dict(masses=[1.4, 1.2, 1.0, 0.8], springs=[4200.0, 3600.0, 3000.0, 2400.0],
            dampers=[3.0, 2.5, 2.0, 1.5], nominal="chain4_nominal.json"),
}
CASES = [(n, h) for n in CHAINS for h in range(1, n + 1)]


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    d = tmp_path_factory.mktemp("driving_point")
    paths = {}
    for n, h in CASES:
        c = CHAINS[n]
        # Hits 20 s apart: the slowest mode (3.4 Hz, zeta 0.8 %) rings down within a record.
        t, f, acc = chain_hammer.simulate(c["masses"], c["springs"], c["dampers"], h,
                                          seconds=81.0, spacing_s=20.0, seed=10 * n + h)
        paths[(n, h)] = d / f"chain{n}_hit{h}.csv"
        chain_hammer.write_recording(paths[(n, h)], t, f, acc)
    return paths


def identify(rec, n, out, *extra):
    responses = ",".join(f"acc{i + 1}_m_s2" for i in range(n))
    return run_cli("identify", "--nominal", ROOT / "examples" / CHAINS[n]["nominal"],
                   "--modal-test", rec, "--modal-responses", responses, "--force", "force1_n",
                   "-o", out, "--report", out.parent / (out.stem + "_report"), *extra)


# Mass 3 of the 4-mass chain sits near a node of mode 2 (8.49 Hz): the hammer there cannot scale
# that mode's shape, and the chain built on it is flagged (worse than the nominal) and not written.
# The point is still found; no model comes from it.
NODE_AT_THE_HAMMER = {(4, 3)}


@pytest.mark.parametrize("n,h", CASES)
def test_hammer_point_found_without_being_named(recordings, tmp_path, n, h):
    out = tmp_path / "model.json"
    r = identify(recordings[(n, h)], n, out)
    assert f"driving point acc{h}_m_s2 (response {h}), found from the data" in r.stderr
    if (n, h) in NODE_AT_THE_HAMMER:
        assert r.returncode == 6, r.stderr
        assert "is flagged" in r.stderr and not out.exists(), r.stderr
        return
    assert r.returncode == 0, r.stderr
    report = json.loads((tmp_path / "model_report" / "report.json").read_text())
    assert report["driving_point"]["response"] == h
    assert report["driving_point"]["how"] == "found"
    masses = json.loads(out.read_text())["masses"]
    for got, truth in zip(masses, CHAINS[n]["masses"]):
        assert abs(got - truth) < 0.02 * truth, (masses, CHAINS[n]["masses"])


@pytest.mark.parametrize("n,h", CASES)
def test_a_wrongly_named_hammer_point_is_refused_naming_the_one_that_fits(recordings, tmp_path,
                                                                          n, h):
    for wrong in range(1, n + 1):
        if wrong == h:
            continue
        out = tmp_path / f"model{wrong}.json"
        r = identify(recordings[(n, h)], n, out, "--driving-point", str(wrong))
        assert r.returncode != 0, (wrong, r.stderr)
        assert f"--driving-point {wrong} names acc{wrong}_m_s2" in r.stderr, r.stderr
        assert f"the data fit acc{h}_m_s2 (response {h})" in r.stderr, r.stderr
        assert f"name response {h} as the driving point" in r.stderr, r.stderr
        assert not out.exists()


def test_the_right_name_is_kept(recordings, tmp_path):
    out = tmp_path / "model.json"
    r = identify(recordings[(3, 2)], 3, out, "--driving-point", "acc2_m_s2")
    assert r.returncode == 0, r.stderr
    report = json.loads((tmp_path / "model_report" / "report.json").read_text())
    assert report["driving_point"] == {
        "response": 2, "name": "acc2_m_s2", "how": "named",
        "note": report["driving_point"]["note"]}
    assert "as the data say" in report["driving_point"]["note"]


def test_python_identify_takes_the_driving_point(recordings):
    nominal = vibid.load_model(ROOT / "examples" / CHAINS[3]["nominal"])
    rec = str(recordings[(3, 2)])
    kw = dict(modal_responses="acc1_m_s2,acc2_m_s2,acc3_m_s2", force="force1_n")
    with pytest.raises(ValueError, match="driving_point=3 names acc3_m_s2 .* the data fit "
                                         "acc2_m_s2 \\(response 2\\)"):
        vibid.identify(nominal, {}, [rec], driving_point=3, **kw)
    for named in ("", 2, "acc2_m_s2"):
        r = vibid.identify(nominal, {}, [rec], driving_point=named, **kw)
        assert r.report["driving_point"]["response"] == 2
        for got, truth in zip(r.report["updated_model"]["masses"], CHAINS[3]["masses"]):
            assert abs(got - truth) < 0.02 * truth


# The emulator's rigs (vibid-emu --rig), hit on the mass the scenario's first parameter names:
# the cases where the last response was taken for the driving point (2 masses hit on mass 1,
# chain3.json on mass 2, chain4.json on mass 3, the rig file's own hammer mass). The board is
# uncalibrated: converter counts, scaled as docs/emulator.md does.
ACC, X, F = "*0.09765625", "*1e-5", "force1_counts*0.244140625"
# Tolerance on the masses (the rigs' friction and converters; measured with seed 5: default.json
# -1.4/-2.8 %, chain3.json -3.1/-1.8/-5.4 %, chain4.json -3.4 to -5.1 %, where mass 3 sits at a
# node of mode 2, 8.49 Hz, which a warning names). Before, from the last response: m1 2.44 kg
# against 1.82 (default.json), m1 2.39 against 1.52 (chain3.json), m4 1.63 against 0.8.
EMULATED = [
    ("default.json", 1, ["acc1", "acc2"], "acc,acc", "rig_nominal.json", [1.82, 1.53], 0.04),
    ("chain3.json", 2, ["acc1", "acc2", "x1"], "acc,acc,disp", "chain3_nominal.json",
     CHAINS[3]["masses"], 0.07),
    ("chain4.json", 3, ["acc1", "x1", "acc2", "x2"], "acc,disp,acc,disp", "chain4_nominal.json",
     CHAINS[4]["masses"], 0.07),
]


@pytest.mark.parametrize("rig,hit,inputs,sensor,nominal,masses,tolerance", EMULATED)
def test_emulated_rigs_hit_off_the_last_mass(make_emulator, tmp_path, rig, hit, inputs, sensor,
                                             nominal, masses, tolerance):
    emulator = make_emulator(seed=5, rig=ROOT / "host" / "emulator" / "rigs" / rig)
    with vibid.Board(emulator.url) as board:
        rec = board.acquire(seconds=60, rate_hz=2000, channels=["force1"] + inputs, no_dob=True,
                            scenario="hammer", scenario_params=[hit, 150, 0, 0])
    path = tmp_path / "rec.csv"
    rec.write_csv(path)
    responses = ",".join(f"{c}_counts{X if c.startswith('x') else ACC}" for c in inputs)
    common = ["identify", "--nominal", ROOT / "examples" / nominal, "--modal-test", path,
              "--modal-responses", responses, "--sensor", sensor, "--force", F]
    out = tmp_path / "model.json"
    r = run_cli(*common, "-o", out)
    assert r.returncode == 0, r.stderr
    assert f"(response {hit}), found from the data" in r.stderr, r.stderr
    got = json.loads(out.read_text())["masses"]
    for g, t in zip(got, masses):
        assert abs(g - t) < tolerance * t, (got, masses)
    # The last response, which vibid took for the driving point before, named: refused.
    wrong = tmp_path / "wrong.json"
    r = run_cli(*common, "--driving-point", str(len(inputs)), "-o", wrong)
    assert r.returncode != 0
    assert f"name response {hit} as the driving point" in r.stderr, r.stderr
    assert not wrong.exists()
