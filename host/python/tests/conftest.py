"""Shared fixtures: the build tree's programs, the repository's example files, emulators."""
import json
import os
import pathlib
import re
import subprocess
import threading
import time

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]
BUILD = pathlib.Path(os.environ.get("VIBID_BUILD_DIR", ROOT / "build" / "host"))
VIBID = BUILD / "host" / "cli" / "vibid"
EMU = BUILD / "host" / "emulator" / "vibid-emu"

# How long a test waits for a state it acts on (the emulator's word that it samples or stopped):
# sized for a machine running 6-8 jobs on 2 cores, where a realtime emulator's first sample can
# come tens of seconds late. A state that comes ends the wait at once, so the size costs nothing
# then; a wait that gives up fails the test and says what it waited for.
STATE_WAIT_S = 120.0


def run_cli(*args, device=None) -> subprocess.CompletedProcess:
    cmd = [str(VIBID)] + ([f"--device={device}"] if device else []) + [str(a) for a in args]
    return subprocess.run(cmd, capture_output=True, text=True, check=False)


def cli_json(*args):
    r = run_cli(*args)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


class Emulator:
    """vibid-emu on a free port, its flash in a temporary file, its log (-v: clients, sampling
    starts and stops) in a file await_log reads; stopped by stop()."""

    def __init__(self, tmp: pathlib.Path, seed: int = 1, realtime: bool = False, rig=None):
        self.log_path = tmp / f"emu{seed}-{os.urandom(4).hex()}.log"
        self._log = open(self.log_path, "w")
        self.proc = subprocess.Popen(
            [str(EMU), "--port", "0", "--seed", str(seed), "--flash", str(tmp / f"flash{seed}.bin"),
             "-v"] + (["--realtime"] if realtime else []) + (["--rig", str(rig)] if rig else []),
            stdout=subprocess.PIPE, stderr=self._log, text=True)
        banner = self.proc.stdout.readline()
        m = re.search(r"127\.0\.0\.1:(\d+),", banner)
        assert m, banner
        self.url = f"usbip://127.0.0.1:{m.group(1)}"

    def await_log(self, text: str, count: int = 1, timeout_s: float = STATE_WAIT_S) -> None:
        """Waits until the emulator's log holds `text` `count` times (the state a test acts on);
        a wait that gives up raises AssertionError naming what it waited for, with the log."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            if self.log_path.read_text().count(text) >= count:
                return
            time.sleep(0.01)
        raise AssertionError(f"waited {timeout_s:g} s for the emulator's log to say {text!r} "
                             f"{count} time(s); it says:\n{self.log_path.read_text()[-2000:]}")

    def when_logged(self, text: str, action, timeout_s: float = STATE_WAIT_S) -> "WhenLogged":
        """Runs `action` on a thread once the log says `text` (while the test's own thread is
        busy, e.g. in an acquisition); check() fails the test if that wait gave up."""
        return WhenLogged(self, text, action, timeout_s)

    def stop(self):
        self.proc.terminate()
        self.proc.wait(timeout=STATE_WAIT_S)
        self._log.close()


class WhenLogged:
    """An action on a thread once the emulator's log says a text. The thread cannot fail the test
    itself: a wait that gave up is kept (the action is then not taken) and check() raises it."""

    def __init__(self, emulator: Emulator, text: str, action, timeout_s: float):
        self.failure = None
        self._thread = threading.Thread(target=self._run, args=(emulator, text, action, timeout_s))
        self._thread.start()

    def _run(self, emulator, text, action, timeout_s):
        try:
            emulator.await_log(text, timeout_s=timeout_s)
        except AssertionError as e:
            self.failure = e
            return
        action()

    def check(self) -> None:
        """Waits for the thread; raises the wait's failure (what it waited for, the log)."""
        self._thread.join()
        if self.failure is not None:
            raise self.failure


@pytest.fixture
def emulator(tmp_path):
    emu = Emulator(tmp_path)
    yield emu
    emu.stop()


@pytest.fixture
def make_emulator(tmp_path):
    started = []

    def make(seed=1, realtime=False, rig=None):
        started.append(Emulator(tmp_path, seed, realtime, rig))
        return started[-1]
    yield make
    for e in started:
        e.stop()
