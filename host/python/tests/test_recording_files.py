"""Recording files as other tools read them: a plain CSV (one header row, then rows) that pandas'
and numpy's readers open with their defaults, the board's sampling instants in a JSON sidecar
beside it (REC.csv.json), t_s the exact decimal of index / rate, and the files vibid wrote before
the sidecar (instants on an opening comment line) still read as they were."""
import json
import shutil
from decimal import Decimal

import numpy as np
import pandas
import pytest

import vibid
from conftest import run_cli

DATA = __import__("pathlib").Path(__file__).resolve().parent / "data"
# A hammer test in the form vibid wrote before the sidecar: its first line
# `# vibid-recording sample_instants_us=force1_n:2.667,acc1_m_s2:5.905`, then the CSV.
OLD_FORM = DATA / "recording_v1_hammer.csv"


def read_with_every_reader(path):
    """The file as pandas.read_csv, numpy.genfromtxt(names=True) and numpy.loadtxt(skiprows=1)
    give it, with their defaults (the comma as the delimiter: CSV)."""
    frame = pandas.read_csv(path)
    table = np.genfromtxt(path, delimiter=",", names=True)
    rows = np.loadtxt(path, delimiter=",", skiprows=1)
    return frame, table, rows


def test_an_acquisition_opens_in_pandas_and_numpy(emulator, tmp_path):
    out = tmp_path / "rec.csv"
    r = run_cli("acquire", "--seconds", 0.4, "--rate-hz", 5000, "--channels", "force1,force2,acc1",
                "--no-dob", "-o", out, device=emulator.url)
    assert r.returncode == 0, r.stderr
    names = ["t_s", "force1_counts", "force2_counts", "acc1_counts"]
    assert out.read_text().splitlines()[0] == ",".join(names)  # the header row comes first
    frame, table, rows = read_with_every_reader(out)
    assert list(frame.columns) == names
    assert list(table.dtype.names) == names
    assert rows.shape == (2000, 4) and frame.shape == (2000, 4) and table.shape == (2000,)
    rec = vibid.read_recording(out)
    for i, n in enumerate(names[1:]):
        np.testing.assert_array_equal(frame[n].to_numpy(), rec[n])
        np.testing.assert_array_equal(table[n], rec[n])
        np.testing.assert_array_equal(rows[:, i + 1], rec[n])
    # The instants, in the sidecar: those `vibid info --json` states for the channels (56 and
    # 124 converter clocks of 21 MHz after the edge: 2.667 and 5.905 us in whole ns).
    info = json.loads(run_cli("info", "--json", device=emulator.url).stdout)
    sidecar = json.loads((tmp_path / "rec.csv.json").read_text())
    assert sidecar["format"] == "vibid-recording" and sidecar["version"] == 2
    assert sidecar["columns"] == names and sidecar["fs"] == 5000.0
    instants = {c["name"]: c["sample_instant_us"] for c in sidecar["channels"]}
    assert instants == {"force1_counts": info["sample_instants_us"]["force1"],
                        "force2_counts": info["sample_instants_us"]["force2"],
                        "acc1_counts": info["sample_instants_us"]["acc1"]}
    assert instants["force2_counts"] == 5.905
    assert rec.sample_instants_us == instants
    # The facts a reader needs: the board, the options, and per channel its converter's rails
    # (uncalibrated: the 12-bit codes), its unit and the board's clip count.
    assert sidecar["board"]["board"] == "emulator" and sidecar["board"]["adc_bits"] == 12
    # The emulator's serial number carries its seed (1, the fixture's), and the sidecar says so.
    assert sidecar["board"]["serial"] == "EMU0000000000000001"
    assert sidecar["acquisition"]["emulator_seed"] == 1
    assert sidecar["acquisition"]["seconds"] == 0.4 and sidecar["acquisition"]["records"] == 2000
    assert "calibration" not in sidecar  # uncalibrated
    for c in sidecar["channels"]:
        assert c["unit_str"] == "counts" and c["rails"] == [0.0, 4095.0]
        assert c["code_range"] == [0.0, 4095.0] and c["clipped_samples"] == 0
    assert rec.facts == sidecar


def test_t_s_is_the_exact_decimal_of_index_over_rate(emulator, tmp_path):
    # Each time cell, read as a decimal, is index / 5000 exactly (Decimal arithmetic, not a float
    # that prints as 0.40019999999999994).
    out = tmp_path / "rec.csv"
    r = run_cli("acquire", "--seconds", 1, "--rate-hz", 5000, "--channels", "force1", "--no-dob",
                "-o", out, device=emulator.url)
    assert r.returncode == 0, r.stderr
    cells = [line.split(",")[0] for line in out.read_text().splitlines()[1:]]
    assert len(cells) == 5000
    for i, cell in enumerate(cells):
        assert Decimal(cell) == Decimal(i) / Decimal(5000), (i, cell)
    assert "0.4002" in cells


def test_python_writes_the_files_the_cli_writes(make_emulator, tmp_path):
    # The same acquisition through the CLI and through Python: the CSV and the sidecar byte for
    # byte, so either reads back the other's.
    cli = tmp_path / "cli.csv"
    r = run_cli("acquire", "--seconds", 0.2, "--channels", "force1,acc2", "--no-dob", "-o", cli,
                device=make_emulator(seed=4).url)
    assert r.returncode == 0, r.stderr
    with vibid.Board(make_emulator(seed=4).url) as board:
        rec = board.acquire(seconds=0.2, channels="force1,acc2", no_dob=True)
    rec.write_csv(tmp_path / "py.csv")
    assert (tmp_path / "py.csv").read_bytes() == cli.read_bytes()
    # The same facts, but for the moment each started.
    py_facts = json.loads((tmp_path / "py.csv.json").read_text())
    cli_facts = json.loads((tmp_path / "cli.csv.json").read_text())
    for facts in (py_facts, cli_facts):
        facts.pop("start_timestamp")
        for c in facts["channels"]:
            c.pop("start_timestamp")
    assert py_facts == cli_facts


def test_a_file_written_before_the_sidecar_still_reads(tmp_path):
    # The old form: pandas needs comment="#" for it (the reason for the sidecar); vibid reads it
    # as it did, instants included, and its FRF equals that of the same recording in the new form.
    old = vibid.read_recording(OLD_FORM)
    assert old.sample_instants_us == {"force1_n": 2.667, "acc1_m_s2": 5.905}
    frame = pandas.read_csv(OLD_FORM, comment="#")
    # pandas' default float parser is not round-trip exact (float_precision="round_trip" is).
    np.testing.assert_allclose(frame["acc1_m_s2"].to_numpy(), old["acc1_m_s2"], rtol=1e-13,
                               atol=1e-14)
    new = tmp_path / "new.csv"
    old.write_csv(new)
    assert not new.read_text().startswith("#")
    assert {c["name"]: c["sample_instant_us"] for c in
            json.loads((tmp_path / "new.csv.json").read_text())["channels"]} == \
        old.sample_instants_us
    a = vibid.frf_estimate(OLD_FORM, force="force1_n", responses="acc1_m_s2")
    b = vibid.frf_estimate(new, force="force1_n", responses="acc1_m_s2")
    c = vibid.frf_estimate(old, force="force1_n", responses="acc1_m_s2")  # in memory
    assert "sampling instants compensated" in a.compensation
    assert a.compensation == b.compensation == c.compensation
    np.testing.assert_array_equal(a.frd.h, b.frd.h)
    np.testing.assert_array_equal(a.frd.h, c.frd.h)
    # The CLI reads the old form too, with the same compensation.
    r = run_cli("frf-estimate", OLD_FORM, "--force", "force1_n", "--response", "acc1_m_s2",
                "-o", tmp_path / "frf.csv")
    assert r.returncode == 0, r.stderr
    assert "sampling instants compensated" in r.stdout


def test_a_sidecar_of_another_recording_is_refused_and_a_stale_one_removed(tmp_path):
    rec = vibid.Recording(names=["force1_n", "acc1_m_s2"], data=np.ones((2, 16)), fs_hz=100.0,
                          sample_instants_us={"force1_n": 2.667, "acc1_m_s2": 5.905})
    path = tmp_path / "r.csv"
    rec.write_csv(path)
    assert (tmp_path / "r.csv.json").exists()
    # The same path written again without instants: the old sidecar must not describe it.
    vibid.Recording(names=["force1_n", "acc1_m_s2"], data=np.ones((2, 16)), fs_hz=100.0
                    ).write_csv(path)
    assert not (tmp_path / "r.csv.json").exists()
    assert vibid.read_recording(path).sample_instants_us is None
    # A sidecar beside a CSV of other columns (copied there by hand) is refused, naming both.
    other = vibid.Recording(names=["force2_n", "x1_m"], data=np.ones((2, 16)), fs_hz=100.0)
    other.write_csv(tmp_path / "o.csv")
    rec.write_csv(path)
    shutil.copy(tmp_path / "r.csv.json", tmp_path / "o.csv.json")
    with pytest.raises(ValueError, match=r"o\.csv\.json: describes columns .*the recording's are "
                                         r"t_s,force2_n,x1_m: it belongs to another recording"):
        vibid.read_recording(tmp_path / "o.csv")


def test_an_frf_csv_opens_in_pandas_and_numpy_its_metadata_beside(tmp_path):
    # frf.csv is one header row and rows (no opening comment line, on which pandas.read_csv and
    # numpy.genfromtxt(names=True) fail with their defaults); the metadata is in frf.csv.json.
    path = tmp_path / "frf.csv"
    r = run_cli("frf-estimate", OLD_FORM, "--force", "force1_n", "--response", "acc1_m_s2",
                "-o", path)
    assert r.returncode == 0, r.stderr
    names = ["freq_hz", "acc1_m_s2_re", "acc1_m_s2_im", "acc1_m_s2_coh"]
    assert path.read_text().splitlines()[0] == ",".join(names)
    frame, table, rows = read_with_every_reader(path)
    assert list(frame.columns) == names and list(table.dtype.names) == names
    e = vibid.frf_estimate(OLD_FORM, force="force1_n", responses="acc1_m_s2")
    # numpy's parser reads every value back exactly; pandas' default one to about 1e-12
    # (float_precision="round_trip" is exact).
    np.testing.assert_array_equal(table["freq_hz"], e.frd.freq_hz)
    np.testing.assert_array_equal(table["acc1_m_s2_re"], e.frd.h[0, 0].real)
    np.testing.assert_array_equal(table["acc1_m_s2_im"], e.frd.h[0, 0].imag)
    np.testing.assert_allclose(frame["acc1_m_s2_re"].to_numpy(), e.frd.h[0, 0].real, rtol=1e-12,
                               atol=1e-15)
    exact = pandas.read_csv(path, float_precision="round_trip")
    np.testing.assert_array_equal(exact["acc1_m_s2_im"].to_numpy(), e.frd.h[0, 0].imag)
    meta = json.loads((tmp_path / "frf.csv.json").read_text())
    assert meta["format"] == "vibid-frf" and meta["columns"] == names
    assert meta["kind"] == "receptance" and meta["force"] == "force1_n"
    assert meta["averages"] == e.averages
    # vibid reads its metadata back from the sidecar: the same modes as from the recording.
    m = run_cli("modes", path, "--json")
    assert m.returncode == 0, m.stderr


def test_the_clip_check_uses_the_facts_and_says_when_it_has_none(tmp_path):
    # A recording whose force sits on the load cell's top rail for 2 samples in its second hit:
    # with the facts (the rails), that hit is clipped and rejected; without them the check is
    # unavailable, and the warnings say so.
    old = vibid.read_recording(OLD_FORM)
    data = old.data.copy()
    f = data[old.index("force1_n")]
    peaks = [i for i in range(1, f.size - 1) if f[i] > 0.5 * f.max() and f[i] >= f[i - 1]
             and f[i] >= f[i + 1]]
    top = 1.01 * f.max()
    second = [p for p in peaks if p > peaks[0] + int(0.5 * old.fs_hz)][0]
    f[second:second + 2] = top
    facts = {"format": "vibid-recording", "version": 2, "columns": ["t_s"] + old.names,
             "channels": [{"name": "force1_n", "unit_str": "N", "rails": [-top, top]},
                          {"name": "acc1_m_s2", "unit_str": "m/s2", "rails": [-1e6, 1e6]}]}
    rec = vibid.Recording(names=old.names, data=data, fs_hz=old.fs_hz, facts=facts)
    path = tmp_path / "clipped.csv"
    rec.write_csv(path)
    for source in (path, rec, vibid.read_recording(path)):
        e = vibid.frf_estimate(source, force="force1_n", responses="acc1_m_s2")
        clipped = [h for h in e.hits if h.clipped]
        assert len(clipped) == 1 and not clipped[0].used, e.hits
        assert not any("clip check unavailable" in w for w in e.warnings)
    bare = vibid.Recording(names=old.names, data=data, fs_hz=old.fs_hz)
    e = vibid.frf_estimate(bare, force="force1_n", responses="acc1_m_s2")
    assert not any(h.clipped for h in e.hits)
    assert any("clip check unavailable for the force and response 1" in w for w in e.warnings)
