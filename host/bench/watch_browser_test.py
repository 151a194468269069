#!/usr/bin/python3
"""The bench's Watch view in headless chromium against vibid-emu (operate scenario, 200 Hz).

1. The built-in rig with its mass step made 30 % at 240 s (docs/watch.md's fast example: a
   230 s reference, 5 s blocks, windows of 6): the form's empty fields say the library's
   defaults (those `vibid watch --help` states); a block too short for the band is refused in the
   page in the library's words, nothing started; with the demo's calibration and its 5 kHz observer
   running, logging d̂ at 200 Hz is refused by the board (shown), and "without d̂" runs; the
   watch started until Stop shows the
   reference's seconds left, then the blocks: the alarm at 260 s (the first full window after
   the change, as the CLI gives it in docs/watch.md), mode 1 moved down, the modes with their
   intervals once 70 s have come since the reference, the board's model test as get-info gives it
   (this calibration has none, and its log no model columns); Stop keeps the journal:
   the file in the bench's directory and the page's download are the blocks the page drew, line
   for line.
2. The built-in 3 % step as the rig file has it (mass 2 + 0.0459 kg at 600 s), a 590 s reference
   and the library's other defaults, 1200 s: flagged at 1190 s, the block `vibid watch` flags
   on the same emulator's recording, with the statistic `vibid watch --device` prints there
   (window T² 48.1 over 45.9, the 590 s reference's own threshold).
   A reload mid-run shows the blocks again and the run's settings in the form.
3. The board's own flag: the same rig calibrated with an observer from its truth (1 kHz) and the
   model test built from a 500 s calibration day (`vibid cal upload --watch-day`, as
   hil ModelStaleTest does), watched at 1 kHz logged at 200 Hz with d̂: every block carries the
   board's flag from the log; the page says MODEL STALE from the block after the trip, since the
   time `vibid info` gives for it (897.14 s on this emulator's default seed), and draws g against h.

  /usr/bin/python3 host/bench/watch_browser_test.py --build build/host [--screenshots docs]
"""
import argparse
import atexit
import json
import os
import re
import subprocess
import sys
import tempfile
import time

from selenium.webdriver.common.by import By

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from browser_test import ROOT, Bench, browser, check, wait  # noqa: E402

STEP_RIG = os.path.join(ROOT, "host", "emulator", "rigs", "chain2_mass_step.json")


class WatchBench(Bench):
    """An emulator (as fast as it runs: no --realtime) with `rig`, and a bench on it."""

    def __init__(self, build, work, rig):
        self.vibid = os.path.join(build, "host", "cli", "vibid")
        emu = os.path.join(build, "host", "emulator", "vibid-emu")
        self.work = work
        self.emu = subprocess.Popen([emu, "--port", "0", "--rig", rig],
                                    stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        self.server = None
        port = re.search(r"127\.0\.0\.1:(\d+)", self.emu.stdout.readline())
        check(port is not None, "no port in the emulator's banner")
        self.device = "usbip://127.0.0.1:" + port.group(1)
        self.server = None
        atexit.register(self.close)  # a failed check exits at once: nothing outlives the test


def js(driver, script):
    return driver.execute_script(script)


def fill(driver, values):
    for field, value in values.items():
        e = driver.find_element(By.ID, field)
        e.clear()
        if value:
            e.send_keys(value)


def open_watch(bench):
    bench.serve()
    driver = browser()
    try:
        driver.get(bench.url)
        wait(driver, lambda d: js(d, "return document.body.dataset.ready") == "yes", "the page")
        driver.find_element(By.CSS_SELECTOR, "#tabs button[data-view=watch]").click()
        wait(driver, lambda d: d.find_element(By.ID, "view-watch").get_attribute("data-ready") == "yes",
             "the watch view")
    except BaseException:
        driver.quit()
        raise
    return driver


def blocks(driver):
    return js(driver, "return watch.blocks") or []


def library_defaults(vibid):
    """The defaults `vibid watch --help` states (CLI11's `=VALUE`)."""
    text = subprocess.run([vibid, "watch", "--help"], capture_output=True, text=True).stdout
    out = {}
    for option in ("reference-s", "block-s", "window-blocks", "false-alarm-per-hour", "fmax-hz",
                   "modes-s", "rate-hz"):
        m = re.search(r"--%s [^\n]*=([^\s=]+)" % option, text)
        check(m is not None, "no default for --%s in vibid watch --help" % option)
        out[option] = m.group(1)
    return out


def large_change(args, work):
    with open(STEP_RIG) as f:
        rig = json.load(f)
    check(rig["changes"][0]["at_s"] == 600.0, "the built-in step moved: %s" % rig["changes"])
    rig["changes"][0]["at_s"] = 240.0
    rig["changes"][0]["add_kg"] = 10 * rig["changes"][0]["add_kg"]  # 3 % -> 30 %
    path = os.path.join(work, "step240.json")
    with open(path, "w") as f:
        json.dump(rig, f)
    bench = WatchBench(os.path.abspath(args.build), work, path)
    driver = None
    try:
        bench.calibrate()  # the demo's calibration, its 5 kHz observer running (no residual test)
        driver = open_watch(bench)
        defaults = library_defaults(bench.vibid)
        for field, option in (("wt-rate", "rate-hz"), ("wt-reference-s", "reference-s"),
                              ("wt-block", "block-s"), ("wt-window", "window-blocks"),
                              ("wt-far", "false-alarm-per-hour"), ("wt-fmax", "fmax-hz"),
                              ("wt-modes", "modes-s")):
            shown = driver.find_element(By.ID, field).get_attribute("placeholder")
            check(shown == defaults[option], "%s says %r, vibid watch's default is %s"
                  % (field, shown, defaults[option]))
        fill(driver, {"wt-rate": "200", "wt-reference-s": "230", "wt-block": "1", "wt-window": "6"})
        driver.find_element(By.ID, "wt-start").click()
        wait(driver, lambda d: "--block-s 1 is too short for the band" in d.find_element(By.ID, "wt-status").text,
             "the refusal of a 1 s block")
        print("refused: " + driver.find_element(By.ID, "wt-status").text)
        check(js(driver, "return document.body.dataset.watch") == "none", "a refused watch started")
        fill(driver, {"wt-block": "5", "wt-modes": "70"})
        # With d̂ at 200 Hz the board refuses (its observer runs at 5 kHz only): the run's error.
        driver.find_element(By.ID, "wt-start").click()
        wait(driver, lambda d: "runs at that rate only" in d.find_element(By.ID, "wt-status").text,
             "the board's refusal of d̂ at another rate than the observer's (the banner: {message})")
        check(js(driver, "return document.body.dataset.watch") == "ended", "the refused run not ended")
        print("refused by the board: " + driver.find_element(By.ID, "wt-status").text)
        driver.find_element(By.ID, "wt-no-dob").click()
        driver.find_element(By.ID, "wt-start").click()
        wait(driver, lambda d: 0 < float(d.find_element(By.ID, "wt-reference-state").get_attribute("data-left") or 0) < 230,
             "the reference's seconds left", timeout=30)
        print("reference phase: " + driver.find_element(By.ID, "wt-reference-state").text)
        wait(driver, lambda d: len(blocks(d)) >= 22, "22 blocks (to 340 s)", timeout=60)
        wait(driver, lambda d: d.find_element(By.ID, "wt-moved").text.startswith("mode "),
             "the mode that moved shown")
        moved = driver.find_element(By.ID, "wt-moved").text
        quantity = driver.find_element(By.ID, "wt-moved").get_attribute("data-quantity")
        words = {"omega": "Hz against", "zeta": "ζ:", "shape": "MAC"}
        check(quantity in words and words[quantity] in moved and "its interval" in moved,
              "what moved (%s): %s" % (quantity, moved))
        print("shown: " + moved)
        if args.screenshots:
            driver.set_window_size(1400, 1400)
            driver.find_element(By.CSS_SELECTOR, "#tabs button[data-view=watch]").click()
            wait(driver, lambda d: js(d, "return watch.dirty") is False, "the plots drawn")
            driver.save_screenshot(os.path.join(args.screenshots, "bench-watch.png"))
        driver.find_element(By.ID, "wt-stop").click()
        wait(driver, lambda d: js(d, "return document.body.dataset.watch") == "ended", "the end after Stop")
        b = blocks(driver)
        check(js(driver, "return watch.watch.end.stopped") is True, "not stopped by Stop")
        # Up to the Stop, every block in turn; the emulator (not paced in real time) may have run
        # ahead of the stream, and what its log still held after the Stop follows a gap.
        times = [x["t_s"] for x in b]
        check(times[:22] == [235.0 + 5 * i for i in range(22)] and times == sorted(set(times)),
              "block times: %s" % times)
        first = [x for x in b if x["alarm"]][0]
        # docs/watch.md (vibid watch --device on the same rig and options): ALARM at 260 s.
        check(first["t_s"] == 260.0 and b[-1]["first_alarm_t_s"] == 260.0, "first alarm: %s" % first)
        verdict = driver.find_element(By.ID, "wt-verdict")
        check(verdict.get_attribute("data-first-alarm") == "260" and "ALARM" in verdict.text,
              "the verdict shown: " + verdict.text)
        with_modes = [x for x in b if x["modes"]]
        check(with_modes and with_modes[0]["t_s"] == 300.0, "modes from 300 s (230 + 70)")
        last = with_modes[-1]
        check(last["moved"]["mode"] == 1 and last["moved"]["relative"] < -0.05,
              "mode 1 lower: %s" % last["moved"])
        check(all(m["ci95"]["omega_rad_s"] > 0 and m["ci95"]["zeta"] > 0 for x in with_modes for m in x["modes"]),
              "an interval of zero")
        board = driver.find_element(By.ID, "wt-board").text
        # device::WatchText's words for a calibration without the residual test (vibid info's).
        check(board == "no model test in the log; the board at the end: none (the calibration "
              "carries no residual test)",
              "the board's flag: " + board)
        check(int(driver.find_element(By.ID, "wt-freq").get_attribute("data-points")) >= 8,
              "the frequency trend's points")
        journal = js(driver, "return watch.watch.journal")
        with open(journal) as f:
            on_disk = [json.loads(line) for line in f.read().splitlines()]
        # The first line says what was watched (the page's watch has it as its header).
        header = on_disk.pop(0)
        check(header.get("header") == "vibid watch" and header == js(driver, "return watch.watch.header")
              and header["reference"]["source"] == "watched" and header["options"]["window_blocks"] == 6,
              "the journal's header: %s" % header)
        ref_text = driver.find_element(By.ID, "wt-reference-state").text
        check("watched, 0 to 229.995 s" in ref_text, "the reference's source and span shown: " + ref_text)
        check(on_disk == b, "the journal on disk (%d lines) is not the %d blocks drawn" % (len(on_disk), len(b)))
        driver.find_element(By.ID, "wt-download").click()
        wait(driver, lambda d: d.find_element(By.ID, "wt-download").get_attribute("data-lines") == str(len(b) + 1),
             "the journal downloaded (the header and every block)")
        print("30 %% at 240 s: ALARM at %.0f s; mode 1 %+.2f %% at %.0f s; %d blocks journaled in %s%s"
              % (first["t_s"], 100 * last["moved"]["relative"], last["t_s"], len(b), journal,
                 "; " + js(driver, "return watch.watch.warning") if js(driver, "return watch.watch.warning") else ""))
    finally:
        if driver is not None:
            driver.quit()
        bench.close()


def three_percent(args, work):
    bench = WatchBench(os.path.abspath(args.build), work, STEP_RIG)
    driver = None
    try:
        driver = open_watch(bench)
        fill(driver, {"wt-rate": "200", "wt-seconds": "1200", "wt-reference-s": "590", "wt-modes": "0"})
        driver.find_element(By.ID, "wt-start").click()
        wait(driver, lambda d: len(blocks(d)) >= 5, "five blocks", timeout=40)
        before = len(blocks(driver))
        driver.refresh()
        wait(driver, lambda d: js(d, "return document.body.dataset.ready") == "yes", "the page after the reload")
        driver.find_element(By.CSS_SELECTOR, "#tabs button[data-view=watch]").click()
        wait(driver, lambda d: len(blocks(d)) >= before, "the blocks after the reload")
        shows = json.loads(driver.find_element(By.ID, "wt-form").get_attribute("data-shows"))
        check(shows == js(driver, "return watch.settings()") == js(driver, "return watch.watch.settings"),
              "the form after the reload: %s" % shows)
        wait(driver, lambda d: js(d, "return document.body.dataset.watch") == "ended", "the end", timeout=60)
        b = blocks(driver)
        with open(js(driver, "return watch.watch.journal")) as f:
            on_disk = [json.loads(line) for line in f.read().splitlines()]
        # The first line says what was watched; the page has it as the watch's header.
        header = on_disk.pop(0)
        check(header.get("header") == "vibid watch" and header == js(driver, "return watch.watch.header"),
              "the journal's header: %s" % header)
        check(on_disk == b, "the journal on disk (%d lines: %s) is not the %d blocks drawn (%s)"
              % (len(on_disk), [x["t_s"] for x in on_disk], len(b), [x["t_s"] for x in b]))
        check(len(b) == 61, "%d blocks, not (1200 - 590) / 10" % len(b))
        first = [x for x in b if x["alarm"]]
        check(first and first[0]["t_s"] == 1190.0, "3 %% step: first alarm %s" % (first[0]["t_s"] if first else None))
        a = first[0]["accumulated"]
        # vibid watch --device on the same rig: "window 48.1/37.3 (60/60) | ALARM" at 1190 s.
        check(round(a["statistic"], 1) == 48.1 and round(a["threshold"], 1) == 45.9,
              "the alarm's window T²: %s" % a)
        check(js(driver, "return watch.watch.end.stopped") is False, "ended by Stop, not by its length")
        print("3 %% at 600 s: ALARM at %.0f s (window T² %.1f over %.1f), %d blocks after the change"
              % (first[0]["t_s"], a["statistic"], a["threshold"], (first[0]["t_s"] - 600) / 10))
    finally:
        if driver is not None:
            driver.quit()
        bench.close()


def board_flag(args, work):
    bench = WatchBench(os.path.abspath(args.build), work, STEP_RIG)
    driver = None
    try:
        emu = os.path.join(os.path.abspath(args.build), "host", "emulator", "vibid-emu")
        truth = os.path.join(work, "truth.json")
        with open(truth, "w") as f:
            f.write(subprocess.run([emu, "--rig", STEP_RIG, "--print-truth"], capture_output=True,
                                   text=True, check=True).stdout)
        sensors = os.path.join(ROOT, "examples", "sensors.json")
        design = os.path.join(work, "design.json")
        day = os.path.join(work, "day.csv")
        subprocess.run([bench.vibid, "dob", "design", truth, "--fs-hz", "1000", "--sensors",
                        sensors, "-o", design], check=True, capture_output=True)
        bench.cli("cal", "upload", truth, "--design", design, "--sensors", sensors)
        bench.cli("cal", "commit")
        bench.cli("dob", "start")
        bench.cli("acquire", "--seconds", "500", "--rate-hz", "1000", "--channels", "force1,x2",
                  "--scenario", "operate", "-o", day)
        bench.cli("cal", "upload", truth, "--design", design, "--sensors", sensors,
                  "--watch-day", day)
        bench.cli("cal", "commit")
        bench.cli("dob", "start")
        driver = open_watch(bench)
        fill(driver, {"wt-rate": "1000", "wt-log-rate": "200", "wt-seconds": "1200",
                      "wt-reference-s": "590", "wt-modes": "0"})
        driver.find_element(By.ID, "wt-start").click()
        wait(driver, lambda d: js(d, "return document.body.dataset.watch") == "ended", "the end",
             timeout=120)
        # The board's model_stale as the run read it at the end (vibid info --json's object: the
        # bench holds the board).
        tripped = js(driver, "return watch.watch.end.model_stale")
        check(tripped and tripped["stale"] is True, "the board's flag after the run: %s" % tripped)
        b = blocks(driver)
        check(len(b) == 61 and all(x["board"] for x in b), "every block with the board's flag")
        stale = [x for x in b if x["board"]["stale"]]
        check(stale and stale[0]["t_s"] - 0.005 >= tripped["tripped_at_s"] > stale[0]["t_s"] - 10,
              "the first stale block %s against the trip at %s" % (stale[0]["t_s"] if stale else None,
                                                                 tripped["tripped_at_s"]))
        since = stale[0]["board"]["stale_since_t_s"]
        check(tripped["tripped_at_s"] <= since < tripped["tripped_at_s"] + 0.005,
              "stale since %s, the board tripped at %s" % (since, tripped["tripped_at_s"]))
        shown = driver.find_element(By.ID, "wt-board")
        check(shown.get_attribute("data-stale") == "true" and "MODEL STALE since" in shown.text,
              "the board's flag shown: " + shown.text)
        check(driver.find_element(By.ID, "wt-board-card").is_displayed(), "g against h not drawn")
        if args.screenshots:
            driver.set_window_size(1400, 1400)
            driver.find_element(By.CSS_SELECTOR, "#tabs button[data-view=watch]").click()
            wait(driver, lambda d: js(d, "return watch.dirty") is False, "the plots drawn")
            driver.save_screenshot(os.path.join(args.screenshots, "bench-watch-board.png"))
        print("the board's flag: %s (board: tripped at %.2f s)" % (shown.text, tripped["tripped_at_s"]))
    finally:
        if driver is not None:
            driver.quit()
        bench.close()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build", "host"))
    ap.add_argument("--screenshots", default=None, help="directory for the view's PNG")
    args = ap.parse_args()
    t0 = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="vibid-watch-browser-") as work:
        os.makedirs(os.path.join(work, "a"))
        os.makedirs(os.path.join(work, "b"))
        os.makedirs(os.path.join(work, "c"))
        large_change(args, os.path.join(work, "a"))
        three_percent(args, os.path.join(work, "b"))
        board_flag(args, os.path.join(work, "c"))
    print("watch browser test passed in %.1f s" % (time.monotonic() - t0))


if __name__ == "__main__":
    main()
