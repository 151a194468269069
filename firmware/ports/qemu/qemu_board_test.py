#!/usr/bin/env python3
"""Boots the netduinoplus2 board image in QEMU and talks to it over its USART1 link.

Checks, through qemu_link.py (framing and report header written independently of the C++):
ping echoes its payload and token; get-info names the QEMU board, the protocol and firmware
versions and the six channels; an unknown command is refused with kUnimplemented; an
acquisition on injected samples returns exactly the injected frames through log-read, with the
stream CRC-32 matching and no overrun or starved frame lost. Prints the sampling cost the image
reports on its diagnostics USART.

usage: qemu_board_test.py IMAGE.elf --fw-version X.Y.Z
"""

import argparse
import random
import struct
import sys
import time
import zlib

import qemu_link
from qemu_link import FLAG_RESPONSE, FLAG_STREAM_END, QemuBoard

# Command ids and statuses (shared/include/vibid/shared/wire/commands.hpp, status.hpp).
PING, GET_INFO, GET_STATUS = 0x01, 0x02, 0x03
ACQ_CONFIGURE, ACQ_START, ACQ_STOP, LOG_READ = 0x20, 0x21, 0x22, 0x24
INJECT_FRAMES = 0x71
OK, UNAVAILABLE, UNIMPLEMENTED = 0, 5, 6
BOARD_QEMU = 2
CAP_SAMPLE_INJECTION = 1 << 4
CHANNEL_KINDS = [1, 1, 2, 2, 3, 3]  # load cell x2, accelerometer x2, encoder x2

# get-info payload layout (InfoResponse, 52 bytes).
INFO = struct.Struct("<BBBBHHIIIIIB6sBBBHIII")

failures = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        failures.append(what)


def test_ping(board):
    payload = b"vibid over USART1"
    r = board.request(PING, payload)
    check(r.magic == qemu_link.MAGIC and r.major == qemu_link.PROTOCOL_MAJOR, "ping: magic and major")
    check(r.command == PING and r.status == OK, "ping: command echoed, status ok")
    check(r.flags & FLAG_RESPONSE != 0, "ping: response flag set")
    check(r.token == board.token, "ping: token echoed")
    check(r.payload == payload, "ping: payload echoed")


def test_info(board, fw_version):
    r = board.request(GET_INFO)
    check(r.status == OK and len(r.payload) == INFO.size, f"get-info: ok with {INFO.size} bytes")
    if len(r.payload) != INFO.size:
        return
    (proto_major, _proto_minor, fw_major, fw_minor, fw_patch, board_id, _build, caps, period_us,
     min_period_us, log_bytes, channel_count, kinds, _reset, cal_state, _slot, _res, _crc,
     overruns, dropped) = INFO.unpack(r.payload)
    check(proto_major == 1, "get-info: protocol major 1")
    check((fw_major, fw_minor, fw_patch) == fw_version, f"get-info: firmware {fw_version}")
    check(board_id == BOARD_QEMU, "get-info: board id is the QEMU netduinoplus2 image")
    check(caps & CAP_SAMPLE_INJECTION != 0, "get-info: sample injection advertised")
    check(period_us == 200 and min_period_us == 100, "get-info: 200 us default period, 100 us minimum")
    check(log_bytes >= 32 * 1024, f"get-info: log capacity {log_bytes} bytes")
    check(channel_count == 6 and list(kinds) == CHANNEL_KINDS, "get-info: six channels, kinds in order")
    check(cal_state == 0, "get-info: RAM calibration slots start uncalibrated")
    check(overruns == 0 and dropped == 0, "get-info: no overruns or drops at boot")


def test_unknown_command(board):
    r = board.request(0x60)
    check(r.status == UNIMPLEMENTED and r.flags & FLAG_RESPONSE != 0, "unknown command: kUnimplemented")


def inject(board, frames):
    """Sends frames two per report, resending a report the device refuses while its queue is full."""
    for i in range(0, len(frames), 2):
        chunk = frames[i:i + 2]
        payload = bytes([len(chunk), 0, 0, 0]) + b"".join(struct.pack("<6i", *f) for f in chunk)
        while True:
            r = board.request(INJECT_FRAMES, payload)
            if r.status == OK:
                break
            if r.status != UNAVAILABLE:
                raise RuntimeError(f"inject-frames refused with status {r.status}")
            time.sleep(0.01)


def test_acquisition(board, count=600):
    rng = random.Random(20261121)
    frames = [[rng.randrange(0, 4096) for _ in range(4)] + [rng.randrange(-2**31, 2**31) for _ in range(2)]
              for _ in range(count)]
    # 200 us period, all six channels, no d_hat, decimation 1, immediate trigger, stop after count.
    config = struct.pack("<IBBHBBHiII", 200, 0x3F, 0, 1, 0, 0, 0, 0, 0, count)
    r = board.request(ACQ_CONFIGURE, config)
    check(r.status == OK, "acquisition: configure accepted")
    record_bytes, _, capacity = struct.unpack("<HHI", r.payload)
    check(record_bytes == 28, "acquisition: 28-byte records (index + six channels)")
    check(board.request(ACQ_START).status == OK, "acquisition: started")
    inject(board, frames)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        status = board.request(GET_STATUS)
        acq_state, records = status.payload[0], struct.unpack_from("<I", status.payload, 16)[0]
        if acq_state == 3 or records >= count:
            break
        time.sleep(0.05)
    board.request(ACQ_STOP)
    data, trailer = board.stream(LOG_READ, struct.pack("<II", 0, 0))
    check(trailer.status == OK and trailer.flags & FLAG_STREAM_END != 0, "log-read: stream trailer")
    (total, crc, first, n, rec_bytes, _mask, _flags, _period, _dec, _state, _res, _trig, dropped,
     overruns, written) = struct.unpack_from("<IIIIHBBIHBBIIII", trailer.payload)
    body = b"".join(d.payload for d in data)
    check([d.sequence for d in data] == list(range(len(data))), "log-read: sequences 0..n-1")
    check(total == len(body) and crc == zlib.crc32(body), "log-read: byte count and CRC-32 of the stream")
    check(first == 0 and n == count and rec_bytes == 28, f"log-read: {count} records from 0")
    check(dropped == 0 and overruns == 0, "log-read: no dropped records, no overruns")
    records = []
    for d in data:
        for k in range(len(d.payload) // 28):
            records.append(struct.unpack_from("<I6i", d.payload, 28 * k))
    check([r[0] for r in records] == list(range(count)), "log-read: sample indices 0..count-1")
    check([list(r[1:]) for r in records] == frames, "log-read: every record equals the injected frame")


def report_isr_cost(diag):
    """The image counts SysTick cycles (168 MHz core clock) spent in the sampling interrupt; under
    -icount shift=0 one instruction takes 1 ns of virtual time, so cycles * 1e9 / 168e6 is the
    number of instructions."""
    for line in reversed(diag.splitlines()):
        fields = line.split()
        if fields[:1] == ["frames"]:
            values = dict(zip(fields[0::2], (int(v) for v in fields[1::2])))
            per_frame = values["isr_cycles"] / values["frames"]
            print(f"sampling interrupt: {per_frame:.1f} core cycles = "
                  f"{per_frame * 1e9 / 168e6:.0f} instructions per sample")
            return


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("image")
    parser.add_argument("--fw-version", required=True)
    args = parser.parse_args()
    fw_version = tuple(int(x) for x in args.fw_version.split("."))
    with QemuBoard(args.image) as board:
        test_ping(board)
        test_info(board, fw_version)
        test_unknown_command(board)
        test_acquisition(board)
        diag = board.diagnostics()
    print("diagnostics:\n" + diag.strip())
    report_isr_cost(diag)
    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
