"""Shared fixtures: the build tree's programs, the repository's example files, emulators."""
import json
import os
import pathlib
import re
import subprocess
import time

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]
BUILD = pathlib.Path(os.environ.get("VIBID_BUILD_DIR", ROOT / "build" / "host"))
VIBID = BUILD / "host" / "cli" / "vibid"
EMU = BUILD / "host" / "emulator" / "vibid-emu"


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

    def await_log(self, text: str, count: int = 1, timeout_s: float = 10.0) -> bool:
        """Waits until the emulator's log holds `text` `count` times (the state a test acts on);
        False on timeout."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            if self.log_path.read_text().count(text) >= count:
                return True
            time.sleep(0.01)
        return False

    def stop(self):
        self.proc.terminate()
        self.proc.wait(timeout=10)
        self._log.close()


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
