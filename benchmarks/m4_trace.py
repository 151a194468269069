"""What the Cortex-M4 instruction counters in benchmarks/ share: building a firmware-preset image and
running it in qemu-system-arm -M mps2-an386 with one instruction per translation block
(-singlestep) and the execution log (-d exec,nochain), then reading the executed program counters.
QEMU executes instructions, not cycles, and needs no plugin for this."""
import contextlib
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
_PC = re.compile(r"\[[0-9a-f]+/([0-9a-f]+)/")


def _build_dir():
    """The firmware preset's build directory: build/firmware, or the one given by --build DIR."""
    if "--build" in sys.argv:
        i = sys.argv.index("--build")
        if i + 1 >= len(sys.argv):
            sys.exit("--build needs a directory")
        return os.path.abspath(sys.argv[i + 1])
    return os.path.join(ROOT, "build", "firmware")


BUILD_DIR = _build_dir()


def build(target):
    """Configures the firmware preset in BUILD_DIR and builds `target` (unless --no-build was given)."""
    if "--no-build" in sys.argv:
        return
    subprocess.run(["cmake", "--preset", "firmware", "-B", BUILD_DIR], cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
    subprocess.run(["cmake", "--build", BUILD_DIR, "-j2", "--target", target], cwd=ROOT, check=True,
                   stdout=subprocess.DEVNULL)


@contextlib.contextmanager
def executed_pcs(image):
    """Runs `image` under QEMU and yields an iterator over the executed program counters."""
    with tempfile.TemporaryDirectory() as tmp:
        log = os.path.join(tmp, "exec.log")
        run = subprocess.run(["qemu-system-arm", "-M", "mps2-an386", "-cpu", "cortex-m4", "-nographic", "-monitor",
                              "none", "-serial", "none", "-semihosting-config", "enable=on,target=native",
                              "-singlestep", "-d", "exec,nochain", "-D", log, "-kernel", image],
                             capture_output=True, text=True, timeout=600)
        if run.returncode != 0:
            sys.exit("the image failed under QEMU:\n" + run.stdout + run.stderr)

        def pcs():
            with open(log) as f:
                for line in f:
                    m = _PC.search(line)
                    if m:
                        yield int(m.group(1), 16)

        yield pcs()
