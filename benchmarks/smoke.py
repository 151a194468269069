#!/usr/bin/python3
"""Runs every documented benchmark command once, in a short smoke mode, so that a renamed folder
or program cannot break one unseen. Its figures are not judged: each command must exit 0.

The commands are those the docs and the benchmarks' own files give, collected from README.md,
docs/*.md and every text file under benchmarks/ (usage lines, comments): each
`/usr/bin/python3 benchmarks/DIR/NAME.py ARGS` and each `build/host/bench[marks]/DIR/PROGRAM ARGS`,
as written (bracketed placeholders such as `[BUILD_DIR]` left out), each program once (the first
form found; its other forms differ only in counts of seeds or repeats, and each form's program
must be there). A path that names no file fails here, as it would fail a reader. They run from the repository's root with
VIBID_BENCH_SMOKE=1 (the scripts' small records and single repeats) and BENCHMARK_MIN_TIME
(Google Benchmark's shortest runs). The host build (benchmarks included) and, for the Cortex-M4
counts, the firmware build must be there.

Usage (from the project root): /usr/bin/python3 benchmarks/smoke.py [--list]
Prints each command with its exit status and time, and `benchmarks smoke: N passed, N failed`.
"""
import glob
import os
import re
import shlex
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# A command ends at a backtick, a closing parenthesis, a comment, a shell operator or the line.
_END = r"[^`)#;&|\n]*"
COMMAND = re.compile(r"(/usr/bin/python3 benchmarks/[\w/.-]+\.py" + _END + r"|"
                     r"(?<![\w/])build/host/bench(?:marks)?/[\w/.-]+" + _END + r")")
# Each command gets this long (the slowest, the board-flag study's seed, takes about a minute
# on an idle machine); the bound keeps a hung benchmark from holding CI.
TIMEOUT_S = 900


def sources():
    files = [os.path.join(ROOT, "README.md")] + sorted(glob.glob(os.path.join(ROOT, "docs", "*.md")))
    for path in sorted(glob.glob(os.path.join(ROOT, "benchmarks", "**", "*"), recursive=True)):
        if os.path.isfile(path) and path.endswith((".py", ".cpp", ".txt", ".md")) and \
                os.path.abspath(path) != os.path.abspath(__file__):
            files.append(path)
    return files


def commands():
    """The documented commands, one per program (the first found), with the file that gives it."""
    found, programs = {}, {}
    for path in sources():
        with open(path, encoding="utf-8") as f:
            for m in COMMAND.finditer(f.read()):
                text = re.sub(r"\[[^\]]*\]", "", m.group(1))  # optional arguments: left out
                words = tuple(shlex.split(text))
                program = words[1] if words[0] == "/usr/bin/python3" else words[0]
                if os.path.abspath(os.path.join(ROOT, program)) == os.path.abspath(__file__):
                    continue  # the docs name this runner too; it never runs itself
                where = os.path.relpath(path, ROOT)
                if program not in programs:
                    found[words] = where
                programs.setdefault(program, where)
    return found, programs


def main():
    found, programs = commands()
    if "--list" in sys.argv[1:]:
        for words, where in found.items():
            print(f"{shlex.join(words)}    ({where})")
        return 0
    env = dict(os.environ, VIBID_BENCH_SMOKE="1", BENCHMARK_MIN_TIME="0.001")
    passed = failed = 0
    for program, where in programs.items():
        if not os.path.isfile(os.path.join(ROOT, program)):
            failed += 1
            print(f"FAIL {program} ({where}): no such file (a renamed folder or program?)")
    for words, where in found.items():
        t0 = time.monotonic()
        try:
            r = subprocess.run(list(words), cwd=ROOT, env=env, capture_output=True, text=True,
                               timeout=TIMEOUT_S)
            code, out = r.returncode, r.stdout + r.stderr
        except FileNotFoundError as e:
            code, out = 127, str(e)
        except subprocess.TimeoutExpired:
            code, out = -1, f"no end after {TIMEOUT_S} s"
        ok = code == 0
        passed, failed = passed + ok, failed + (not ok)
        print(f"{'ok  ' if ok else 'FAIL'} {time.monotonic() - t0:6.1f} s  {shlex.join(words)}"
              f"    ({where})", flush=True)
        if not ok:
            print(f"     exit {code}: " + "\n     ".join(out.strip().splitlines()[-15:]))
    print(f"benchmarks smoke: {passed} passed, {failed} failed")
    return 1 if failed or not found else 0


if __name__ == "__main__":
    sys.exit(main())
