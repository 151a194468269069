"""Recordings: the CSV reader's numbers, SEP005 round trip, write/read bit-identical."""
import numpy as np
import pytest

import vibid


def test_round_trip_csv_and_sep005(tmp_path):
    rng = np.random.default_rng(3)
    rec = vibid.Recording(names=["force1_n", "acc1_m_s2"], data=rng.normal(size=(2, 100)),
                          fs_hz=2000.0)
    path = tmp_path / "r.csv"
    rec.write_csv(path)
    back = vibid.read_recording(path)
    assert back.names == rec.names
    assert back.fs_hz == pytest.approx(2000.0, rel=1e-9)
    np.testing.assert_array_equal(back.data, rec.data)
    sep = back.to_sep005()
    assert sep[0]["quantity"] == "force" and sep[0]["unit_str"] == "N"
    assert sep[1]["quantity"] == "acceleration" and sep[1]["unit_str"] == "m/s^2"
    assert sep[1]["fs"] == back.fs_hz
    again = vibid.Recording.from_sep005(sep)
    np.testing.assert_array_equal(again.data, rec.data)
    # A channel is a view into the recording's array, not a copy.
    assert np.shares_memory(back["acc1_m_s2"], back.data)


def test_frf_estimate_of_a_recording_equals_that_of_its_csv(tmp_path):
    # The same signals through the file reader and in memory: the same FRF to the last bit.
    rng = np.random.default_rng(5)
    f = rng.standard_normal(4096)
    rec = vibid.Recording(names=["force_n", "acc1_m_s2"],
                          data=np.vstack([f, np.convolve(f, [0.5, 0.3, 0.2], "same")]),
                          fs_hz=1000.0)
    rec.write_csv(tmp_path / "r.csv")
    a = vibid.frf_estimate(rec, force="force_n", responses="acc1_m_s2", welch=True)
    b = vibid.frf_estimate(tmp_path / "r.csv", force="force_n", responses="acc1_m_s2", welch=True)
    np.testing.assert_array_equal(a.frd.h, b.frd.h)
    np.testing.assert_array_equal(a.frd.coherence, b.frd.coherence)
    with pytest.raises(ValueError, match="unknown column 'acc9'"):
        vibid.frf_estimate(rec, force="force_n", responses="acc9", welch=True)
