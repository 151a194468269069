"""Every Board method's arguments, checked before the board does anything: a wrong type is a
TypeError naming the argument, a wrong value a ValueError with the CLI's message (the library's
own check, the one `vibid acquire` makes), and the board is left idle. Then the ends of an
acquisition other than its length: each returns the records it kept."""
import math
import re

import numpy as np
import pytest

import vibid
from conftest import ROOT, run_cli

NOMINAL = ROOT / "examples" / "rig_nominal.json"
SENSORS = ROOT / "examples" / "sensors.json"

# (method, keyword arguments, exception, message). acquire and stream take the same arguments and
# are checked the same way; a good baseline (0.1 s of force1) is completed by each row.
ACQUISITION_ARGUMENTS = [
    # the length: the endless acquisition of a negative length, and its kin
    (dict(seconds=-1), ValueError, "--seconds -1: must be a number > 0"),
    (dict(seconds=0), ValueError, "--seconds 0: must be a number > 0"),
    (dict(seconds=math.nan), ValueError, "--seconds nan: must be a number > 0"),
    (dict(seconds=math.inf), ValueError, "--seconds inf: must be a number > 0"),
    (dict(seconds=1e12), ValueError, "--seconds 1e+12: more records than the board counts"),
    (dict(seconds=1e-9), ValueError, "--seconds is shorter than one logged sample"),
    (dict(seconds="1"), TypeError, "seconds: expected a number, got str '1'"),
    (dict(seconds=True), TypeError, "seconds: expected a number, got bool True"),
    (dict(seconds=None), TypeError, "seconds: expected a number, got NoneType"),
    # the rates
    (dict(rate_hz=-5000), ValueError, "--rate-hz -5000: must be a number > 0"),
    (dict(rate_hz=0), ValueError, "--rate-hz 0: must be a number > 0"),
    (dict(rate_hz=20000), ValueError, "the board samples at 10000 Hz at most"),
    (dict(rate_hz=3000), ValueError, "is not; choose a rate that divides 1000000"),
    (dict(rate_hz="5k"), TypeError, "rate_hz: expected a number, got str"),
    (dict(log_rate_hz=-1), ValueError, "--log-rate-hz -1: must be a number > 0"),
    (dict(log_rate_hz=math.nan), ValueError, "--log-rate-hz nan: must be a number > 0"),
    (dict(log_rate_hz=3000), ValueError, "must be a whole multiple of it"),
    (dict(decimation=-1), ValueError, "--decimation -1: must be in 1..1000"),
    (dict(decimation=1001), ValueError, "--decimation 1001: must be in 1..1000"),
    (dict(decimation=3), ValueError, "the board decimates by 2^a 5^b"),
    (dict(decimation=2.0), TypeError, "decimation: expected a whole number, got float"),
    (dict(decimation=2, log_rate_hz=2500), ValueError, "give one of them, not both"),
    # the channels
    (dict(channels=["f"]), ValueError, "--channels: unknown channel 'f'"),
    (dict(channels="force1,accl"), ValueError, "--channels: unknown channel 'accl'"),
    (dict(channels=5), TypeError, "channels: expected names"),
    # an empty list is no channel, not every channel (None is every channel)
    (dict(channels=[]), ValueError, "channels: an empty list names no channel; name them"),
    (dict(channels=""), ValueError, "channels: an empty list names no channel; name them"),
    (dict(channels=["force1", 2]), TypeError, "channels: expected names (strings), got int"),
    # the trigger
    (dict(trigger="force>abc"), ValueError, "--trigger 'force>abc': expected force>F"),
    (dict(trigger="acc1>1"), ValueError, "--trigger 'acc1>1': expected force>F"),
    (dict(trigger=40), TypeError, "trigger: expected a string, got int"),
    (dict(pretrigger_s=-1), ValueError, "--pretrigger-s -1: must be a number >= 0"),
    (dict(pretrigger_s=0.1), ValueError, "--pretrigger-s needs a --trigger"),
    (dict(trigger_timeout_s=-1), ValueError, "--trigger-timeout-s -1: must be a number >= 0"),
    (dict(trigger_timeout_s=1), ValueError, "--trigger-timeout-s needs a --trigger"),
    # the flags and the emulator's scenario
    (dict(no_dob="yes"), TypeError, "no_dob: expected True or False, got str"),
    (dict(allow_drops=1), TypeError, "allow_drops: expected True or False, got int"),
    (dict(scenario=3), TypeError, "scenario: expected a string, got int"),
    (dict(scenario_params="1,2"), TypeError, "scenario_params: expected a sequence of numbers"),
    (dict(scenario_params=[1, "2"]), TypeError, "scenario_params[1]: expected a number"),
    (dict(scenario_params=[1, 2, 3, 4, 5]), ValueError, "--scenario-param takes at most 4 values"),
    # the link: 60 s of every channel at 10 kHz overflows the log (the preflight's refusal)
    (dict(seconds=60, rate_hz=10000, channels=None), ValueError, "--allow-drops"),
]

GOOD = dict(seconds=0.1, rate_hz=1000, channels=["force1"], no_dob=True)


def _acquire(board, **kw):
    return board.acquire(**{**GOOD, **kw})


def _stream(board, **kw):
    # The arguments are checked when stream() is called, before a block is asked for.
    return board.stream(**{**GOOD, **kw})


OTHER_ARGUMENTS = [
    # cal_upload: each of its four arguments
    (lambda b: b.cal_upload(5, _design()), TypeError, "model: expected a vibid.Model or a model"),
    (lambda b: b.cal_upload("nowhere/rig.json", _design()), FileNotFoundError, "no such file"),
    (lambda b: b.cal_upload(NOMINAL, 5), TypeError, "design: expected an ObserverDesign"),
    (lambda b: b.cal_upload(NOMINAL, _design(), sensors="nowhere.json"), FileNotFoundError,
     "sensors: no such file"),
    (lambda b: b.cal_upload(NOMINAL, _design(), sensors=3), TypeError,
     "sensors: expected a file path, got int"),
    (lambda b: b.cal_upload(NOMINAL, _design(), sensors=SENSORS, label=7), TypeError,
     "label: expected a string, got int"),
    # a design for another force full scale than the sensors' load cell: the library's refusal
    (lambda b: b.cal_upload(NOMINAL, _design(force_fs_n=100), sensors=SENSORS), ValueError,
     "force1: the sensors give a full scale of 500 N, the observer's input 2 was designed for "
     "100 N"),
    # the observer of a board with no calibration: the board's refusal, named
    (lambda b: b.dob_start(), vibid.DeviceError, "the board's calibration holds no observer"),
]


def _design(**kw):
    return vibid.dob_design(vibid.load_model(NOMINAL), **kw)


@pytest.fixture(scope="module")
def board_url(tmp_path_factory):
    from conftest import Emulator
    emu = Emulator(tmp_path_factory.mktemp("emu"))
    yield emu.url
    emu.stop()


@pytest.mark.parametrize("method", [_acquire, _stream], ids=["acquire", "stream"])
@pytest.mark.parametrize("kw,exc,message", ACQUISITION_ARGUMENTS,
                         ids=[re.sub(r"\W+", "_", repr(r[0])) for r in ACQUISITION_ARGUMENTS])
def test_bad_acquisition_arguments_are_refused_before_the_board_starts(board_url, method, kw,
                                                                       exc, message):
    with vibid.Board(board_url) as board:
        with pytest.raises(exc) as e:
            method(board, **kw)
        assert message in str(e.value)
        assert board.state() == "idle"  # nothing was configured or started


@pytest.mark.parametrize("call,exc,message", OTHER_ARGUMENTS,
                         ids=["cal_upload_model", "cal_upload_missing_model", "cal_upload_design",
                              "cal_upload_missing_sensors", "cal_upload_sensors_type",
                              "cal_upload_label", "cal_upload_other_full_scale", "dob_start"])
def test_bad_arguments_of_the_other_methods(board_url, call, exc, message):
    with vibid.Board(board_url) as board:
        with pytest.raises(exc) as e:
            call(board)
        assert message in str(e.value)
        assert board.state() == "idle"
        assert board.info()["calibrated"] is False  # nothing was staged or committed


def test_the_board_url_and_a_closed_board():
    with pytest.raises(TypeError, match="url: expected a string, got int"):
        vibid.Board(3240)
    with pytest.raises(ValueError, match="bogus://x"):
        vibid.Board("bogus://x")


def test_methods_of_a_closed_board_raise(board_url):
    board = vibid.Board(board_url)
    board.close()
    for call in (board.info, board.state, board.dob_start, board.dob_stop, board.cal_commit,
                 lambda: board.acquire(**GOOD)):
        with pytest.raises(vibid.DeviceError, match="the board is closed"):
            call()


def test_channels_as_the_cli_writes_them(board_url):
    # "force1,acc1" is the CLI's --channels: two channels, not the letters of one.
    with vibid.Board(board_url) as board:
        rec = board.acquire(seconds=0.01, rate_hz=1000, channels="force1,acc1", no_dob=True)
    assert rec.names == ["force1_counts", "acc1_counts"]
    assert rec.samples == 10


def test_a_board_that_goes_away_returns_the_records_that_arrived(make_emulator):
    # The emulator killed while it samples (it says when it starts): the acquisition ends with
    # a DeviceError naming the lost board, and the records that had arrived are returned with
    # it, in order, each once, at the times of their ticks.
    emu = make_emulator(realtime=True)
    with vibid.Board(emu.url) as board:
        # A wait for "sampling started" that gives up fails the test saying so (check()).
        killer = emu.when_logged("vibid-emu: sampling started", emu.proc.kill)
        lost = None
        try:
            board.acquire(seconds=60, rate_hz=1000, channels=["force1", "acc1"], no_dob=True)
        except vibid.DeviceError as e:
            lost = e
        killer.check()
    assert lost is not None, "the acquisition ran its 60 s: the board was never killed"
    kept = lost.recording
    assert re.search(r"; kept the (\d+) records that had arrived$", str(lost)), str(lost)
    assert str(kept.samples) in str(lost)
    assert kept.names == ["force1_counts", "acc1_counts"]
    ticks = kept.sample_index.astype(np.int64)
    np.testing.assert_array_equal(ticks, np.arange(kept.samples))
    np.testing.assert_array_equal(kept.t_s, ticks / 1000)
    assert kept.samples < 60 * 1000


def test_a_trigger_that_does_not_fire_ends_with_the_records_kept(make_emulator, tmp_path):
    # The rig at rest never reaches 40 N: trigger_timeout_s ends the wait, as the CLI's
    # --trigger-timeout-s does, with a DeviceError carrying what was recorded (nothing).
    emu = make_emulator()
    with vibid.Board(emu.url) as board:
        board.cal_upload(NOMINAL, _design(sensors=SENSORS), sensors=SENSORS)
        board.cal_commit()
        with pytest.raises(vibid.DeviceError) as e:
            board.acquire(seconds=1, rate_hz=1000, channels=["force1"], trigger="force>40",
                          trigger_timeout_s=1.5)
        assert board.state() in ("idle", "done")
    assert "the trigger did not fire within 1.5 s (trigger_timeout_s)" in str(e.value)
    assert e.value.recording.samples == 0
    assert e.value.recording.names == ["force1_n"]


def test_d_hat_is_logged_only_while_the_observer_runs(make_emulator, tmp_path):
    # A stored observer that is stopped estimates nothing: d_hat is not logged by default, and
    # an acquisition the link carries without it runs. Started, the observer's d_hat is logged.
    emu = make_emulator()
    with vibid.Board(emu.url) as board:
        board.cal_upload(NOMINAL, _design(sensors=SENSORS), sensors=SENSORS)
        board.cal_commit()
        stopped = board.acquire(seconds=0.1, rate_hz=5000)
        assert "d_hat_n" not in stopped.names
        board.dob_start()
        running = board.acquire(seconds=0.1, rate_hz=5000, channels=["force1", "x2"])
        assert running.names == ["force1_n", "x2_m", "d_hat_q31", "d_hat_n"]
        board.dob_stop()
        again = board.acquire(seconds=0.1, rate_hz=5000, channels=["force1", "x2"])
        assert again.names == ["force1_n", "x2_m"]
    # The CLI decides the same (one library function).
    r = run_cli("acquire", "--seconds", 0.1, "--channels", "force1,x2", "-o", tmp_path / "c.csv",
                device=emu.url)
    assert r.returncode == 0, r.stderr
    assert vibid.read_recording(tmp_path / "c.csv").names == ["force1_n", "x2_m"]
