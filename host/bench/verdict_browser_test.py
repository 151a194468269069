#!/usr/bin/python3
"""The verdict in the bench's calibration view, in headless chromium against vibid-emu: a flagged
identification is shown in red and not written; its model reaches the board only on the explicit
accept, at every step.

The hammer tests are simulated with scipy (scripts/golden/chain_hammer_scipy.py, independent of
vibid): the chain m = (1.2, 0.8) kg, k = (3000, 2000) N/m, c = (0.9, 0.8) N*s/m, hammer on mass 2;
mass 1's test stood on a spring of 4400 N/m where the nominal model says 3300 (a slip: the mass
test on another spring than the chain's), so its mass comes out 25 % light and the chain built
on it fits its own test worse than the nominal model: flagged.

Checked: (1) Identify shows "Verdict: FLAGGED" in the red box with the reason, says the model was
not written, and no file is there; (2) with "write it even if flagged" ticked it is written,
carrying the verdict; (3) the design refuses it until its accept box is ticked; (4) "Show the
changes" shows the red verdict and keeps Upload disabled until the accept box is ticked; the
server itself refuses the upload without the accept (400 naming the reasons), and after an
accepted upload refuses the commit without it; (5) with the box ticked, upload and commit go
through and the board holds the record. A screenshot of the view with the flagged verdict.

  /usr/bin/python3 host/bench/verdict_browser_test.py --build build/host [--screenshots DIR]
"""
import argparse
import json
import os
import shutil
import sys
import tempfile
import time

from selenium.webdriver.common.by import By

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from browser_test import ROOT, Bench, browser, check, wait  # noqa: E402

sys.path.insert(0, os.path.join(ROOT, "scripts", "golden"))
import chain_hammer_scipy as sim  # noqa: E402

NOMINAL = {"topology": "chain", "masses": [1.296, 0.864], "springs": [3300, 2200]}


def write_tests(folder):
    sim.write_hammer_test(os.path.join(folder, "modal.csv"), [1.2, 0.8], [3000, 2000], [0.9, 0.8],
                          hammer=2, seed=7)
    for name, m, k, column, seed in (("mass1.csv", 1.2, 4400, "acc1_m_s2", 12),
                                     ("mass2.csv", 0.8, 2200, "acc2_m_s2", 13)):
        sim.write_hammer_test(os.path.join(folder, name), [m], [k],
                              [2 * 0.02 * (k * m) ** 0.5], responses=[column], seed=seed)
    with open(os.path.join(folder, "nominal.json"), "w") as f:
        json.dump(NOMINAL, f)


def api(driver, path, body):
    """POST from the page itself (its token), as the page's own api() would: [status, json]."""
    return driver.execute_async_script(
        "const done = arguments[arguments.length - 1];"
        "fetch(arguments[0], {method: 'POST', headers: access.headers("
        "{'Content-Type': 'application/json'}), body: JSON.stringify(arguments[1])})"
        ".then(r => r.json().then(j => done([r.status, j])));", path, body)


def text(driver, element_id):
    return driver.find_element(By.ID, element_id).text


def click(driver, element_id):
    driver.find_element(By.ID, element_id).click()


def fill(driver, element_id, value):
    e = driver.find_element(By.ID, element_id)
    e.clear()
    e.send_keys(value)


def run(args, work, shots):
    bench = Bench(os.path.abspath(args.build), work)
    driver = None
    try:
        bench.calibrate()  # examples/rig_nominal.json and the sensors: the board's record
        bench.serve()
        write_tests(bench.data)
        driver = browser()
        driver.get(bench.url)
        wait(driver, lambda d: d.find_element(By.TAG_NAME, "body").get_attribute("data-ready")
             == "yes", "the page")
        driver.find_element(By.CSS_SELECTOR, "#tabs button[data-view=calibration]").click()

        # (1) Flagged: shown in red, not written.
        fill(driver, "id-nominal", "nominal.json")
        fill(driver, "id-mass", "1=mass1.csv, 2=mass2.csv")
        fill(driver, "id-modal", "modal.csv")
        fill(driver, "id-exp", "0.01")
        fill(driver, "id-output", "flagged.json")
        click(driver, "id-run")
        wait(driver, lambda d: d.find_element(By.ID, "id-verdict").get_attribute("data-level"),
             "the identification's verdict", timeout=120)
        box = driver.find_element(By.ID, "id-verdict")
        check(box.get_attribute("data-level") == "flagged", "verdict: " + box.text)
        check("verdict-flagged" in box.get_attribute("class"), "the box's colour: " +
              box.get_attribute("class"))
        check(box.value_of_css_property("border-top-color") in
              ("rgba(198, 40, 40, 1)", "rgb(198, 40, 40)"),
              "the box is red: " + box.value_of_css_property("border-top-color"))
        check("fits its own test worse than the nominal model" in box.text, box.text)
        check("not written" in box.text, box.text)
        check(text(driver, "id-run-status") == "identified: FLAGGED",
              "status: " + text(driver, "id-run-status"))
        check(not os.path.exists(os.path.join(bench.data, "flagged.json")),
              "a flagged model was written without the accept")
        driver.save_screenshot(os.path.join(shots, "bench-verdict-flagged.png"))

        # (2) Written on the accept, carrying its verdict.
        click(driver, "id-accept")
        click(driver, "id-run")
        wait(driver, lambda d: "wrote flagged.json" in text(d, "id-status"),
             "the accepted flagged model written", timeout=120)
        with open(os.path.join(bench.data, "flagged.json")) as f:
            written = json.load(f)
        check(written["verdict"]["level"] == "flagged", "the file's verdict: %s" % written)

        # (3) The design refuses it until its own accept is ticked.
        fill(driver, "design-model", "flagged.json")
        fill(driver, "design-output", "design.json")
        click(driver, "design-run")
        wait(driver, lambda d: d.find_element(By.ID, "design-status").get_attribute("class")
             == "error", "the design's refusal")
        said = text(driver, "design-status")
        check("is flagged" in said and "accept" in said, "the design's refusal: " + said)
        click(driver, "design-accept")
        click(driver, "design-run")
        wait(driver, lambda d: text(d, "design-status") == "designed", "the accepted design")
        check("model FLAGGED" in text(driver, "design-summary"), text(driver, "design-summary"))

        # (4) The upload: red verdict, Upload disabled until the accept is ticked.
        for field, value in (("cal-model", "flagged.json"), ("cal-design", "design.json")):
            fill(driver, field, value)
        click(driver, "cal-preview")
        wait(driver, lambda d: d.find_element(By.ID, "cal-verdict").get_attribute("data-level"),
             "the upload's verdict")
        cal = driver.find_element(By.ID, "cal-verdict")
        check(cal.get_attribute("data-level") == "flagged" and cal.is_displayed(), cal.text)
        check("fits its own test worse" in cal.text, cal.text)
        upload = driver.find_element(By.ID, "cal-upload")
        check(not upload.is_enabled(), "Upload is offered for a flagged model without the accept")
        check(driver.find_element(By.ID, "cal-accept").is_displayed(), "no accept box")
        files = {"model": "flagged.json", "design": "design.json"}
        status, answer = api(driver, "/api/cal/upload", files)
        check(status == 400 and "is flagged" in answer["error"] and "accept" in answer["error"],
              "the server's answer to an unaccepted upload: %d %s" % (status, answer))
        driver.save_screenshot(os.path.join(shots, "bench-verdict-upload.png"))

        # (5) Accepted: staged and committed; the server wants the accept for the commit too.
        click(driver, "cal-accept")
        check(upload.is_enabled(), "Upload stays disabled after the accept")
        click(driver, "cal-upload")
        wait(driver, lambda d: "staged" in text(d, "cal-status"), "the accepted upload")
        check("FLAGGED" in text(driver, "cal-status"), text(driver, "cal-status"))
        status, answer = api(driver, "/api/cal/commit", {})
        check(status == 400 and "is flagged" in answer.get("error", ""),
              "an unaccepted commit of the flagged staged model: %d %s" % (status, answer))
        click(driver, "cal-commit")
        wait(driver, lambda d: d.find_element(By.ID, "cal-status").get_attribute(
            "data-committed"), "the accepted commit")
        check("model FLAGGED" in text(driver, "cal-status"), text(driver, "cal-status"))
        board = driver.execute_async_script(
            "const done = arguments[arguments.length - 1];"
            "fetch('/api/board', {headers: access.headers()}).then(r => r.json()).then(done);")
        check(board["calibration"].get("label") == "flagged",
              "the board's record: %s" % board["calibration"])
        print("verdict in the bench: flagged shown red, not written, not designed, uploaded or "
              "committed without the accept; accepted, on the board")
    finally:
        if driver is not None:
            driver.quit()
        bench.close()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build", "host"))
    ap.add_argument("--screenshots", default=None, help="directory for the PNGs")
    args = ap.parse_args()
    t0 = time.monotonic()
    work = tempfile.mkdtemp(prefix="vibid-bench-verdict-")
    try:
        run(args, work, args.screenshots or work)
    finally:
        if not args.screenshots:
            shutil.rmtree(work, ignore_errors=True)
    print("verdict browser test: %.1f s" % (time.monotonic() - t0))


if __name__ == "__main__":
    main()
