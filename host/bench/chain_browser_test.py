#!/usr/bin/python3
"""The bench on a chain of three (or four) masses, in headless chromium against vibid-emu.

The board is calibrated for the rig's chain (its record holds the masses' model and each sensor on
its mass, as the rig file's response_inputs place them; the load cells on the hammer's mass). The
hammer view runs a test with every response input the rig uses and the hammer point on the hammered
mass: every hit judged, the chain's modes at the rig truth's frequencies. The calibration view then
identifies the chain from the saved test: the bench takes each mass's response from the board's
record (and the driving point from its load cell's mass), and `vibid identify` with those named
gives the same parameters, within 7 % of the truth. The emulator runs at --speed 8 (hits every 12 s of rig time: the slowest mode rings down
between them).

  /usr/bin/python3 host/bench/chain_browser_test.py --build build/host [--rig RIG.json]
                                                    [--screenshots DIR]
"""
import argparse
import json
import os
import re
import shutil
import struct
import subprocess
import tempfile
import time

from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select

import sys
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from browser_test import ROOT, Bench, browser, check, wait  # noqa: E402

CHAIN3 = os.path.join(ROOT, "host", "emulator", "rigs", "chain3.json")
UNITS = {"acc": "m_s2", "x": "m"}


def column(name):
    return name + "_" + UNITS[name.rstrip("12")]


class ChainBench(Bench):
    """An emulated board with the rig, calibrated for its chain."""

    def __init__(self, build, work, rig_path):
        with open(rig_path) as f:
            self.rig = json.load(f)
        self.n = len(self.rig["masses_kg"])
        # The response input on each mass, in mass order (rig file: input -> mass from 1).
        on = {mass: name for name, mass in self.rig["response_inputs"].items()}
        self.inputs = [on[m] for m in range(1, self.n + 1)]
        self.hammer = self.rig.get("hammer_mass", self.n)
        self.vibid = os.path.join(build, "host", "cli", "vibid")
        emu = os.path.join(build, "host", "emulator", "vibid-emu")
        self.work = work
        self.emu = subprocess.Popen([emu, "--port", "0", "--speed", "8", "--seed", "7", "--rig",
                                     rig_path], stdout=subprocess.PIPE,
                                    stderr=subprocess.DEVNULL, text=True)
        port = re.search(r"127\.0\.0\.1:(\d+)", self.emu.stdout.readline())
        check(port is not None, "no port in the emulator's banner")
        self.device = "usbip://127.0.0.1:" + port.group(1)
        self.server = None
        truth = subprocess.run([emu, "--rig", rig_path, "--print-truth"], capture_output=True,
                               text=True, check=True).stdout
        self.truth = os.path.join(work, "truth.json")
        with open(self.truth, "w") as f:
            f.write(truth)
        # The nominal model: the truth's springs 5 % stiffer, as a datasheet would give them.
        nominal = json.loads(truth)
        nominal["springs"] = [k * 1.05 for k in nominal["springs"]]
        self.nominal = os.path.join(work, "nominal.json")
        with open(self.nominal, "w") as f:
            json.dump(nominal, f)

    def offline(self, *args):
        r = subprocess.run([self.vibid, *args], capture_output=True, text=True, timeout=60)
        check(r.returncode == 0, "vibid %s: %s" % (" ".join(args), r.stderr))
        return r.stdout

    def calibrate(self):
        with open(os.path.join(ROOT, "examples", "sensors.json")) as f:
            sensors = json.load(f)
        for name, ch in sensors["channels"].items():
            if name in self.inputs:
                ch["dof"] = self.inputs.index(name) + 1
            elif name.startswith("force"):
                ch["dof"] = self.hammer
            else:
                ch.pop("dof", None)
        self.sensors = os.path.join(self.work, "sensors.json")
        with open(self.sensors, "w") as f:
            json.dump(sensors, f)
        design = os.path.join(self.work, "design.json")
        encoder = self.inputs[self.hammer - 1].startswith("x")
        self.cli("dob", "design", self.nominal, "--sensors", self.sensors, "--fs-hz", "5000",
                 "--input-dof", str(self.hammer), "--output-dof", str(self.hammer), "--sensor",
                 "disp" if encoder else "acc", "-o", design)
        self.cli("cal", "upload", self.nominal, "--design", design, "--sensors", self.sensors)
        self.cli("cal", "commit")
        shown = json.loads(self.cli("cal", "show", "--json"))
        check(len(shown["M"]) == self.n, "the board's record holds %d masses" % len(shown["M"]))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build", "host"))
    ap.add_argument("--rig", default=CHAIN3, help="a rig file of a chain (3 or 4 masses)")
    ap.add_argument("--screenshots", default=None, help="directory for the views' PNGs")
    args = ap.parse_args()
    t0 = time.monotonic()
    work = tempfile.mkdtemp(prefix="vibid-chain-browser-")
    bench = ChainBench(os.path.abspath(args.build), work, args.rig)
    driver = None
    try:
        bench.calibrate()
        bench.serve()
        driver = browser()
        driver.get(bench.url)
        wait(driver, lambda d: d.execute_script("return document.body.dataset.ready") == "yes",
             "the page to load")
        driver.find_element(By.CSS_SELECTOR, "#tabs button[data-view=hammer]").click()
        wait(driver, lambda d: d.find_element(By.ID, "view-hammer").get_attribute("data-ready") == "yes",
             "the hammer view")
        # Every response input the rig uses, the hammer point on the hammered mass; 2.5 kHz (the
        # chain's modes lie below 20 Hz, and four responses' 14-byte records fit the link there).
        for box in driver.find_elements(By.CSS_SELECTOR, "#hm-responses input"):
            if (box.get_attribute("value") in bench.inputs) != box.is_selected():
                box.click()
        Select(driver.find_element(By.ID, "hm-rate")).select_by_value("400")
        Select(driver.find_element(By.ID, "hm-point")).select_by_visible_text(
            bench.inputs[bench.hammer - 1])
        for field, value in (("hm-seconds", "60"), ("hm-exp", "0.1"),
                             ("hm-params", "%d, 100, 12, 0" % bench.hammer)):
            e = driver.find_element(By.ID, field)
            e.clear()
            e.send_keys(value)
        wait(driver, lambda d: "records/s" in d.find_element(By.ID, "hm-preflight").text,
             "the link budget")
        driver.find_element(By.ID, "hm-start").click()
        wait(driver, lambda d: d.execute_script("return document.body.dataset.hammer") == "running",
             "the test to run: {message}")
        started = time.monotonic()
        wait(driver, lambda d: d.execute_script("return document.body.dataset.hammer") == "ended",
             "the test to end: {message}", timeout=150)
        print("the test of 60 s (rig time) ran %.1f s" % (time.monotonic() - started))
        hits = driver.execute_script("return hammer.snap.hits")
        accepted = [h for h in hits if h["accepted"]]
        print("%d hits, %d accepted: %s" % (len(hits), len(accepted),
                                            ", ".join(h["verdict"] for h in hits)))
        check(len(accepted) >= 4, "%d accepted hits" % len(accepted))
        wait(driver, lambda d: d.execute_script("return hammer.snap.modes !== null"), "the modes")
        modes = driver.execute_script("return hammer.snap.modes")
        truth_modes = json.loads(subprocess.run([bench.vibid, "modal", bench.truth, "--json"],
                                                capture_output=True, text=True,
                                                check=True).stdout)["modes"]
        freqs = [m["freq_hz"] for m in modes]
        truth_hz = [m["freq_hz"] for m in truth_modes]
        print("modes on the page: %s Hz; truth %s Hz" % (
            ", ".join("%.4f" % f for f in freqs), ", ".join("%.4f" % f for f in truth_hz)))
        check(len(freqs) == bench.n, "%d modes for %d masses" % (len(freqs), bench.n))
        for f, t in zip(freqs, truth_hz):
            check(abs(f - t) <= 0.01 * t, "mode at %.4f Hz, truth %.4f Hz" % (f, t))
        # The shape column: each response over the driving point's, one entry per mass, as the
        # library gives it (never a ratio of two of them, never "nan").
        rows = driver.find_elements(By.CSS_SELECTOR, "#hm-modes tr")
        check(rows[0].text.endswith("shape a_k/a_dp (95 %)"), "the modes table's head: " + rows[0].text)
        for row, m in zip(rows[1:], modes):
            shape = row.find_elements(By.TAG_NAME, "td")[-1].text
            check(len(shape.split("; ")) == bench.n and "nan" not in shape,
                  "mode shape shown as %r for %s" % (shape, m.get("shape_ratio")))
        print("shapes on the page: " + " | ".join(
            r.find_elements(By.TAG_NAME, "td")[-1].text for r in rows[1:]))
        driver.find_element(By.ID, "hm-save").click()
        wait(driver, lambda d: d.find_element(By.ID, "hm-save").get_attribute("data-dir"), "the save")
        saved = driver.find_element(By.ID, "hm-save").get_attribute("data-dir")
        if args.screenshots:
            driver.set_window_size(1400, 2000)
            driver.execute_script("window.dispatchEvent(new Event('resize'))")
            driver.save_screenshot(os.path.join(args.screenshots, "bench-hammer-chain.png"))
        # The calibration view: identify from the saved test.
        shutil.copy(bench.nominal, os.path.join(bench.data, "nominal.json"))
        driver.find_element(By.CSS_SELECTOR, "#tabs button[data-view=calibration]").click()
        for field, value in (("id-nominal", "nominal.json"),
                             ("id-modal", os.path.relpath(saved, bench.data) + "/recording.csv"),
                             ("id-exp", "0.1"), ("id-output", "identified.json")):
            driver.find_element(By.ID, field).clear()
            driver.find_element(By.ID, field).send_keys(value)
        driver.find_element(By.ID, "id-run").click()
        wait(driver, lambda d: "identifying" not in d.find_element(By.ID, "id-run-status").text,
             "the identification", timeout=90)
        check(driver.find_element(By.ID, "id-status").get_attribute("data-parameters"),
              "identify: " + driver.find_element(By.ID, "id-run-status").text)
        page = json.loads(driver.find_element(By.ID, "id-status").get_attribute("data-parameters"))
        page_table = driver.find_element(By.ID, "id-table").text
        # The observer design from the updated model: on the hammer's mass, fed by its sensor.
        driver.find_element(By.ID, "design-run").click()
        wait(driver, lambda d: d.find_element(By.ID, "design-summary").get_attribute("data-checksum"),
             "the observer design", timeout=60)
        design_summary = driver.find_element(By.ID, "design-summary").text
        print(design_summary.splitlines()[2])
        if args.screenshots:
            driver.set_window_size(1400, 1300)
            driver.save_screenshot(os.path.join(args.screenshots, "bench-identify-chain.png"))
    finally:
        if driver is not None:
            driver.quit()
        bench.close()
    # The same identification through the CLI, each mass's response named as the board's record
    # places it.
    report = os.path.join(work, "identify")
    responses = ",".join(column(i) for i in bench.inputs)
    r = subprocess.run([bench.vibid, "identify", "--nominal", bench.nominal, "--modal-test",
                        os.path.join(saved, "recording.csv"), "--modal-responses", responses,
                        "--driving-point", column(bench.inputs[bench.hammer - 1]),
                        "--exp-window", "0.1", "-o", os.path.join(work, "identified.json"), "--report", report],
                       capture_output=True, text=True, timeout=120)
    check(r.returncode == 0, "vibid identify: " + r.stderr)
    with open(os.path.join(report, "report.json")) as f:
        cli = json.load(f)["parameters"]
    check(page == cli, "identify: page %r, vibid identify %r" % (page, cli))
    check(page_table.strip() == r.stdout.strip(),
          "validation table: page\n%s\nCLI\n%s" % (page_table, r.stdout))
    check(len(page) == bench.n, "%d parameters rows for %d masses" % (len(page), bench.n))
    with open(bench.truth) as f:
        truth = json.load(f)
    # One hammer test of four or five hits: the one-test chain fit, its masses and springs low by
    # a few percent from the rig's friction (the caution says so); measured within 2.6 % of the
    # truth on chain3.json, 5.5 % on chain4.json.
    for i, p in enumerate(page):
        print("m%d %.4g kg (truth %.4g), k%d %.5g N/m (truth %.5g)" % (
            i + 1, p["m_kg"], truth["masses"][i], i + 1, p["k_n_per_m"], truth["springs"][i]))
        check(abs(p["m_kg"] - truth["masses"][i]) <= 0.07 * truth["masses"][i],
              "mass %d: %g kg, truth %g" % (i + 1, p["m_kg"], truth["masses"][i]))
        check(abs(p["k_n_per_m"] - truth["springs"][i]) <= 0.07 * truth["springs"][i],
              "spring %d: %g N/m, truth %g" % (i + 1, p["k_n_per_m"], truth["springs"][i]))
    for line in page_table.splitlines():
        if line.startswith(("CAUTION", "FLAGGED")):
            print(line)
    # The same design through the CLI: the hammer's mass, its sensor at the record's (float32)
    # full scale, the load cell's 500 N, the bench's 5 kHz.
    point = bench.inputs[bench.hammer - 1]
    with open(bench.sensors) as f:
        fs = struct.unpack("<f", struct.pack("<f", json.load(f)["channels"][point]["full_scale"]))[0]
    cli_design = os.path.join(work, "design_cli.json")
    bench.offline("dob", "design", os.path.join(bench.data, "identified.json"), "--force-fs-n", "500",
                  "--input-dof", str(bench.hammer), "--output-dof", str(bench.hammer), "--sensor",
                  "disp" if point.startswith("x") else "acc", "--sensor-fs", repr(fs), "-o",
                  cli_design)
    with open(cli_design) as a, open(os.path.join(bench.data, "design.json")) as b:
        check(json.load(a) == json.load(b), "the observer designs differ")
    check("@m%d" % bench.hammer in design_summary, "the design's inputs: " + design_summary)
    print("observer design on the page equals vibid dob design --input-dof %d --sensor %s"
          % (bench.hammer, "disp" if point.startswith("x") else "acc"))
    print("identify on the page equals vibid identify --modal-responses %s --driving-point %s"
          % (responses, column(bench.inputs[bench.hammer - 1])))
    print("chain browser test (%d masses): passed in %.1f s" % (bench.n, time.monotonic() - t0))


if __name__ == "__main__":
    main()
