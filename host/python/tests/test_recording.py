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
