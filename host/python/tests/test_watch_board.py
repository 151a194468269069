"""Board.watch against vibid-emu: the same blocks as `vibid watch --device` on an emulator of the
same seed (one runner, workflow::WatchBoardRun), a large mass step alarmed with the window the
docs state, the board stopped and idle when the loop is left (break or Ctrl-C) with the journal
kept, and the refusals made before the board starts."""
import json
import os
import signal

import pytest

import vibid
from conftest import ROOT, run_cli

# docs/watch.md's fast case: mass 2 30 % heavier at 240 s, a 230 s reference in 5 s blocks,
# windows of 6, no modes; acc1 and acc2 at 200 Hz under the operate scenario.
OPTIONS = dict(reference_s=230, block_s=5, window_blocks=6, modes_s=0)
CLI_OPTIONS = ["--reference-s", 230, "--block-s", 5, "--window-blocks", 6, "--modes-s", 0]


@pytest.fixture
def step_rig(tmp_path):
    rig = json.loads((ROOT / "host/emulator/rigs/chain2_mass_step.json").read_text())
    rig["changes"] = [{"at_s": 240.0, "mass": 2, "add_kg": 0.459}]
    path = tmp_path / "step240.json"
    path.write_text(json.dumps(rig))
    return path


def test_live_blocks_are_the_clis_and_the_step_alarms_with_its_window(make_emulator, step_rig,
                                                                     tmp_path):
    a = make_emulator(seed=1, rig=step_rig)
    r = run_cli("watch", "--seconds", 300, "--rate-hz", 200, "--scenario", "operate", "--json",
                *CLI_OPTIONS, device=a.url)
    assert r.returncode == 0, r.stderr
    cli = [json.loads(line) for line in r.stdout.splitlines()]
    cli_header = cli.pop(0)  # the first line: the options, the reference, the thresholds
    b = make_emulator(seed=1, rig=step_rig)
    with vibid.Board(b.url) as board:
        w = board.watch(seconds=300, rate_hz=200, scenario="operate",
                        journal=tmp_path / "live.jsonl", **OPTIONS)
        blocks = list(w)
        assert board.state() in ("idle", "done")
    assert w.start["responses"] == ["acc1_counts", "acc2_counts"]
    assert w.start["board_columns"] is False and w.start["model_stale"] is None
    assert w.reference.seconds == 230.0 and len(w.reference.modes) == 2
    assert w.reference.source == "watched"
    assert (w.reference.from_t_s, w.reference.to_t_s) == (0.0, pytest.approx(230.0 - 0.005))
    for h in (w.header, cli_header):
        h["reference"].pop("analysis_ms")
    assert w.header == cli_header and w.header["header"] == "vibid watch"
    assert w.result["stopped"] is False and w.result["blocks"] == 14
    assert len(blocks) == len(cli) == 14
    for block, c in zip(blocks, cli):
        d = block.to_dict()
        d.pop("analysis_ms"), c.pop("analysis_ms")
        assert d == c
    # The window of 230 to 260 s holds the change at 240 s and alarms when it is full.
    assert [x.t_s for x in blocks if x.alarm][0] == 260.0
    assert all(x.first_alarm_t_s == 260.0 for x in blocks[5:])
    journal = (tmp_path / "live.jsonl").read_text().splitlines()
    assert json.loads(journal[0])["reference"]["window_threshold"] == \
        w.reference.window_threshold
    assert [json.loads(line)["t_s"] for line in journal[1:]] == [x.t_s for x in blocks]


def test_leaving_the_loop_stops_the_board_and_keeps_the_journal(make_emulator, tmp_path):
    emulator = make_emulator(seed=2)
    with vibid.Board(emulator.url) as board:
        w = board.watch(rate_hz=200, scenario="operate", journal=tmp_path / "j.jsonl", **OPTIONS)
        for first in w:  # until stopped: the first block, then leave
            break
        w.close()
        assert w.result["stopped"] is True and w.result["reference_built"] is True
        assert board.state() in ("idle", "done")
        emulator.await_log("vibid-emu: sampling stopped")
        lines = (tmp_path / "j.jsonl").read_text().splitlines()
        assert json.loads(lines[0])["header"] == "vibid watch"
        assert json.loads(lines[1])["t_s"] == first.t_s == 235.0
        assert board.acquire(seconds=0.1, rate_hz=1000, channels=["acc1"]).samples == 100


@pytest.fixture
def ctrl_c_raises():
    # Python raises KeyboardInterrupt on SIGINT only when it started with SIGINT not ignored (a
    # background job of a shell starts with it ignored): the default handler, for the test.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def test_ctrl_c_stops_the_board(make_emulator, tmp_path, ctrl_c_raises):
    emulator = make_emulator(seed=3)
    with vibid.Board(emulator.url) as board:
        got = []
        with pytest.raises(KeyboardInterrupt):
            # 10 000 s: a bound, should the interrupt be lost (a failure, not a test that hangs).
            with board.watch(seconds=10000, rate_hz=200, scenario="operate",
                             journal=tmp_path / "j.jsonl", **OPTIONS) as w:
                for block in w:
                    got.append(block)
                    if len(got) == 1:
                        os.kill(os.getpid(), signal.SIGINT)
        assert w.result["stopped"] is True
        assert board.state() in ("idle", "done")
        assert len((tmp_path / "j.jsonl").read_text().splitlines()) >= len(got) + 1 >= 2


def test_closing_the_board_stops_its_watch(make_emulator):
    emulator = make_emulator(seed=5)
    board = vibid.Board(emulator.url)
    w = board.watch(rate_hz=200, scenario="operate", **OPTIONS)
    assert next(w).t_s == 235.0
    board.close()  # the watch is stopped (and waited for) before the link goes
    assert w.result["stopped"] is True
    emulator.await_log("vibid-emu: sampling stopped")


def test_refusals_come_before_the_board_starts(make_emulator, tmp_path):
    emulator = make_emulator(seed=4)
    with vibid.Board(emulator.url) as board:
        cases = [
            (dict(seconds=300, reference_s=60), ValueError,
             "watch: reference_s=60 is too short: the test needs at least"),
            (dict(seconds=100, reference_s=230, block_s=5, window_blocks=6), ValueError,
             "seconds=100 ends before the first block after the reference (235 s); watch "
             "longer or shorten reference_s"),
            (dict(seconds=0), ValueError, "seconds=0: watch for a positive length"),
            (dict(seconds=300, block_s="5"), TypeError, "block_s: expected a number, got str"),
            (dict(seconds=300, reference=vibid.Recording(["acc1"], [[0.0]], 200.0)), TypeError,
             "reference: expected a recording file's path"),
            (dict(seconds=300, journal=tmp_path / "none" / "j.jsonl"), FileNotFoundError, ""),
        ]
        for kwargs, error, message in cases:
            with pytest.raises(error) as e:
                board.watch(rate_hz=200, scenario="operate", **kwargs)
            assert message in str(e.value), (kwargs, str(e.value))
        assert board.state() == "idle"
    assert "sampling started" not in emulator.log_path.read_text()
