#!/usr/bin/python3
"""The bench in a real browser (headless chromium through selenium) against vibid-emu.

Starts the emulator (paced at wall-clock speed, as a board samples) on a free port, calibrates it
with the nominal model, its sensors and an observer through the vibid CLI, then:
  0. `vibid bench` without -o serves into ./vibid-bench under its working directory and prints
     that folder's full path;
  1. while the bench holds the board, `vibid info` on it is refused (exit 4);
  2. the board view loads with the board's identity, calibration and link budget; the opening
     form (5 kHz, four channels and d̂, 60 s, log rate auto) fits the budget (2500 records/s) and
     runs; every sample for 60 s is refused in the page's words, beside Start;
  3. after an acquisition (stopped, then one that ends) the board is shown stopped, as
     `vibid monitor` says, never sampling;
  4. at 5 kHz x 4 channels + d̂, d̂ on the scope follows the push the shaker scenario applies
     (the page's own buffers of d̂ and force2 against each other);
  5. a reload mid-acquisition shows the running acquisition's settings in the form and its
     history on the scope, which goes on;
  6. the observer view shows d̂ against the measured push with the running fit;
  7. the calibration view: a refused Identify shows its error beside its button (not "identifying"
     and not in the banner); it shows what an updated model changes, stages it and commits it;
  8. Ctrl-C ends the bench with exit code 130 and the recordings on disk; then `vibid info`
     shows the committed record's slot and CRC, and `vibid monitor` the board stopped.
Saves a screenshot of each view. With --bench-seconds, instead: the scope's frame rate, the
blocks reaching the page and the server's CPU while it streams (a timed run, no pass/fail).

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

    def serve(self, out=True, cwd=None):
        self.data = os.path.join(self.work, "data")
        self.server = subprocess.Popen([self.vibid, "--device", self.device, "bench", "--port",
                                        "0", *(["-o", self.data] if out else [])],
                                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                       cwd=cwd)
        self.url = self.server.stdout.readline().strip()
        check(re.fullmatch(r"http://127\.0\.0\.1:\d+/\?token=[0-9a-f]{32}", self.url) is not None,
              "the first line is not the URL with its token: " + self.url)

    def interrupt(self):
        """SIGINT to the bench: it must end with 130."""
        self.server.send_signal(signal.SIGINT)
        try:
            code = self.server.wait(timeout=15 * LOADED)
        except subprocess.TimeoutExpired:
            self.close()
            fail("waited %d s for the bench to end on SIGINT" % (15 * LOADED))
        check(code == 130, "the bench ended with %d on SIGINT, not 130" % code)

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


# A wait gives up after LOADED times what an idle machine needs: sized for a machine running 6-8
# jobs on 2 cores. A state that comes ends the wait at once, so the size costs nothing then; a
# wait that gives up fails the test naming what it waited for. How fast is a benchmark's question.
LOADED = 4


def wait(driver, condition, what, timeout=20):
    timeout *= LOADED
    try:
        return WebDriverWait(driver, timeout, poll_frequency=0.05).until(lambda d: condition(d))
    except Exception:
        fail("waited %g s for %s" % (timeout, what.replace("{message}", page_message(driver))))


def data(driver, element_id, key):
    return driver.execute_script(
        "const e = document.getElementById(arguments[0]); return e ? e.dataset[arguments[1]] : null",
        element_id, key)


def start_acquisition(driver, rate, seconds, params, channels, lowpass_hz=""):
    """Fills the form (log rate auto, the shaker scenario, the fit against force2) and starts."""
    Select(driver.find_element(By.ID, "rate")).select_by_visible_text(rate)
    Select(driver.find_element(By.ID, "log-rate")).select_by_value("auto")
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
    return (driver.find_element(By.ID, "message").text + " | " +
            driver.find_element(By.ID, "acq-msg").text + " | " +
            driver.find_element(By.ID, "acq-state").text)


def board_api(driver):
    """GET /api/board from the page (with the token it keeps in memory)."""
    return driver.execute_async_script(
        "const done = arguments[0]; fetch('/api/board', {headers: access.headers()})"
        ".then(r => r.json()).then(done)")


def wait_stopped(driver, words):
    """The Identity panel and /api/board after an acquisition: stopped, never sampling."""
    said = "status stopped: the last acquisition " + words
    wait(driver, lambda d: said in d.find_element(By.ID, "identity").text,
         "the Identity panel to say '%s' ({message})" % said)
    check(data(driver, "identity", "sampling") == "false",
          "the Identity panel: sampling %s" % data(driver, "identity", "sampling"))
    status = board_api(driver)["status"]
    check(status["sampling"] is False and status["text"].startswith("stopped"),
          "/api/board after an acquisition that %s: %s" % (words, status))
    return status


def correlation_and_gain(x, y):
    """Pearson correlation of x and y and the least-squares gain of y on x."""
    n = len(x)
    mx, my = sum(x) / n, sum(y) / n
    sxx = sum((a - mx) ** 2 for a in x)
    syy = sum((b - my) ** 2 for b in y)
    sxy = sum((a - mx) * (b - my) for a, b in zip(x, y))
    return sxy / (sxx * syy) ** 0.5, sxy / sxx


def moving_average(v, k):
    """Centred mean over k samples (k odd), the ends dropped."""
    out, acc, h = [], sum(v[:k]), k // 2
    for i in range(h, len(v) - h - 1):
        out.append(acc / k)
        acc += v[i + h + 1] - v[i - h]
    return out


def dhat_follows_push(driver, from_s):
    """d̂ against the push the shaker scenario applies (load cell 2), from the page's own
    buffers: both through a 0.25 s centred mean, which nulls the 16 Hz shaker (4 periods) and
    keeps the push's tones of 0.2-2 Hz; correlation and gain of d̂ on the push."""
    b = driver.execute_script(
        "const t = bench.time, d = bench.buffers['d_hat_n'], f = bench.buffers['force2_n'];"
        "const o = {t: [], d: [], f: []};"
        "for (let i = 0; i < t.n; i++) { o.t.push(t.at(i)); o.d.push(d.at(i)); o.f.push(f.at(i)); }"
        "return o")
    keep = [i for i, t in enumerate(b["t"]) if t >= from_s]
    dt = b["t"][1] - b["t"][0]
    k = int(round(0.25 / dt)) | 1
    d = moving_average([b["d"][i] for i in keep], k)
    f = moving_average([b["f"][i] for i in keep], k)
    r, gain = correlation_and_gain(f, d)
    return r, gain, len(keep) * dt


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


def default_out_dir(build, work):
    """`vibid bench` without -o: ./vibid-bench under its working directory, its path printed."""
    bench = Bench(build, work)
    try:
        cwd = os.path.join(work, "cwd")
        os.makedirs(cwd)
        bench.serve(out=False, cwd=cwd)
        said = bench.server.stderr.readline()
        folder = os.path.join(cwd, "vibid-bench")
        check(("recordings in " + folder + ";") in said, "the bench's folder line: " + said)
        check(os.path.isdir(folder), "no folder " + folder)
        bench.interrupt()
        print("vibid bench without -o: " + said.strip())
    finally:
        bench.close()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build", "host"))
    ap.add_argument("--screenshots", default=None, help="directory for the views' PNGs")
    ap.add_argument("--bench-seconds", type=float, default=0,
                    help="instead of the test: the scope's frame rate over this many seconds")
    args = ap.parse_args()
    if args.bench_seconds:
        frame_rate_bench(args)
        return
    t0 = time.monotonic()
    work = tempfile.mkdtemp(prefix="vibid-bench-browser-")
    shots = args.screenshots or work
    default_out_dir(os.path.abspath(args.build), work)
    bench = Bench(os.path.abspath(args.build), work)
    driver = None
    try:
        bench.calibrate()
        bench.serve()
        # One bench per board: while it holds the board, another command is refused.
        other = subprocess.run([bench.vibid, "--device", bench.device, "info"],
                               capture_output=True, text=True, timeout=30)
        check(other.returncode == 4 and ("in use" in other.stderr or "refused" in other.stderr),
              "vibid info while the bench holds the board: %d %s" % (other.returncode,
                                                                   other.stderr))
        driver = browser()
        driver.get(bench.url)
        wait(driver, lambda d: d.execute_script("return document.body.dataset.ready") == "yes",
             "the board view to load")
        text = driver.find_element(By.ID, "calibration").text
        check("rig_nominal" in text and "force1 N" in text, "calibration card: " + text)

        # The opening form: 5 kHz, four channels and d̂, 60 s, log rate auto. 12-byte records,
        # 4 per report: the link carries 4000 of the 5000 records/s, so every sample would fill
        # the 96 KiB log (6144 records) after 6.1 s; auto takes every 2nd (2500 records/s).
        form = driver.execute_script("return ask()")
        check(form == {"sample_period_us": 200, "channels": ["force1", "force2", "acc1", "acc2"],
                       "seconds": 60, "log_rate_hz": "auto", "log_dob": True},
              "the opening form: %s" % form)
        wait(driver, lambda d: data(d, "budget", "fits") == "yes", "the budget of the opening form")
        budget = driver.find_element(By.ID, "budget").text
        for words in ("logged 2500 records/s (every 2nd sample of 5000 Hz)",
                      "log holds 6144 records (96 KiB)", "log fills never: the link keeps up",
                      "this acquisition 60.0 s: fits, nothing dropped"):
            check(words in budget, "the budget box lacks %r: %s" % (words, budget))
        # Every sample for 60 s: refused in the page's own words, beside Start.
        Select(driver.find_element(By.ID, "log-rate")).select_by_visible_text("every sample")
        wait(driver, lambda d: data(d, "budget", "fits") == "no", "the budget of every sample")
        refusal = driver.find_element(By.ID, "budget-refusal").text
        check("the 96 KiB log overflows after 6.1 s of the 60.0 s" in refusal and
              "choose a log rate of 2500 Hz or lower" in refusal and "6.1 seconds or less" in refusal
              and "--" not in refusal, "the budget's refusal: " + refusal)
        driver.find_element(By.ID, "start").click()
        wait(driver, lambda d: d.find_element(By.ID, "acq-msg").get_attribute("class") == "error",
             "the refusal beside Start")
        check(driver.find_element(By.ID, "acq-msg").text == refusal,
              "beside Start: " + driver.find_element(By.ID, "acq-msg").text)
        check(driver.find_element(By.ID, "message").text == "", "the banner: " + page_message(driver))
        Select(driver.find_element(By.ID, "log-rate")).select_by_value("auto")
        driver.find_element(By.ID, "start").click()
        wait(driver, lambda d: d.execute_script("return document.body.dataset.running") == "yes",
             "the opening form's acquisition to run ({message})")
        check(driver.find_element(By.ID, "acq-msg").text == "acquisition started",
              "beside Start after the refusal: " + page_message(driver))
        state = driver.execute_script("return bench.state")
        check(state["log_rate_hz"] == 2500, "the opening form's log rate: %s" % state)
        wait(driver, lambda d: float(data(d, "scope", "lastTime") or 0) > 1.0, "1 s of data")
        driver.find_element(By.ID, "stop").click()
        wait(driver, lambda d: d.execute_script("return document.body.dataset.running") == "no",
             "the stop")
        stopped = wait_stopped(driver, "was stopped")
        print("opening form: %s records at 2500 records/s, then stopped; the board: %s"
              % (driver.execute_script("return bench.state.records"), stopped["text"]))

        # 5 kHz, force1 force2 acc1 acc2 and d̂ for 5.5 s: the log holds every sample (6.1 s).
        start_acquisition(driver, "5000 Hz", 5.5, "16, 10, 10", ["force1", "force2", "acc1", "acc2"])
        check(driver.execute_script("return bench.state.log_rate_hz") == 5000,
              "auto for 5.5 s: %s" % driver.execute_script("return bench.state"))
        # d̂ follows the push: 3 s after the push's 1 s fade-in.
        wait(driver, lambda d: float(data(d, "scope", "lastTime") or 0) > 4.5, "4.5 s of d̂")
        r, gain, span = dhat_follows_push(driver, 1.5)
        print("d̂ on the scope against the push over %.1f s (0.25 s means): correlation %.3f, "
              "gain %.3f" % (span, r, gain))
        check(span > 2.9, "%.2f s of d̂ on the page" % span)
        check(r > 0.9 and 0.8 < gain < 1.25,
              "d̂ does not follow the push: correlation %.3f, gain %.3f" % (r, gain))
        check(driver.execute_script("return document.querySelectorAll('#scope canvas').length") == 5,
              "the scope does not show 4 channels and d̂")
        driver.save_screenshot(os.path.join(shots, "bench-board.png"))
        wait(driver, lambda d: d.execute_script("return document.body.dataset.running") == "no",
             "the acquisition to end")
        wait_stopped(driver, "ended (27500 records)")

        # A reload mid-acquisition shows the running acquisition again: its settings in the form,
        # its history on the scope, which goes on.
        # Both load cells and d̂ (8-byte records, 7000 records/s of link): the log never fills.
        # The fit scores d̂ through the 4 Hz low-pass the demo's `dob run --lowpass-hz 4` uses.
        start_acquisition(driver, "5000 Hz", 12, "16, 10, 10", ["force1", "force2"], "4")
        sent = driver.execute_script("return bench.state.ask")
        wait(driver, lambda d: float(data(d, "scope", "lastTime") or 0) > 2.5, "2.5 s of data")
        before = float(data(driver, "scope", "lastTime"))
        driver.refresh()
        wait(driver, lambda d: d.execute_script("return document.body.dataset.running") == "yes",
             "the running state after the reload")
        wait(driver, lambda d: data(d, "acq-form", "shows") is not None,
             "the form to show the running acquisition")
        shown = driver.execute_script("return ask()")
        check(shown == sent, "the form after the reload: %s, the acquisition: %s" % (shown, sent))
        wait(driver, lambda d: float(data(d, "scope", "lastTime") or 0) > before,
             "the scope to go on after the reload")
        drawn = driver.execute_script(
            "const u = bench.plots[0].u, x = u.data[0];"
            "return {plots: bench.plots.length, first: bench.time.at(0), x0: x[0], x1: x[x.length - 1],"
            " n: x.length, finite: u.data[1].filter(Number.isFinite).length}")
        check(drawn["first"] <= before - 2.0,
              "the scope after the reload holds no history: from %.2f s (reload at %.2f s)"
              % (drawn["first"], before))
        check(drawn["x1"] - drawn["x0"] > 1.9 and drawn["finite"] == drawn["n"] > 100,
              "the scope after the reload draws %s" % drawn)
        check(driver.execute_script("return document.querySelectorAll('#scope canvas').length") == 3,
              "the scope after the reload does not show force1, force2 and d̂")
        print("reload at t = %.2f s: the form shows the running acquisition, the scope its data "
              "from t = %.2f s (%d points over %.2f s of the 2 s time base)"
              % (before, drawn["first"], drawn["n"], drawn["x1"] - drawn["x0"]))

        driver.find_element(By.CSS_SELECTOR, "#tabs button[data-view=observer]").click()
        wait(driver, lambda d: data(d, "fit", "fitPercent") is not None, "the running fit")
        check(driver.execute_script("return document.querySelectorAll('#observer-plot canvas').length") > 0,
              "no plot of d̂ and the measured force")
        wait(driver, lambda d: float(data(d, "fit", "windowS") or 0) >= 5.0 - 1e-9,
             "a fit over a 5 s window")
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
        refused_identify(driver)
        staged_crc = calibrate_from_page(driver, bench, shots)
    finally:
        if driver is not None:
            driver.quit()
    bench.interrupt()
    recordings = sorted(f for f in os.listdir(bench.data) if f.endswith(".csv"))
    check(len(recordings) == 3 and not any(f.endswith(".partial.csv") for f in recordings),
          "recordings: %s" % recordings)
    # The board holds what the page committed: vibid info names its slot and CRC.
    info = bench.cli("info")
    check(("slot 1, crc " + staged_crc) in info, "vibid info after the commit:\n" + info)
    shown = json.loads(bench.cli("cal", "show", "--json"))
    check(shown["label"] == "bench-updated" and abs(shown["M"][0][0] - 1.82) < 1e-6,
          "vibid cal show after the commit: %s %s" % (shown["label"], shown["M"]))
    print("calibration committed from the page: vibid info shows slot 1, crc " + staged_crc)
    # What the page said of the board, the CLI says too: stopped.
    monitor = bench.cli("monitor", "--count", "1")
    check("stopped: the last frame of the acquisition that ended" in monitor,
          "vibid monitor after the bench: " + monitor)
    bench.close()
    print("bench browser test: passed in %.1f s%s" % (
        time.monotonic() - t0, " (screenshots in %s)" % shots if args.screenshots else ""))
    shutil.rmtree(work)


def refused_identify(driver):
    """A refused Identify: its error beside its button, in place of its progress, not in the
    banner; the next step that succeeds is not followed by the old error."""
    driver.find_element(By.CSS_SELECTOR, "#tabs button[data-view=calibration]").click()
    driver.find_element(By.ID, "id-nominal").send_keys("no-such-model.json")
    driver.find_element(By.ID, "id-modal").send_keys("no-such-test.csv")
    driver.find_element(By.ID, "id-run").click()
    wait(driver, lambda d: d.find_element(By.ID, "id-run-status").get_attribute("class") == "error",
         "the refused Identify's error beside its button")
    said = driver.find_element(By.ID, "id-run-status").text
    check("no-such-model.json" in said and "identifying" not in said, "beside Identify: " + said)
    check(driver.find_element(By.ID, "message").text == "",
          "the banner after a refused Identify: " + driver.find_element(By.ID, "message").text)
    print("refused Identify, beside its button: " + said)
    for field in ("id-nominal", "id-modal"):
        driver.find_element(By.ID, field).clear()


def frame_rate_bench(args):
    """The scope while the board streams 5 kHz x 4 channels + d̂ (every sample, 12-byte records):
    frames drawn (requestAnimationFrame), blocks reaching the page and the server's CPU."""
    work = tempfile.mkdtemp(prefix="vibid-bench-frames-")
    bench = Bench(os.path.abspath(args.build), work)
    driver = None
    try:
        bench.calibrate()
        bench.serve()
        driver = browser()
        driver.get(bench.url)
        wait(driver, lambda d: d.execute_script("return document.body.dataset.ready") == "yes",
             "the board view to load")
        # 6 s at every sample fit the log (6.1 s); the figures over the seconds asked for.
        seconds = min(args.bench_seconds, 5.0)
        start_acquisition(driver, "5000 Hz", seconds + 1.0, "16, 10, 10",
                          ["force1", "force2", "acc1", "acc2"])
        wait(driver, lambda d: float(data(d, "scope", "lastTime") or 0) > 0.5, "the first data")
        frames0 = driver.execute_script("return bench.frames")
        blocks0 = driver.execute_script("return bench.blocks")
        cpu0, wall0 = bench.cpu_s(), time.monotonic()
        time.sleep(seconds - 0.5)  # the measured interval itself
        frames1 = driver.execute_script("return bench.frames")
        blocks1 = driver.execute_script("return bench.blocks")
        cpu1, wall1 = bench.cpu_s(), time.monotonic()
    finally:
        if driver is not None:
            driver.quit()
        bench.close()
    span = wall1 - wall0
    print("scope at 5 kHz x 4 channels + d̂ over %.1f s: %.1f frames/s, %.1f blocks/s; server CPU "
          "%.1f %% of one core" % (span, (frames1 - frames0) / span, (blocks1 - blocks0) / span,
                                  100.0 * (cpu1 - cpu0) / span))
    shutil.rmtree(work)


if __name__ == "__main__":
    main()
