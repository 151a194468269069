#!/usr/bin/python3
"""Two benches in one browser, and a third local server beside them (headless chromium).

Starts two emulators (paced at wall-clock speed) and a `vibid bench` on each, and a plain HTTP
server on a third port of 127.0.0.1 that records what it receives. In one browser:
  1. bench A's page loads; the token leaves the address bar; no cookie is set;
  2. bench B's page loads in a second tab;
  3. back in A, the page still answers (the board read through the API) and its live channel
     still streams: a short acquisition started from A's page draws blocks on A's scope;
  4. the same in B; then a reload of each keeps the token (the tab's sessionStorage) and both
     work again;
  5. the third server's page is loaded in a third tab: it received no Cookie header and no token.
Saves a screenshot of each bench's page (with --screenshots DIR, there).

  /usr/bin/python3 host/bench/two_benches_browser_test.py --build build/host [--screenshots DIR]
"""
import argparse
import http.server
import os
import shutil
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from browser_test import Bench, browser, check, wait  # noqa: E402


class Recorder(http.server.BaseHTTPRequestHandler):
    """A plain local server: what a browser sends it is what any local server would receive."""
    seen = []

    def do_GET(self):  # noqa: N802 (the handler's name is http.server's)
        Recorder.seen.append((self.path, dict(self.headers)))
        body = b"<!doctype html><title>another local server</title><p>hello</p>"
        self.send_response(200)
        self.send_header("Content-Type", "text/html")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *args):
        pass


def api_status(driver, path):
    """GET `path` from the page with the token it keeps; the HTTP status."""
    return driver.execute_async_script(
        "const done = arguments[1]; fetch(arguments[0], {headers: access.headers()})"
        ".then(r => done(r.status)).catch(e => done(String(e)))", path)


def live_blocks(driver, bench, name):
    """A short acquisition from the page: its blocks must reach the page's scope."""
    before = driver.execute_script("return bench.blocks")
    status = driver.execute_async_script(
        "const done = arguments[0]; api('/api/acquire', {sample_period_us: 1000, "
        "channels: ['force1', 'acc1'], seconds: 1}).then(() => done('ok'))"
        ".catch(e => done(e.message))")
    check(status == "ok", "%s: the acquisition from the page: %s" % (name, status))
    wait(driver, lambda d: d.execute_script("return bench.blocks") > before + 3,
         "%s: blocks on the live channel" % name)
    wait(driver, lambda d: d.execute_script("return document.body.dataset.running") == "no",
         "%s: the acquisition to end" % name)
    check(driver.find_element("id", "link-state").text == "live",
          "%s: link state %r" % (name, driver.find_element("id", "link-state").text))


def ready(driver, name):
    wait(driver, lambda d: d.execute_script("return document.body.dataset.ready") == "yes",
         "%s: the page to load ({message})" % name)
    wait(driver, lambda d: d.find_element("id", "link-state").text == "live",
         "%s: the live channel" % name)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join("build", "host"))
    ap.add_argument("--screenshots", default=None)
    args = ap.parse_args()
    t0 = time.monotonic()
    work = tempfile.mkdtemp(prefix="vibid-two-benches-")
    shots = args.screenshots or work
    recorder = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Recorder)
    threading.Thread(target=recorder.serve_forever, daemon=True).start()
    other_url = "http://127.0.0.1:%d/page" % recorder.server_address[1]
    benches = []
    for name in ("a", "b"):
        os.makedirs(os.path.join(work, name))
        benches.append(Bench(os.path.abspath(args.build), os.path.join(work, name)))
        benches[-1].serve()
    a, b = benches
    check(a.url != b.url and a.url.split("?token=")[1] != b.url.split("?token=")[1],
          "two benches, two URLs and tokens: %s %s" % (a.url, b.url))
    driver = browser()
    try:
        driver.get(a.url)
        ready(driver, "bench A")
        tab_a = driver.current_window_handle
        check("token" not in driver.current_url, "A's address bar: " + driver.current_url)
        check(driver.execute_script("return document.cookie") == "", "A set a cookie")
        driver.switch_to.new_window("tab")
        tab_b = driver.current_window_handle
        driver.get(b.url)
        ready(driver, "bench B")
        check("token" not in driver.current_url, "B's address bar: " + driver.current_url)
        check(driver.get_cookies() == [], "cookies after B: %s" % driver.get_cookies())

        driver.switch_to.window(tab_a)
        check(api_status(driver, "/api/board") == 200, "bench A's API after B opened")
        live_blocks(driver, a, "bench A")
        driver.save_screenshot(os.path.join(shots, "two-benches-a.png"))
        driver.switch_to.window(tab_b)
        live_blocks(driver, b, "bench B")
        driver.save_screenshot(os.path.join(shots, "two-benches-b.png"))
        for tab, bench, name in ((tab_a, a, "bench A"), (tab_b, b, "bench B")):
            driver.switch_to.window(tab)
            driver.refresh()
            ready(driver, name + " after a reload")
            check(api_status(driver, "/api/state") == 200, name + "'s API after a reload")
            live_blocks(driver, bench, name + " after a reload")

        driver.switch_to.new_window("tab")
        driver.get(other_url)
        wait(driver, lambda d: "hello" in d.page_source, "the other local server's page")
        check(Recorder.seen, "the other server saw no request")
        for path, headers in Recorder.seen:
            names = {k.lower() for k in headers}
            check("cookie" not in names, "the other server received a cookie: %s" % headers)
            for bench in benches:
                token = bench.url.split("?token=")[1]
                check(not any(token in v for v in headers.values()) and token not in path,
                      "the other server received a bench's token: %s %s" % (path, headers))
        print("other local server: %d requests, headers %s" % (
            len(Recorder.seen), sorted({k for _, h in Recorder.seen for k in h})))
    finally:
        driver.quit()
        recorder.shutdown()
        for bench in benches:
            bench.close()
    print("two benches browser test: passed in %.1f s (screenshots in %s)" %
          (time.monotonic() - t0, shots))
    if not args.screenshots:
        shutil.rmtree(work)


if __name__ == "__main__":
    main()
