#!/usr/bin/python3
"""The bench's hammer test view in headless chromium against vibid-emu.

The emulator's rig asks for a double hit at hit 2 and an overload at hit 4 (hammer_test_hits).
The page starts a hammer test (after a refused one: the session's message is shown) with the
record length left empty (the CLI's default: the shortest hit spacing), a reload mid-test shows
the hits again and the running test's settings in the form, the faulty hits come out rejected
with their reasons and the others accepted, the operator rejects and accepts hit 1 from the
keyboard and hit 3 with the buttons, the test is saved; the FRF is drawn over the band the modes
were identified in, every line on request;
then `vibid modes --json` and `vibid frf-estimate` with their defaults on the saved files with the
saved hit list give exactly the modes the page holds, the warnings it shows and the FRF file the
test saved. A second test shows at once as the new one (its settings, none of the first test's
hits or modes, no error); a hit rejected while it runs: the choice is on disk at once, and
Ctrl-C leaves the test whole (recording, hits, FRF: frf-estimate gives the same file). Prints the
hit-to-screen latency (the completing block's arrival on the host to the FRF drawn in the
browser).

  /usr/bin/python3 host/bench/hammer_browser_test.py --build build/host [--screenshots docs]
"""
import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from browser_test import ROOT, Bench, browser, check, fail, wait  # noqa: E402

# 5 kHz, the hammer's load cell and both accelerometers, hits on m2 every 1.5 s (0.7-1.3 x) for
# 24 s; the record of a hit left empty: the CLI's default, the shortest spacing between hits.
SETTINGS = {"hm-seconds": "24", "hm-record": "", "hm-params": "2, 100, 1.5, 0"}
COLUMNS = ["--force", "force1_n", "--response", "acc1_m_s2,acc2_m_s2", "--impact"]
MODES = ["--driving-point", "acc2_m_s2"]


NOMINAL = os.path.join(ROOT, "examples", "rig_nominal.json")
SENSORS = os.path.join(ROOT, "examples", "sensors.json")


class HammerBench(Bench):
    def __init__(self, build, work):
        with open(os.path.join(ROOT, "host", "emulator", "rigs", "default.json")) as f:
            rig = json.load(f)
        rig["hammer_test_hits"] = {"double_hit": [2], "overload": [4]}
        rig_path = os.path.join(work, "rig.json")
        with open(rig_path, "w") as f:
            json.dump(rig, f)
        self.vibid = os.path.join(build, "host", "cli", "vibid")
        emu = os.path.join(build, "host", "emulator", "vibid-emu")
        self.work = work
        self.emu = subprocess.Popen([emu, "--port", "0", "--realtime", "--rig", rig_path],
                                    stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        port = re.search(r"127\.0\.0\.1:(\d+)", self.emu.stdout.readline())
        check(port is not None, "no port in the emulator's banner")
        self.device = "usbip://127.0.0.1:" + port.group(1)
        self.server = None

    def offline(self, *args):
        r = subprocess.run([self.vibid, *args], capture_output=True, text=True, timeout=60)
        check(r.returncode == 0, "vibid %s: %s" % (" ".join(args), r.stderr))
        return r.stdout


def js(driver, script):
    return driver.execute_script(script)


def hits(driver):
    return js(driver, "return hammer.snap ? hammer.snap.hits : []") or []


def server_hits(driver):
    """The hits the server has judged (POST /api/hammer/snapshot from the page)."""
    return driver.execute_async_script(
        "const done = arguments[0];"
        "const h = {'Content-Type': 'application/json'};"
        "if (window.access) Object.assign(h, access.headers());"
        "fetch('/api/hammer/snapshot', {method: 'POST', headers: h, body: '{}'})"
        ".then(r => r.json()).then(j => done(j.snapshot ? j.snapshot.hits : []))")


def fill(driver, values):
    for field, value in values.items():
        e = driver.find_element(By.ID, field)
        e.clear()
        if value:
            e.send_keys(value)


def resize(driver, height):
    """The window resized and the page laid out again at the new size (no fixed wait)."""
    driver.set_window_size(1400, height)
    wait(driver, lambda d: abs(d.execute_script("return window.outerHeight") - height) <= 2,
         "the window at %d px" % height)
    driver.execute_script("window.dispatchEvent(new Event('resize'))")


def hammer_tab(driver):
    """The hammer view's tab: the page draws its plots again at their container's width."""
    driver.find_element(By.CSS_SELECTOR, "#tabs button[data-view=hammer]").click()
    wait(driver, lambda d: d.execute_script(
        "const c = document.querySelector('#hm-mag canvas'), p = document.getElementById('hm-mag');"
        "return !c || Math.abs(c.clientWidth - (p.clientWidth - 6)) <= 3"), "the plots redrawn")


def open_hammer_view(bench):
    """Calibrates the emulated board, starts the bench and opens its hammer view in chromium."""
    bench.calibrate()
    bench.serve()
    driver = browser()
    try:
        driver.get(bench.url)
        wait(driver, lambda d: d.execute_script("return document.body.dataset.ready") == "yes",
             "the page to load")
        driver.find_element(By.CSS_SELECTOR, "#tabs button[data-view=hammer]").click()
        wait(driver, lambda d: d.find_element(By.ID, "view-hammer").get_attribute("data-ready") == "yes",
             "the hammer view")
    except BaseException:
        driver.quit()  # the caller never gets it to quit
        raise
    return driver


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build", "host"))
    ap.add_argument("--screenshots", default=None, help="directory for the view's PNG")
    ap.add_argument("--bench-seconds", type=float, default=0,
                    help="instead of the test: a hammer test this long, one page open, and the "
                         "hit-to-screen latency of every hit")
    args = ap.parse_args()
    if args.bench_seconds:
        latency_bench(args)
        return
    t0 = time.monotonic()
    work = tempfile.mkdtemp(prefix="vibid-hammer-browser-")
    bench = HammerBench(os.path.abspath(args.build), work)
    driver = None
    try:
        driver = open_hammer_view(bench)
        # The fields left empty show what empty does: the library's defaults.
        for field, words in (("hm-record", "auto"), ("hm-pretrigger", "auto"), ("hm-fwin", "auto"),
                             ("hm-trigger", "0.1"), ("hm-exp", "none"), ("hm-params", "empty: ")):
            shown = driver.find_element(By.ID, field).get_attribute("placeholder")
            check(words in shown, "%s's placeholder: %r" % (field, shown))
        # A refused start: the session's own message, and nothing runs.
        fill(driver, dict(SETTINGS, **{"hm-pretrigger": "0.8", "hm-record": "1"}))
        driver.find_element(By.ID, "hm-start").click()
        wait(driver, lambda d: "pretrigger" in d.find_element(By.ID, "hm-status").text,
             "the refusal of a pretrigger longer than half the record")
        print("refused: " + driver.find_element(By.ID, "hm-status").text)
        fill(driver, dict(SETTINGS, **{"hm-pretrigger": ""}))
        wait(driver, lambda d: "records/s" in d.find_element(By.ID, "hm-preflight").text,
             "the link budget")
        print("preflight: " + driver.find_element(By.ID, "hm-preflight").text)
        driver.find_element(By.ID, "hm-start").click()
        # Three hits judged on the server (the page may draw them later on a loaded machine).
        wait(driver, lambda d: len(server_hits(d)) >= 3, "three hits judged", timeout=30)
        # A reload mid-test: the hits come back, the test goes on.
        before = len(server_hits(driver))
        driver.refresh()
        wait(driver, lambda d: d.execute_script("return document.body.dataset.ready") == "yes",
             "the page after the reload")
        driver.find_element(By.CSS_SELECTOR, "#tabs button[data-view=hammer]").click()
        wait(driver, lambda d: len(hits(d)) >= before, "the hits after the reload")
        check(js(driver, "return hammer.test.running") is True,
              "the test is not running after the reload: %s" % js(driver, "return [hammer.test, hammer.snap.samples, bench.state]"))
        # The page restores the form from the running test once its snapshot is in: waited for.
        wait(driver, lambda d: d.find_element(By.ID, "hm-form").get_attribute("data-shows"),
             "the form to show the running test's settings")
        sent = js(driver, "return hammer.test.settings")
        check(js(driver, "return hammer.settings()") == sent,
              "the form after the reload: %s; the running test's: %s"
              % (js(driver, "return hammer.settings()"), sent))
        check(driver.find_element(By.ID, "hm-seconds").get_attribute("value") == "24" and
              driver.find_element(By.ID, "hm-record").get_attribute("value") == "",
              "the form after the reload does not show the running test's settings")
        print("reload with %d hits judged: the page shows %d, the test goes on" % (before, len(hits(driver))))
        wait(driver, lambda d: d.execute_script("return document.body.dataset.hammer") == "ended",
             "the test to end", timeout=30)
        h = hits(driver)
        for x in h:
            print("hit %d: %s%s, %s" % (x["index"], x["verdict"], (": " + x["reason"]) if x["reason"] else "",
                                        "accepted" if x["accepted"] else "rejected"))
        check(len(h) >= 6, "%d hits" % len(h))
        check(h[1]["verdict"] == "double hit" and not h[1]["accepted"], "hit 2: %s" % h[1])
        check(h[3]["verdict"] == "clipped" and not h[3]["accepted"] and "clipped" in h[3]["reason"],
              "hit 4: %s" % h[3])
        # The others: accepted exactly when their verdict is ok (the emulator's own rebounds, one
        # hit in ten, and a last hit the end cuts off are rejected with their verdict).
        for x in h:
            if x["index"] not in (2, 4):
                check(x["verdict"] in ("ok", "double hit", "truncated") and
                      x["accepted"] == (x["verdict"] == "ok"), "hit %d: %s" % (x["index"], x))
        ok = [x["index"] for x in h if x["verdict"] == "ok"]
        check(len(ok) >= 5, "%d hits ok" % len(ok))
        rows = driver.find_elements(By.CSS_SELECTOR, "#hm-hits tr[data-index]")
        check("double hit" in rows[1].text and "clipped" in rows[3].text, "the rows: " + rows[1].text)
        # The operator, from the keyboard: the first ok hit rejected, then accepted again.
        a, b = ok[0], ok[1]
        rows[a - 1].click()
        body = driver.find_element(By.TAG_NAME, "body")
        ActionChains(driver).send_keys_to_element(body, "r").perform()
        wait(driver, lambda d: hits(d)[a - 1]["accepted"] is False, "hit %d rejected by the key r" % a)
        ActionChains(driver).send_keys_to_element(body, "j").perform()
        wait(driver, lambda d: d.execute_script("return hammer.sel") == a + 1, "j to move to the next hit")
        ActionChains(driver).send_keys_to_element(body, "k").perform()
        ActionChains(driver).send_keys_to_element(body, "a").perform()
        wait(driver, lambda d: hits(d)[a - 1]["accepted"] is True and hits(d)[a - 1]["decided_by"] == "operator",
             "hit %d accepted by the key a" % a)
        # And with the buttons: the second ok hit rejected, then accepted again.
        driver.find_element(By.CSS_SELECTOR, "#hm-hits tr[data-index='%d'] .hm-reject" % b).click()
        wait(driver, lambda d: hits(d)[b - 1]["accepted"] is False, "hit %d rejected by its button" % b)
        driver.find_element(By.CSS_SELECTOR, "#hm-hits tr[data-index='%d'] .hm-accept" % b).click()
        wait(driver, lambda d: hits(d)[b - 1]["accepted"] is True and hits(d)[b - 1]["decided_by"] == "operator",
             "hit %d accepted by its button" % b)
        accepted = js(driver, "return hammer.snap.accepted")
        check(accepted == sum(1 for x in hits(driver) if x["accepted"]) ==
              sum(1 for x in h if x["verdict"] == "ok"), "%d accepted hits on the page" % accepted)
        driver.find_element(By.ID, "hm-save").click()
        wait(driver, lambda d: d.find_element(By.ID, "hm-save").get_attribute("data-dir"), "the save")
        saved = driver.find_element(By.ID, "hm-save").get_attribute("data-dir")
        wait(driver, lambda d: d.execute_script("return hammer.snap.modes !== null"), "the modes")
        page_modes = js(driver, "return hammer.snap.modes")
        page_warnings = js(driver, "return hammer.snap.warnings")
        shown = json.loads(driver.find_element(By.ID, "hm-warnings").get_attribute("data-warnings"))
        check(shown == page_warnings and len(driver.find_elements(By.CSS_SELECTOR, "#hm-warnings li"))
              == len(page_warnings), "the warnings shown: %s of %s" % (shown, page_warnings))
        table = driver.find_element(By.ID, "hm-modes").text
        latencies = js(driver, "return hammer.latencies")
        # The FRF over the band the modes were identified in (the modes sit in the lowest
        # percent of the 2500 Hz lines); every line on request.
        band = js(driver, "return hammer.snap.band_hz")
        check(band is not None and band[1] >= max(m["freq_hz"] for m in page_modes) and band[1] < 50,
              "the modes' band: %s (modes at %s Hz)" % (band, [m["freq_hz"] for m in page_modes]))
        x_max = float(driver.find_element(By.ID, "hm-mag").get_attribute("data-x-max"))
        check(x_max <= band[1], "the FRF is drawn up to %g Hz, beyond the band %s" % (x_max, band))
        driver.find_element(By.ID, "hm-all-lines").click()
        wait(driver, lambda d: float(d.find_element(By.ID, "hm-mag").get_attribute("data-x-max")) > 2400,
             "every line up to 2500 Hz on request")
        driver.find_element(By.ID, "hm-all-lines").click()
        wait(driver, lambda d: float(d.find_element(By.ID, "hm-mag").get_attribute("data-x-max")) == x_max,
             "the band again")
        print("FRF drawn over the modes' band %.3g-%.3g Hz (up to %.4g Hz; every line up to 2500 Hz "
              "on request)" % (band[0], band[1], x_max))
        if args.screenshots:
            # The whole view (the hit list's notes make it tall): the FRF, the diagram and the
            # modes sit below the hits.
            resize(driver, 1750)
            hammer_tab(driver)
            full = js(driver, "return document.documentElement.scrollHeight")
            resize(driver, min(3200, full + 140))
            driver.save_screenshot(os.path.join(args.screenshots, "bench-hammer.png"))
        # The calibration view's first steps on the saved test: identify (the nominal chain, the
        # saved recording as the modal test), then the observer design.
        shutil.copy(NOMINAL, os.path.join(bench.data, "rig_nominal.json"))
        saved_rel = os.path.relpath(saved, bench.data)
        driver.find_element(By.CSS_SELECTOR, "#tabs button[data-view=calibration]").click()
        for field, value in (("id-nominal", "rig_nominal.json"),
                             ("id-modal", saved_rel + "/recording.csv"),
                             ("id-output", "identified.json")):
            driver.find_element(By.ID, field).clear()
            driver.find_element(By.ID, field).send_keys(value)
        driver.find_element(By.ID, "id-run").click()
        wait(driver, lambda d: d.find_element(By.ID, "id-status").get_attribute("data-parameters"),
             "the identification", timeout=60)
        page_parameters = json.loads(
            driver.find_element(By.ID, "id-status").get_attribute("data-parameters"))
        page_table = driver.find_element(By.ID, "id-table").text
        driver.find_element(By.ID, "design-run").click()
        wait(driver, lambda d: d.find_element(By.ID, "design-summary").get_attribute("data-checksum"),
             "the observer design", timeout=60)
        page_checksum = int(driver.find_element(By.ID, "design-summary").get_attribute("data-checksum"))
        if args.screenshots:
            resize(driver, 1300)
            driver.save_screenshot(os.path.join(args.screenshots, "bench-identify.png"))
        journal = interrupted_test(driver, bench, work)
    finally:
        if driver is not None:
            driver.quit()
        bench.close()
    rec, hit_list = os.path.join(saved, "recording.csv"), os.path.join(saved, "hits.json")
    modes_run = subprocess.run([bench.vibid, "modes", rec, *COLUMNS, *MODES, "--hits", hit_list,
                                "--json"], capture_output=True, text=True, timeout=60)
    check(modes_run.returncode == 0, "vibid modes: " + modes_run.stderr)
    cli = json.loads(modes_run.stdout)
    # The CLI names the file a warning comes from; the page has one test and no file name.
    cli_warnings = [line[len("vibid: warning: "):] for line in modes_run.stderr.splitlines()
                    if line.startswith("vibid: warning: ")]
    cli_warnings = [w[len(rec) + 2:] if w.startswith(rec + ": ") else w for w in cli_warnings]
    check(page_warnings == cli_warnings,
          "warnings: the page %s, vibid modes %s" % (page_warnings, cli_warnings))
    check(len(cli["modes"]) == len(page_modes) and len(page_modes) > 0,
          "modes: page %d, CLI %d" % (len(page_modes), len(cli["modes"])))
    for i, (p, c) in enumerate(zip(page_modes, cli["modes"])):
        for k in ("freq_hz", "omega_rad_s", "zeta", "ratio", "shape", "ci95"):
            check(p.get(k) == c.get(k), "mode %d %s: page %r, vibid modes %r" % (i + 1, k, p.get(k), c.get(k)))
    check(("%.6g" % page_modes[0]["freq_hz"]) in table, "the modes table: " + table)
    frf = os.path.join(work, "frf-cli.csv")
    bench.offline("frf-estimate", rec, *COLUMNS, "--hits", hit_list, "-o", frf)
    with open(frf, "rb") as a, open(os.path.join(saved, "frf.csv"), "rb") as b:
        check(a.read() == b.read(), "frf-estimate's FRF differs from the saved frf.csv")
    print("%d accepted hits: vibid modes gives the page's %d modes exactly (%s Hz); frf-estimate "
          "writes the saved frf.csv byte for byte" % (accepted, len(page_modes),
                                                      ", ".join("%.6g" % m["freq_hz"] for m in page_modes)))
    check(len(latencies) >= 3, "latencies measured: %s" % latencies)
    # The same identification and design through the CLI: the same numbers and the same files.
    report = os.path.join(work, "identify")
    cli_model = os.path.join(work, "identified.json")
    table = bench.offline("identify", "--nominal", NOMINAL, "--modal-test", rec, "-o", cli_model,
                          "--report", report)
    with open(os.path.join(report, "report.json")) as f:
        cli_parameters = json.load(f)["parameters"]
    check(page_parameters == cli_parameters,
          "identify: page %r, vibid identify %r" % (page_parameters, cli_parameters))
    check(page_table.strip() == table.strip(), "validation table: page\n%s\nCLI\n%s" % (page_table, table))
    with open(cli_model) as a, open(os.path.join(bench.data, "identified.json")) as b:
        check(json.load(a) == json.load(b), "the updated model files differ")
    with open(SENSORS) as f:
        force_fs = json.load(f)["channels"]["force1"]["full_scale"]
    bench.offline("dob", "design", cli_model, "--force-fs-n", str(force_fs), "-o",
                  os.path.join(work, "design_cli.json"))
    with open(os.path.join(bench.data, "design.json")) as a, open(os.path.join(work, "design_cli.json")) as b:
        check(json.load(a) == json.load(b), "the observer designs differ (page checksum %d)" % page_checksum)
    print("calibration view: identify gives vibid identify's parameters and table exactly (m1 %.5g kg, "
          "k1 %.5g N/m); the design equals vibid dob design's (checksum %d)"
          % (page_parameters[0]["m_kg"], page_parameters[0]["k_n_per_m"], page_checksum))
    print("hit to screen (3 channels at 5 kHz): median %.1f ms, max %.1f ms over %d FRF updates"
          % (statistics.median(latencies), max(latencies), len(latencies)))
    print(journal)
    print("hammer browser test: passed in %.1f s" % (time.monotonic() - t0))


def interrupted_test(driver, bench, work):
    """A second test: hit 1 rejected while it runs (on disk at once, in hits.json), then Ctrl-C
    to the bench: the test's folder holds the whole test, which frf-estimate reproduces."""
    hammer_tab(driver)
    fill(driver, dict(SETTINGS, **{"hm-seconds": "60"}))
    old = js(driver, "return hammer.test.name")
    old_hits = len(hits(driver))
    driver.find_element(By.ID, "hm-start").click()
    # The page shows the new test at once (Start's answer): its settings in the form, none of
    # the first test's hits, modes or selected hit beside them, and no error (a hit is judged
    # when the next arrives, 1.5 s apart: the new test has none yet).
    wait(driver, lambda d: js(d, "return hammer.test.name") != old, "the second test on screen")
    shown = js(driver, "return [hammer.snap.hits.length, document.getElementById('hm-modes')"
                       ".dataset.modes, document.getElementById('hm-hit-title').textContent,"
                       " document.getElementById('hm-status').className,"
                       " document.getElementById('hm-status').textContent]")
    check(shown[0] == 0 and shown[1] == "[]" and shown[2] == "" and shown[3] != "error",
          "the second test's start shows the first test's state (it had %d hits): %s"
          % (old_hits, shown))
    check(driver.find_element(By.ID, "hm-seconds").get_attribute("value") == "60",
          "the form after the second start: %s s"
          % driver.find_element(By.ID, "hm-seconds").get_attribute("value"))
    # A hit after the first accepted on its verdict (the rig double-hits at hit 2, so that is
    # hit 3 once hit 4 has come: a hit is judged when the next arrives): the test then holds an
    # accepted hit whose FRF the Ctrl-C below must keep.
    def accepted_after_first(d):
        return (d.execute_script("return hammer.test.name") != old
                and any(h["index"] > 1 and h["accepted"] for h in hits(d)))
    wait(driver, accepted_after_first, "an accepted hit after hit 1 in the second test",
         timeout=45)
    folder = js(driver, "return hammer.test.dir")
    driver.find_element(By.CSS_SELECTOR, "#hm-hits tr[data-index='1'] .hm-reject").click()
    wait(driver, lambda d: hits(d)[0]["accepted"] is False, "hit 1 rejected by its button")

    def journaled():
        try:
            with open(os.path.join(folder, "hits.json")) as f:
                first = json.load(f)["hits"][0]
        except (OSError, ValueError, IndexError):
            return False
        return first["accepted"] is False and first["decided_by"] == "operator"
    wait(driver, lambda d: journaled(), "the choice in hits.json while the test runs")
    check(js(driver, "return hammer.test.running") is True, "the second test ended early")
    bench.interrupt()
    for f in ("recording.csv", "hits.json", "live.csv", "frf.csv", "frf.uff"):
        check(os.path.isfile(os.path.join(folder, f)), "after Ctrl-C the test has no " + f)
    with open(os.path.join(folder, "hits.json")) as f:
        kept = json.load(f)["hits"]
    check(kept[0]["accepted"] is False and kept[0]["decided_by"] == "operator",
          "hit 1 after Ctrl-C: %s" % kept[0])
    accepted = sum(1 for h in kept if h.get("accepted"))
    check(accepted >= 1, "after Ctrl-C no kept hit is accepted: %s" % kept)
    frf = os.path.join(work, "frf-interrupted.csv")
    bench.offline("frf-estimate", os.path.join(folder, "recording.csv"), *COLUMNS, "--hits",
                  os.path.join(folder, "hits.json"), "-o", frf)
    with open(frf, "rb") as a, open(os.path.join(folder, "frf.csv"), "rb") as b:
        check(a.read() == b.read(), "after Ctrl-C: frf-estimate's FRF differs from the kept frf.csv")
    return ("Ctrl-C mid-test (%d hits, %d accepted, hit 1 rejected by the operator): the folder "
            "holds recording.csv, hits.json with the operator's choice and the FRF frf-estimate "
            "gives on them" % (len(kept), accepted))


def latency_bench(args):
    """Every hit of one long test: the block completing it arriving on the host (the server's
    stamp) to the FRF plot's draw hook in the page (performance.timeOrigin + now())."""
    work = tempfile.mkdtemp(prefix="vibid-hammer-latency-")
    bench = HammerBench(os.path.abspath(args.build), work)
    driver = None
    try:
        driver = open_hammer_view(bench)
        fill(driver, dict(SETTINGS, **{"hm-seconds": "%g" % args.bench_seconds}))
        cpu0 = bench.cpu_s()
        driver.find_element(By.ID, "hm-start").click()
        wait(driver, lambda d: d.execute_script("return document.body.dataset.hammer") == "ended",
             "the test to end", timeout=args.bench_seconds + 30)
        cpu = 100.0 * (bench.cpu_s() - cpu0) / args.bench_seconds
        latencies = js(driver, "return hammer.latencies")
        n = len(hits(driver))
        timing = js(driver, "return hammer.snap.timing_ms")
    finally:
        if driver is not None:
            driver.quit()
        bench.close()
    print("hit to screen (3 channels at 5 kHz, %d hits, %d drawn): median %.1f ms, max %.1f ms; "
          "the last update took %.1f ms (modes %.1f ms); server CPU %.1f %% of one core"
          % (n, len(latencies), statistics.median(latencies), max(latencies), timing["update"],
             timing["modes"], cpu))


if __name__ == "__main__":
    main()
