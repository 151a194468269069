"""What the Cortex-M4 instruction counters in benchmarks/ share: building a firmware-preset image and
running it in qemu-system-arm -M mps2-an386 with one instruction per translation block
(-singlestep) and the execution log (-d exec,nochain), then reading the executed program counters.
QEMU executes instructions, not cycles, and needs no plugin for this.

The image's symbols and disassembly, and the count of each call of a kernel entry until control is
back in the image's driver loop, with its cycles estimated: QEMU executes instructions, not cycles,
so each executed instruction is priced with the Cortex-M4 TRM timings (zero wait states; single
loads and stores 2 cycles, 1 when they follow another load or store; LDRD/STRD 3; LDM/STM/PUSH/POP
1 + registers; multiplies and SMLAL 1; divides 7; taken branches 3, i.e. a two-cycle refill), the
taken branches found from the logged program counters. On the board, flash wait states the ART
accelerator does not hide come on top."""
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


def symbols(image, names):
    """(start, end) of each function whose demangled name starts with one of `names`, by that name;
    exits naming the image when one is missing."""
    out = subprocess.run(["arm-none-eabi-nm", "-C", "-S", image], check=True, capture_output=True, text=True).stdout
    found = {}
    for line in out.splitlines():
        parts = line.split(maxsplit=3)
        if len(parts) == 4 and parts[2] in "tTW":
            for key in names:
                if parts[3].startswith(key):
                    start = int(parts[0], 16) & ~1
                    found[key] = (start, start + int(parts[1], 16))
    if len(found) != len(names):
        sys.exit("symbols not found in " + image + ": " + repr(found))
    return found


def disassembly(image):
    """pc -> (size in bytes, mnemonic, operands) for every instruction of the image."""
    out = subprocess.run(["arm-none-eabi-objdump", "-d", image], check=True, capture_output=True, text=True).stdout
    table = {}
    line_re = re.compile(r"^\s*([0-9a-f]+):\t([0-9a-f]{4}(?: [0-9a-f]{4})?)\s*\t(\S+)\s*(.*)$")
    for line in out.splitlines():
        m = line_re.match(line)
        if m:
            table[int(m.group(1), 16)] = (2 * len(m.group(2).split()), m.group(3), m.group(4))
    return table


SINGLE_LS = re.compile(r"^(ldr|str)(b|h|sb|sh)?(\.w|\.n)?$")
MULTI_LS = re.compile(r"^(ldm|stm|push|pop)")
BRANCH = re.compile(r"^(b|bl|bx|blx|cbz|cbnz)(eq|ne|cs|hs|cc|lo|mi|pl|vs|vc|hi|ls|ge|lt|gt|le)?(\.w|\.n)?$")


def cycles(insn, taken, after_ls):
    """Estimated Cortex-M4 cycles of one executed instruction (see the module comment)."""
    _, mnemonic, operands = insn
    if SINGLE_LS.match(mnemonic):
        return 1 if after_ls else 2
    if mnemonic.startswith(("ldrd", "strd")):
        return 3
    if MULTI_LS.match(mnemonic):
        regs = operands[operands.find("{") + 1:operands.find("}")]
        n = sum(int(r.split("-")[1][1:]) - int(r.split("-")[0][1:]) + 1 if "-" in r else 1
                for r in regs.replace(" ", "").split(",") if r)
        return 1 + n + (2 if taken else 0)
    if mnemonic.startswith(("udiv", "sdiv")):
        return 7
    if BRANCH.match(mnemonic):
        return 3 if taken else 1
    return 3 if taken else 1  # anything else that writes pc, or 1


def per_call_counts(executed, entry, driver, insns):
    """(instructions, estimated cycles) of each call of the function at `entry` (start, end), from
    its first instruction until control is back in `driver` (start, end), in call order."""
    calls, pcs, inside = [], [], False

    def close():
        total, after_ls = 0, False
        for i, pc in enumerate(pcs):
            insn = insns[pc]
            nxt = pcs[i + 1] if i + 1 < len(pcs) else None
            total += cycles(insn, nxt is not None and nxt != pc + insn[0] or nxt is None, after_ls)
            after_ls = bool(SINGLE_LS.match(insn[1]))
        calls.append((len(pcs), total))

    for pc in executed:
        if pc == entry[0]:
            inside, pcs = True, []
        elif inside and driver[0] <= pc < driver[1]:
            close()
            inside = False
        if inside:
            pcs.append(pc)
    return calls
