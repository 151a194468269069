#!/usr/bin/python3
"""Six and eight tabs of one bench in one browser (headless chromium) against vibid-emu.

Chromium opens at most six HTTP/1.1 connections to a host: a live stream held by each tab would
leave none for the API. The tabs share one stream (a leader tab reads it, the others follow on a
BroadcastChannel), so:
  1. six tabs load, each shows the live link; exactly one of them holds a stream;
  2. in every one of the six, GET /api/state answers within a second (a bound against a hang);
  3. an acquisition started from the first tab draws blocks on the sixth tab's scope;
  4. Stop pressed in the fourth tab ends it, and every tab shows it stopped;
  5. tabs seven and eight load and go live as well, the API still answers in each;
  6. the leading tab closed, another takes the stream: a new acquisition reaches the others.
Prints the slowest /api/state and the Stop's time.

  /usr/bin/python3 host/bench/tabs_browser_test.py --build build/host
"""
import argparse
import os
import shutil
import sys
import tempfile
import time

from selenium.webdriver.common.by import By

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from browser_test import Bench, browser, check, wait  # noqa: E402

# A bound against a hang, not a speed figure: a page that waits a second for its state is frozen.
STATE_BOUND_MS = 1000


def state_ms(driver):
    """GET /api/state from the page (the token it keeps): how long the answer took, in ms."""
    r = driver.execute_async_script(
        "const done = arguments[0]; const t0 = performance.now();"
        "fetch('/api/state', {headers: access.headers(), cache: 'no-store'})"
        ".then(r => done([r.status, performance.now() - t0])).catch(e => done([String(e), 0]))")
    check(r[0] == 200, "GET /api/state from a tab: %s" % r[0])
    return r[1]


def ready(driver, name):
    wait(driver, lambda d: d.execute_script("return document.body.dataset.ready") == "yes",
         "%s: the page to load ({message})" % name)
    wait(driver, lambda d: d.find_element(By.ID, "link-state").text == "live",
         "%s: the live channel" % name)


def role(driver):
    return driver.execute_script("return bench.live.role")


def blocks(driver):
    return driver.execute_script("return bench.blocks")


def start(driver, seconds):
    status = driver.execute_async_script(
        "const done = arguments[1]; api('/api/acquire', {sample_period_us: 1000, "
        "channels: ['force1', 'acc1'], seconds: arguments[0]}).then(() => done('ok'))"
        ".catch(e => done(e.message))", seconds)
    check(status == "ok", "the acquisition from the page: %s" % status)


def running(driver):
    return driver.execute_script("return document.body.dataset.running")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join("build", "host"))
    args = ap.parse_args()
    t0 = time.monotonic()
    work = tempfile.mkdtemp(prefix="vibid-tabs-")
    bench = Bench(os.path.abspath(args.build), work)
    bench.serve()
    driver = browser()
    try:
        tabs = []
        for i in range(6):
            if i:
                driver.switch_to.new_window("tab")
            driver.get(bench.url)
            ready(driver, "tab %d" % (i + 1))
            tabs.append(driver.current_window_handle)
        roles = []
        slowest = 0.0
        for i, tab in enumerate(tabs):
            driver.switch_to.window(tab)
            roles.append(role(driver))
            slowest = max(slowest, max(state_ms(driver) for _ in range(3)))
        check(roles.count("leader") == 1 and roles.count("follower") == 5,
              "six tabs: one leader reads the stream, five follow: %s" % roles)
        check(slowest < STATE_BOUND_MS, "six tabs: /api/state took %.0f ms" % slowest)
        print("six tabs: roles %s, slowest /api/state %.0f ms" % (roles, slowest))

        # An acquisition from the first tab reaches the sixth tab's scope.
        driver.switch_to.window(tabs[5])
        before = blocks(driver)
        driver.switch_to.window(tabs[0])
        start(driver, 60)
        driver.switch_to.window(tabs[5])
        wait(driver, lambda d: blocks(d) > before + 3, "blocks on the sixth tab's scope")
        wait(driver, lambda d: running(d) == "yes", "the sixth tab to show the acquisition")

        # Stop from the fourth tab's button.
        driver.switch_to.window(tabs[3])
        wait(driver, lambda d: running(d) == "yes", "the fourth tab to show the acquisition")
        pressed = time.monotonic()
        driver.find_element(By.ID, "stop").click()
        wait(driver, lambda d: running(d) == "no", "Stop in the fourth tab to end it")
        stop_ms = (time.monotonic() - pressed) * 1000
        for i, tab in enumerate(tabs):
            driver.switch_to.window(tab)
            wait(driver, lambda d: running(d) == "no", "tab %d to show it stopped" % (i + 1))
        print("Stop from the fourth of six tabs: %.0f ms to the page's stopped state" % stop_ms)

        # Tabs seven and eight.
        for i in (6, 7):
            driver.switch_to.new_window("tab")
            driver.get(bench.url)
            ready(driver, "tab %d" % (i + 1))
            tabs.append(driver.current_window_handle)
        slowest = 0.0
        roles = []
        for tab in tabs:
            driver.switch_to.window(tab)
            roles.append(role(driver))
            slowest = max(slowest, state_ms(driver))
        check(roles.count("leader") == 1, "eight tabs: one leader: %s" % roles)
        check(slowest < STATE_BOUND_MS, "eight tabs: /api/state took %.0f ms" % slowest)
        print("eight tabs: slowest /api/state %.0f ms" % slowest)

        # The leader closes: another tab takes the stream, the others follow it.
        leader = tabs[roles.index("leader")]
        driver.switch_to.window(leader)
        driver.close()
        tabs.remove(leader)
        driver.switch_to.window(tabs[0])
        wait(driver, lambda d: any(
            (d.switch_to.window(t) or True) and role(d) == "leader" for t in tabs),
             "another tab to lead after the leader closed")
        last = tabs[-1]
        driver.switch_to.window(last)
        before = blocks(driver)
        start(driver, 2)
        wait(driver, lambda d: blocks(d) > before + 3, "blocks after the leader closed")
        wait(driver, lambda d: running(d) == "no", "the short acquisition to end")
        print("tabs browser test: passed in %.0f s" % (time.monotonic() - t0))
    finally:
        driver.quit()
        bench.close()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
