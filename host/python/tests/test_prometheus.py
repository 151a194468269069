"""The watch's metrics scraped by Debian's Prometheus server (scripts/setup --for test), on
loopback: `vibid watch --metrics-port` on the emulator's rig with a mass step, Prometheus started
here with the committed example's scrape config and alert rules (a short interval, a temporary
store), the series and the firing alert read back through its HTTP API and checked against the
watch's own journal and the rig's truth (vibid-emu --print-truth). A second job with a wrong token
is refused (its target down): the token rule of the bench holds for scrapers too."""
import json
import math
import pathlib
import shutil
import socket
import subprocess
import time
import urllib.parse
import urllib.request

import pytest

import vibid
from conftest import EMU, ROOT, STATE_WAIT_S, VIBID, Emulator

EXAMPLE = ROOT / "examples" / "prometheus"
RIGS = ROOT / "host" / "emulator" / "rigs"
STEP_S = 240.0  # the mass step (as docs/watch.md's short watch: 0.459 kg on mass 2)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def api(port: int, path: str, **params) -> dict:
    url = f"http://127.0.0.1:{port}/api/v1/{path}"
    if params:
        url += "?" + urllib.parse.urlencode(params)
    with urllib.request.urlopen(url, timeout=10) as r:
        body = json.load(r)
    assert body["status"] == "success", body
    return body["data"]


def wait_for(what: str, probe, timeout_s: float = STATE_WAIT_S):
    """probe() until it returns something true (a state Prometheus reaches by itself after a few
    scrapes and evaluations); fails naming what it waited for."""
    end = time.monotonic() + timeout_s
    while True:
        try:
            got = probe()
        except OSError:
            got = None
        if got:
            return got
        assert time.monotonic() < end, f"Prometheus never showed {what}"
        time.sleep(0.5)


def truth_hz(rig: pathlib.Path, at_s: float) -> list:
    out = subprocess.run([str(EMU), "--rig", str(rig), "--print-truth", "--at-s", str(at_s)],
                         capture_output=True, text=True, check=True).stdout
    modal = vibid.modal(vibid.Model.from_dict(json.loads(out)))
    return sorted(float(w) / (2 * math.pi) for w in modal.omega_rad_s)


def test_prometheus_scrapes_the_watch_and_fires_its_alarm(tmp_path):
    prometheus = shutil.which("prometheus")
    assert prometheus, "Debian's prometheus is missing: run ./scripts/setup --for test"

    rig = json.loads((RIGS / "chain2_mass_step.json").read_text())
    rig["changes"][0]["at_s"] = STEP_S
    rig["changes"][0]["add_kg"] = 0.459
    rig_path = tmp_path / "step240.json"
    rig_path.write_text(json.dumps(rig))

    token = tmp_path / "metrics.token"
    journal = tmp_path / "watch.jsonl"
    emu = Emulator(tmp_path, rig=rig_path)
    watch = prom = None
    try:
        # The watch: 320 s at 200 Hz, a 230 s reference, windows of six 5 s blocks; it keeps
        # serving its last figures once the acquisition ends (--metrics-keep).
        watch = subprocess.Popen(
            [str(VIBID), f"--device={emu.url}", "watch", "--seconds", "320", "--rate-hz", "200",
             "--scenario", "operate", "--reference-s", "230", "--block-s", "5",
             "--window-blocks", "6", "--modes-s", "70", "-o", str(journal),
             "--metrics-port", "0", "--token-file", str(token), "--metrics-rig", "rig-a",
             "--metrics-keep"],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        said = ""
        while "last figures are served" not in said:
            line = watch.stderr.readline()
            assert line, f"vibid watch ended early: {said}"
            said += line
        metrics_port = int(said.split("metrics on http://127.0.0.1:")[1].split("/")[0])
        assert token.stat().st_mode & 0o077 == 0  # the token file is its owner's only

        # Prometheus with the example's config: its target and token file swapped for this run's,
        # and a second job whose token is wrong.
        config = (EXAMPLE / "prometheus.yml").read_text()
        assert "127.0.0.1:9451" in config and "/etc/vibid/metrics.token" in config
        config = config.replace("scrape_interval: 15s", "scrape_interval: 1s")
        config = config.replace("evaluation_interval: 15s", "evaluation_interval: 1s")
        config = config.replace("/etc/vibid/metrics.token", str(token))
        config = config.replace("          - 127.0.0.1:9452\n", "")
        config = config.replace("127.0.0.1:9451", f"127.0.0.1:{metrics_port}")
        config = config.replace("vibid_rules.yml", str(EXAMPLE / "vibid_rules.yml"))
        wrong = tmp_path / "wrong.token"
        wrong.write_text("0" * 32 + "\n")
        config += (f"  - job_name: vibid-wrong-token\n"
                   f"    authorization:\n      type: Bearer\n      credentials_file: {wrong}\n"
                   f"    static_configs:\n      - targets: ['127.0.0.1:{metrics_port}']\n")
        (tmp_path / "prometheus.yml").write_text(config)
        port = free_port()
        prom = subprocess.Popen(
            [prometheus, f"--config.file={tmp_path / 'prometheus.yml'}",
             f"--storage.tsdb.path={tmp_path / 'data'}",
             f"--web.listen-address=127.0.0.1:{port}"],
            stdout=subprocess.DEVNULL, stderr=(tmp_path / "prometheus.log").open("w"))

        lines = [json.loads(l) for l in journal.read_text().splitlines()]
        assert lines[0]["header"] == "vibid watch"  # the journal's first line says what was watched
        blocks = lines[1:]
        last = blocks[-1]
        first_alarm = next(b["t_s"] for b in blocks if b["alarm"])

        def series(query: str) -> dict:
            return {tuple(sorted(r["metric"].items())): float(r["value"][1])
                    for r in api(port, "query", query=query)["result"]}

        def one(query: str) -> float:
            got = series(query)
            assert len(got) == 1, (query, got)
            return next(iter(got.values()))

        # The series: the alarm, its time and the last block's tests as the journal has them.
        wait_for("vibid_watch_alarm", lambda: series('vibid_watch_alarm{rig="rig-a"}'))
        assert one('vibid_watch_alarm{rig="rig-a",job="vibid"}') == 1.0
        assert one("vibid_watch_first_alarm_time_seconds") == first_alarm
        # The step comes at 240 s: the first window wholly after the reference (230-260 s) holds
        # it and alarms when full (docs/watch.md's short watch).
        assert first_alarm == 260.0
        assert one("vibid_watch_time_seconds") == last["t_s"] == 320.0
        assert one("vibid_watch_blocks_total") == len(blocks) == 18
        assert one("vibid_watch_window_statistic") == pytest.approx(
            last["accumulated"]["statistic"], rel=1e-12)
        assert one("vibid_watch_window_threshold") == pytest.approx(
            last["accumulated"]["threshold"], rel=1e-12)
        assert one("vibid_watch_block_statistic") == pytest.approx(last["statistic"], rel=1e-12)
        assert one("vibid_watch_block_f_quantile") == pytest.approx(last["f_quantile"], rel=1e-12)
        band = lines[0]["reference"]["false_alarms_per_hour_95"]
        assert one('vibid_watch_reference_false_alarms_per_hour{bound="low"}') == pytest.approx(
            band[0], rel=1e-12)
        assert one('vibid_watch_reference_false_alarms_per_hour{bound="high"}') == pytest.approx(
            band[1], rel=1e-12)
        assert one("vibid_watch_running") == 0.0

        # The modes of the last 70 s (250-320 s: the rig after the step; SSI-cov wants 65 s at
        # this band) against its truth there,
        # and the reference's against the truth before it.
        after, before = truth_hz(rig_path, 285.0), truth_hz(rig_path, 0.0)
        def by_mode(query: str) -> dict:
            return {int(dict(k)["mode"]): v for k, v in series(query).items()}

        modes = by_mode("vibid_watch_mode_frequency_hertz")
        widths = by_mode("vibid_watch_mode_frequency_ci95_hertz")
        assert sorted(modes) == [1, 2]
        for mode, f_hz in modes.items():
            assert abs(f_hz - after[mode - 1]) < 3 * widths[mode], (mode, f_hz, after)
        reference = by_mode("vibid_watch_reference_mode_frequency_hertz")
        ref_widths = by_mode("vibid_watch_reference_mode_frequency_ci95_hertz")
        assert sorted(reference) == [1, 2]
        for mode, f_hz in reference.items():
            assert abs(f_hz - before[mode - 1]) < 3 * ref_widths[mode], (mode, f_hz, before)
        # The 30 % mass lowers mode 1 by far more than its interval: the scrape shows it.
        assert modes[1] < reference[1] - 3 * ref_widths[1] - 3 * widths[1]

        # The alert of the example's rules, firing with its rig.
        def firing():
            return [a for a in api(port, "alerts")["alerts"]
                    if a["labels"]["alertname"] == "VibidWatchAlarm" and a["state"] == "firing"]
        alerts = wait_for("VibidWatchAlarm firing", firing)
        assert alerts[0]["labels"]["rig"] == "rig-a"
        assert "260 s" in alerts[0]["annotations"]["description"]

        # The wrong token's job is refused by the gate: its target is down, its error the 403.
        def wrong_down():
            targets = api(port, "targets")["activeTargets"]
            return [t for t in targets if t["labels"]["job"] == "vibid-wrong-token"
                    and t["health"] == "down"]
        down = wait_for("the wrong token's target down", wrong_down)
        assert "403" in down[0]["lastError"]
        assert one('up{job="vibid-wrong-token"}') == 0.0
        assert one('up{job="vibid"}') == 1.0
    finally:
        for p in (prom, watch):
            if p is not None and p.poll() is None:
                p.send_signal(2)  # SIGINT: the watch ends with 130, Prometheus shuts down
                try:
                    p.wait(timeout=30)
                except subprocess.TimeoutExpired:
                    p.kill()
        emu.stop()
    assert watch.returncode == 130
