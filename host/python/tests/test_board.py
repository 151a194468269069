"""The Python Board against vibid-emu: the same records as `vibid acquire`, the same preflight
refusal, Ctrl-C in the middle of an acquisition leaves the board idle and usable, and a board the
Python Board holds is named in use by this process."""
import json
import os
import signal

import numpy as np
import pytest

import vibid
from conftest import run_cli


def test_acquisition_equals_cli_csv(make_emulator, tmp_path):
    # Two emulators of the same seed run the same hammer blows: the CLI records one, Python the
    # other, and every sample must be the same.
    args = dict(seconds=0.5, rate_hz=5000, channels=["force1", "acc1"], no_dob=True,
                scenario="hammer", scenario_params=[1, 200, 0.2, 1])
    a = make_emulator(seed=7)
    out = tmp_path / "cli.csv"
    r = run_cli("acquire", "--seconds", 0.5, "--rate-hz", 5000, "--channels", "force1,acc1",
                "--no-dob", "--scenario", "hammer", "--scenario-param", "1", "200", "0.2", "1",
                "-o", out, device=a.url)
    assert r.returncode == 0, r.stderr
    cli = vibid.read_recording(out)
    b = make_emulator(seed=7)
    with vibid.Board(b.url) as board:
        py = board.acquire(**args)
    assert py.names == cli.names
    assert np.ptp(py.data[0]) > 0  # the hammer hit: not a flat record
    assert py.samples == 2500
    assert py.fs_hz == 5000.0
    np.testing.assert_array_equal(py.data, cli.data)
    # Written out, the files are vibid acquire's to the byte; the sidecars state the same facts
    # (the sampling instants, the board, the options), but for the moment each started.
    py.write_csv(tmp_path / "py.csv")
    assert (tmp_path / "py.csv").read_bytes() == out.read_bytes()
    facts = [json.loads((tmp_path / n).read_text()) for n in ("py.csv.json", "cli.csv.json")]
    for f in facts:
        f.pop("start_timestamp")
        for c in f["channels"]:
            c.pop("start_timestamp")
    assert facts[0] == facts[1]
    assert facts[0]["acquisition"]["scenario"] == "hammer"
    assert facts[0]["acquisition"]["scenario_params"] == [1, 200, 0.2, 1] or \
        np.allclose(facts[0]["acquisition"]["scenario_params"], [1, 200, 0.2, 1])
    # The board's tick of every record: consecutive, none dropped.
    np.testing.assert_array_equal(np.diff(py.sample_index.astype(np.int64)), 1)


def test_info_and_state(emulator):
    with vibid.Board(emulator.url) as board:
        info = board.info()
        assert info["board"] == "emulator"
        assert info["calibrated"] is False
        assert board.state() == "idle"
        assert "usbip" in repr(board) or "127.0.0.1" in repr(board)


def test_preflight_refusal_equals_cli(emulator):
    # Every channel with d_hat at 10 kHz: far more than the link carries for 60 s.
    r = run_cli("acquire", "--seconds", 60, "--rate-hz", 10000, "-o", "/dev/null",
                device=emulator.url)
    assert r.returncode != 0
    cli_message = r.stderr.strip().removeprefix("vibid: error: ")
    with vibid.Board(emulator.url) as board:
        with pytest.raises(ValueError) as e:
            board.acquire(seconds=60, rate_hz=10000)
        assert str(e.value) == cli_message
        assert board.state() == "idle"


def test_bad_device_url_raises():
    with pytest.raises(ValueError, match="usbip"):
        vibid.Board("usbip://127.0.0.1:notaport")


def test_unreachable_device_raises_device_error():
    with pytest.raises(vibid.DeviceError):
        vibid.Board("usbip://127.0.0.1:1")


def test_ctrl_c_stops_the_board_and_it_stays_usable(make_emulator):
    # At wall-clock speed, so the acquisition is still running when the signal comes.
    emulator = make_emulator(realtime=True)
    with vibid.Board(emulator.url) as board:
        # SIGINT to this very process once the board samples (the emulator says so), in the
        # middle of a 60 s acquisition. A wait for "sampling started" that gives up fails the
        # test saying so (check()), not as an acquisition that was never interrupted.
        watcher = emulator.when_logged("vibid-emu: sampling started",
                                       lambda: os.kill(os.getpid(), signal.SIGINT))
        interrupted = None
        try:
            board.acquire(seconds=60, rate_hz=1000, channels=["force1"], no_dob=True)
        except KeyboardInterrupt as e:
            interrupted = e
        watcher.check()
        assert interrupted is not None, "the acquisition ran its 60 s: Ctrl-C did not stop it"
        kept = interrupted.recording
        # Stopped early: what the board sampled, far fewer than 60 s worth, none dropped.
        assert 0 < kept.samples < 60 * 1000
        np.testing.assert_array_equal(np.diff(kept.sample_index.astype(np.int64)), 1)
        assert board.state() in ("idle", "done")
        again = board.acquire(seconds=0.2, rate_hz=1000, channels=["force1"], no_dob=True)
        assert again.samples == 200


def test_stream_delivers_every_record_as_acquire_does(make_emulator):
    # The same hammer test streamed and acquired from two emulators of one seed: the blocks,
    # joined, are the acquisition, record for record.
    args = dict(seconds=2, rate_hz=5000, channels=["force1", "acc1", "acc2"], no_dob=True,
                scenario="hammer", scenario_params=[2, 200, 0.5, 0])
    with vibid.Board(make_emulator(seed=3).url) as board:
        whole = board.acquire(**args)
    with vibid.Board(make_emulator(seed=3).url) as board:
        blocks = list(board.stream(**args))
        assert board.state() in ("idle", "done")
    assert len(blocks) > 10  # delivered piecewise, not at the end only
    assert all(b.names == whole.names for b in blocks)
    np.testing.assert_array_equal(np.hstack([b.data for b in blocks]), whole.data)
    np.testing.assert_array_equal(np.concatenate([b.sample_index for b in blocks]),
                                  whole.sample_index)


def test_stream_left_early_stops_the_board(make_emulator):
    emulator = make_emulator(realtime=True)
    with vibid.Board(emulator.url) as board:
        got = 0
        for b in board.stream(seconds=20, rate_hz=1000, channels=["force1"], no_dob=True):
            got += b.samples
            if got >= 300:
                break
        assert board.state() in ("idle", "done")
        assert board.acquire(seconds=0.1, rate_hz=1000, channels=["force1"],
                             no_dob=True).samples == 100


def test_a_board_held_by_python_is_named_in_use(emulator):
    # While this process holds the board, `vibid info` names it (the program and its pid) and the
    # way out; once it is closed the board answers again.
    with vibid.Board(emulator.url):
        r = run_cli("info", device=emulator.url)
        assert r.returncode == 4, r.stderr
        assert r.stderr.startswith(f"vibid: error: the board at {emulator.url} is in use by ")
        assert f"(pid {os.getpid()}): close it, or wait until it ends, and try again" in r.stderr
    assert run_cli("info", device=emulator.url).returncode == 0
