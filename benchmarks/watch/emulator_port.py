"""The port a vibid-emu started with `--port 0` announces in its banner (the board studies here
start their own emulators)."""
import re
import sys
import time


def emulator_port(emu, log, seed, timeout_s=120):
    """Waits for the banner in `log` (the emulator's stdout, a file opened w+); exits naming the
    seed when it does not come within timeout_s (a loaded machine included) or the emulator ends."""
    deadline = time.monotonic() + timeout_s
    while True:
        log.seek(0)
        m = re.search(r"127\.0\.0\.1:(\d+),", log.read())
        if m:
            return m.group(1)
        if time.monotonic() > deadline or emu.poll() is not None:
            log.seek(0)
            sys.exit(f"seed {seed}: no port in the emulator's banner after {timeout_s} s: "
                     f"{log.read()}")
        time.sleep(0.02)
