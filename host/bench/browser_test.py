#!/usr/bin/python3
"""The bench in a real browser (headless chromium through selenium) against vibid-emu.

Starts the emulator (paced at wall-clock speed, as a board samples) on a free port, calibrates it
with the nominal model, its sensors and an observer through the vibid CLI, starts `vibid bench`
on a free port and drives the page:
  0. while the bench holds the board, `vibid info` on it is refused (exit 4);
  1. the board view loads with the board's identity, calibration and link budget;
  2. at 5 kHz x 4 channels + d̂ the scope shows d̂ moving (read twice from the page) and draws
     at its frame rate (requestAnimationFrame counts: the benchmark figure);
  3. a reload mid-acquisition shows the running acquisition again;
  4. the observer view shows d̂ against the measured push with the running fit;
  5. the calibration view shows what an updated model changes, stages it and commits it;
  6. Ctrl-C ends the bench with exit code 130 and the recordings on disk; then `vibid info`
     shows the committed record's slot and CRC.
Prints the figures (frame rate, server CPU); saves a screenshot of each view.

  /usr/bin/python3 host/bench/browser_test.py --build build/host [--screenshots docs]
"""
import argparse
import atexit
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select, WebDriverWait

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def fail(message):
    print("bench browser test: FAILED: " + message, file=sys.stderr)
    sys.exit(1)


def check(condition, message):
    if not condition:
        fail(message)


class Bench:
    def __init__(self, build, work):
        self.vibid = os.path.join(build, "host", "cli", "vibid")
        emu = os.path.join(build, "host", "emulator", "vibid-emu")
        self.work = work
        self.emu = subprocess.Popen([emu, "--port", "0", "--realtime", "--flash",
                                     os.path.join(work, "flash.bin")],
                                    stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        # A failed check exits at once: the emulator and the bench must not outlive the test.
        atexit.register(self.close)
        banner = self.emu.stdout.readline()
        port = re.search(r"127\.0\.0\.1:(\d+)", banner)
        check(port is not None, "no port in the emulator's banner: " + banner)
        self.device = "usbip://127.0.0.1:" + port.group(1)
        self.server = None

    def cli(self, *args):
        r = subprocess.run([self.vibid, "--device", self.device, *args], capture_output=True,
                           text=True, timeout=60)
        check(r.returncode == 0, "vibid %s: %s" % (" ".join(args), r.stderr))
        return r.stdout

    def calibrate(self):
        sensors = os.path.join(ROOT, "examples", "sensors.json")
        model = os.path.join(ROOT, "examples", "rig_nominal.json")
        with open(sensors) as f:
            force_fs = json.load(f)["channels"]["force1"]["full_scale"]
        design = os.path.join(self.work, "design.json")
        self.cli("dob", "design", model, "--force-fs-n", str(force_fs), "--fs-hz", "5000", "-o",
                 design)
        self.cli("cal", "upload", model, "--design", design, "--sensors", sensors)
        self.cli("cal", "commit")
        self.cli("dob", "start")

    def serve(self):
        self.data = os.path.join(self.work, "data")
        self.server = subprocess.Popen([self.vibid, "--device", self.device, "bench", "--port",
                                        "0", "-o", self.data],
                                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.url = self.server.stdout.readline().strip()
        check(re.fullmatch(r"http://127\.0\.0\.1:\d+/\?token=[0-9a-f]{32}", self.url) is not None,
              "the first line is not the URL with its token: " + self.url)

    def cpu_s(self):
        with open("/proc/%d/stat" % self.server.pid) as f:
            fields = f.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")

    def close(self):
        for p in (self.server, self.emu):
            if p is not None and p.poll() is None:
                p.kill()
                p.wait()


def browser():
    options = webdriver.ChromeOptions()
    options.binary_location = "/usr/bin/chromium"
    for a in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage",
              "--window-size=1400,1250", "--disable-gpu"):
        options.add_argument(a)
    return webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)


def wait(driver, condition, what, timeout=20):
    try:
        return WebDriverWait(driver, timeout, poll_frequency=0.05).until(lambda d: condition(d))
    except Exception:
        fail("waited %g s for %s" % (timeout, what.replace("{message}", page_message(driver))))


def data(driver, element_id, key):
    return driver.execute_script(
        "const e = document.getElementById(arguments[0]); return e ? e.dataset[arguments[1]] : null",
        element_id, key)


def start_acquisition(driver, rate, seconds, params, channels, lowpass_hz=""):
    Select(driver.find_element(By.ID, "rate")).select_by_visible_text(rate)
    for box in driver.find_elements(By.CSS_SELECTOR, "#channels input"):
        if box.is_selected() != (box.get_attribute("value") in channels):
            box.click()
    s = driver.find_element(By.ID, "seconds")
    s.clear()
    s.send_keys(str(seconds))
    Select(driver.find_element(By.ID, "scenario")).select_by_visible_text("shaker")
    p = driver.find_element(By.ID, "scenario-params")
    p.clear()
    p.send_keys(params)
    Select(driver.find_element(By.ID, "fit-measured")).select_by_visible_text("force2")
    lp = driver.find_element(By.ID, "fit-lowpass")
    lp.clear()
    lp.send_keys(lowpass_hz)
    driver.find_element(By.ID, "start").click()
    wait(driver, lambda d: d.execute_script("return document.body.dataset.running") == "yes",
         "the acquisition to run (the page says: %s)" % "{message}")


def page_message(driver):
    return driver.find_element(By.ID, "message").text + " | " + driver.find_element(By.ID, "acq-state").text


def calibrate_from_page(driver, bench, shots):
    """Stages and commits an updated model (m1 1.82 kg) from the calibration view; its CRC."""
    with open(os.path.join(ROOT, "examples", "rig_nominal.json")) as f:
        model = json.load(f)
    model["masses"][0] = 1.82
    with open(os.path.join(bench.data, "updated.json"), "w") as f:
        json.dump(model, f)
    for name, source in (("design.json", os.path.join(bench.work, "design.json")),
                         ("sensors.json", os.path.join(ROOT, "examples", "sensors.json"))):
        with open(source) as src, open(os.path.join(bench.data, name), "w") as dst:
            dst.write(src.read())
    driver.find_element(By.CSS_SELECTOR, "#tabs button[data-view=calibration]").click()
    for field, value in (("cal-model", "updated.json"), ("cal-design", "design.json"),
                         ("cal-sensors", "sensors.json"), ("cal-label", "bench-updated")):
        driver.find_element(By.ID, field).send_keys(value)
    driver.find_element(By.ID, "cal-preview").click()
    wait(driver, lambda d: data(d, "cal-changes", "changes") is not None,
         "the changes the commit makes ({message})")
    text = driver.find_element(By.ID, "cal-changes").text
    check("label" in text and "bench-updated" in text and "M" in text and "1.82" in text,
          "the changes shown: " + text)
    driver.find_element(By.ID, "cal-upload").click()
    wait(driver, lambda d: "staged" in d.find_element(By.ID, "cal-status").text,
         "the record staged ({message})")
    crc = re.search(r"crc (0x[0-9a-f]{8})", driver.find_element(By.ID, "cal-status").text)
    check(crc is not None, "no CRC in: " + driver.find_element(By.ID, "cal-status").text)
    driver.save_screenshot(os.path.join(shots, "bench-calibration.png"))
    driver.find_element(By.ID, "cal-commit").click()
    wait(driver, lambda d: data(d, "cal-status", "committed") is not None,
         "the commit ({message})")
    return crc.group(1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build", "host"))
    ap.add_argument("--screenshots", default=None, help="directory for the views' PNGs")
    args = ap.parse_args()
    t0 = time.monotonic()
    work = tempfile.mkdtemp(prefix="vibid-bench-browser-")
    shots = args.screenshots or work
    bench = Bench(os.path.abspath(args.build), work)
    driver = None
    try:
        bench.calibrate()
        bench.serve()
        # One bench per board: while it holds the board, another command is refused.
        other = subprocess.run([bench.vibid, "--device", bench.device, "info"],
                               capture_output=True, text=True, timeout=30)
        check(other.returncode == 4 and "refused" in other.stderr,
              "vibid info while the bench holds the board: %d %s" % (other.returncode,
                                                                   other.stderr))
        driver = browser()
        driver.get(bench.url)
        wait(driver, lambda d: d.execute_script("return document.body.dataset.ready") == "yes",
             "the board view to load")
        text = driver.find_element(By.ID, "calibration").text
        check("rig_nominal" in text and "force1 N" in text, "calibration card: " + text)
        check("records/s" in driver.find_element(By.ID, "budget").text, "no link budget shown")

        # 5 kHz, force1 force2 acc1 acc2 and d̂: 12-byte records, the link carries 4000 of the
        # 5000 records/s, so the 96 KiB log holds 6.1 s (the budget the page shows).
        start_acquisition(driver, "5000 Hz", 5.5, "16, 10, 10", ["force1", "force2", "acc1", "acc2"])
        wait(driver, lambda d: data(d, "scope", "lastDhat") is not None, "d̂ on the scope")
        first = float(data(driver, "scope", "lastDhat"))
        time.sleep(0.5)
        second = float(data(driver, "scope", "lastDhat"))
        check(first != second, "d̂ did not move: %g then %g" % (first, second))
        print("d̂ on the scope: %.6g N, 0.5 s later %.6g N" % (first, second))
        frames0 = driver.execute_script("return bench.frames")
        blocks0 = driver.execute_script("return bench.blocks")
        cpu0, wall0 = bench.cpu_s(), time.monotonic()
        time.sleep(2.0)
        frames1 = driver.execute_script("return bench.frames")
        blocks1 = driver.execute_script("return bench.blocks")
        cpu1, wall1 = bench.cpu_s(), time.monotonic()
        fps = (frames1 - frames0) / (wall1 - wall0)
        cpu = 100.0 * (cpu1 - cpu0) / (wall1 - wall0)
        print("scope at 5 kHz x 4 channels + d̂: %.1f frames/s, %.1f blocks/s; server CPU %.1f %%"
              % (fps, (blocks1 - blocks0) / (wall1 - wall0), cpu))
        check(fps >= 30.0, "the scope drew %.1f frames/s, fewer than 30" % fps)
        check(driver.execute_script("return document.querySelectorAll('#scope canvas').length") == 5,
              "the scope does not show 4 channels and d̂")
        driver.save_screenshot(os.path.join(shots, "bench-board.png"))
        wait(driver, lambda d: d.execute_script("return document.body.dataset.running") == "no",
             "the acquisition to end")

        # A reload mid-acquisition shows the running acquisition again, with what it has drawn.
        # Both load cells and d̂ (8-byte records, 7000 records/s of link): the log never fills.
        # The fit scores d̂ through the 4 Hz low-pass the demo's `dob run --lowpass-hz 4` uses.
        start_acquisition(driver, "5000 Hz", 12, "16, 10, 10", ["force1", "force2"], "4")
        wait(driver, lambda d: float(data(d, "scope", "lastTime") or 0) > 2.0, "2 s of data")
        before = float(data(driver, "scope", "lastTime"))
        driver.refresh()
        wait(driver, lambda d: d.execute_script("return document.body.dataset.running") == "yes",
             "the running state after the reload")
        wait(driver, lambda d: float(data(d, "scope", "lastTime") or 0) > before,
             "the scope to go on after the reload")
        print("reload at t = %.2f s: the page shows the acquisition at t = %.2f s" %
              (before, float(data(driver, "scope", "lastTime"))))

        driver.find_element(By.CSS_SELECTOR, "#tabs button[data-view=observer]").click()
        wait(driver, lambda d: data(d, "fit", "fitPercent") is not None, "the running fit")
        check(driver.execute_script("return document.querySelectorAll('#observer-plot canvas').length") > 0,
              "no plot of d̂ and the measured force")
        wait(driver, lambda d: float(data(d, "scope", "lastTime") or 0) > 7.0, "a 5 s fit window")
        time.sleep(0.6)
        fit = float(data(driver, "fit", "fitPercent"))
        check(re.search(r"low-pass at 4(\.0+)? Hz", driver.find_element(By.ID, "fit").text),
              "the fit does not say its low-pass: " + driver.find_element(By.ID, "fit").text)
        # The board runs the nominal model's observer: the demo's nominal push fit is 69.85 %
        # over its whole record (README); the raw d̂ scores about 53 %.
        check(fit > 60.0, "running fit of the low-passed d̂: %.1f %%" % fit)
        print("running fit of d̂ (4 Hz low-pass) against the push: %.1f %%" % fit)
        driver.save_screenshot(os.path.join(shots, "bench-observer.png"))
        wait(driver, lambda d: d.execute_script("return document.body.dataset.running") == "no",
             "the acquisition to end", timeout=30)
        staged_crc = calibrate_from_page(driver, bench, shots)
    finally:
        if driver is not None:
            driver.quit()
    bench.server.send_signal(signal.SIGINT)
    try:
        code = bench.server.wait(timeout=10)
    except subprocess.TimeoutExpired:
        bench.close()
        fail("the bench did not end on SIGINT")
    check(code == 130, "the bench ended with %d on SIGINT, not 130" % code)
    recordings = sorted(f for f in os.listdir(bench.data) if f.endswith(".csv"))
    check(len(recordings) == 2 and not any(f.endswith(".partial.csv") for f in recordings),
          "recordings: %s" % recordings)
    # The board holds what the page committed: vibid info names its slot and CRC.
    info = bench.cli("info")
    check(("slot 1, crc " + staged_crc) in info, "vibid info after the commit:\n" + info)
    shown = json.loads(bench.cli("cal", "show", "--json"))
    check(shown["label"] == "bench-updated" and abs(shown["M"][0][0] - 1.82) < 1e-6,
          "vibid cal show after the commit: %s %s" % (shown["label"], shown["M"]))
    print("calibration committed from the page: vibid info shows slot 1, crc " + staged_crc)
    bench.close()
    print("bench browser test: passed in %.1f s%s" % (
        time.monotonic() - t0, " (screenshots in %s)" % shots if args.screenshots else ""))
    shutil.rmtree(work)


if __name__ == "__main__":
    main()
