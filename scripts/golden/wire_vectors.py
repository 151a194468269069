#!/usr/bin/env python3
"""Golden byte vectors for the wire protocol (shared/wire/testdata/wire_vectors.txt).

An independent encoder: every report and record is packed here with struct.pack from the
layouts documented in shared/include/vibid/shared/wire/*.hpp, and every CRC comes from
zlib.crc32, not from the C++ code under test. The C++ tests encode the same values and compare
bytes, and decode these bytes and compare fields with values written out in the test.

Run: /usr/bin/python3 scripts/golden/wire_vectors.py  (rewrites the vector file)
"""
import pathlib
import struct
import zlib

ROOT = pathlib.Path(__file__).resolve().parents[2]
OUT = ROOT / "shared/wire/testdata/wire_vectors.txt"
SEEDS = ROOT / "firmware/core/fuzz/seeds"

PROTOCOL_MAJOR = 2
PROTOCOL_MINOR = 1
CAL_RECORD_VERSION = 3
CAL_RECORD_BYTES = 1020
MAX_DOF = 4                      # M, C, K travel as 4x4 float32, row-major, zero-padded
MAGIC = b"VB"
FLAG_RESPONSE = 0x01
FLAG_STREAM_END = 0x02


STREAM_DATA_TAG = 0xD5


def stream_data(token, sequence, payload):
    """A stream data report: tag, payload length, token, sequence (6 bytes), payload, zeros."""
    assert 0 < len(payload) <= 58
    return (struct.pack("<BBHH", STREAM_DATA_TAG, len(payload), token, sequence) + payload).ljust(64, b"\0")


def report(command, status=0, flags=0, token=0, sequence=0, payload=b""):
    assert len(payload) <= 52
    header = MAGIC + struct.pack("<BBBBHHBB", PROTOCOL_MAJOR, command, status, flags, token,
                                 sequence, len(payload), 0)
    assert len(header) == 12
    return (header + payload).ljust(64, b"\0")


def f32(v):
    return struct.pack("<f", v)


def dob_description():
    """The two-input test filter of shared/wire/test/test_filter.hpp, packed from the layout in
    shared/include/vibid/shared/fixed/filter_description.hpp."""
    desc = b"VDOB" + struct.pack("<HBBI", 1, 2, 1, 5000)
    desc += bytes([1, 4, 0, 0])                  # input kinds: force, acceleration, unused
    desc += bytes([1, 1, 0, 0])                  # input masses
    desc += f32(100.0) + f32(490.0) + bytes(4)   # input full scales (N, m/s^2)
    desc += f32(200.0)                           # output full scale (N)
    one_q30 = 1 << 30
    for gain in (-(1 << 30), 1 << 30):
        section = struct.pack("<iiiiiBBH", one_q30 // 4, one_q30 // 8, 0, -3 * (one_q30 // 4),
                               one_q30 // 8, 1, 0, 0)
        desc += struct.pack("<BBHi", 1, 1, 0, gain) + section + bytes(7 * 24)
    desc += bytes(200)
    assert len(desc) == 636
    return desc + struct.pack("<I", zlib.crc32(desc))


# The residual test of the watch record (calibration_record.hpp "Watch"; residual_cusum.hpp):
# reference force1 (channel 0), sum_shift 14, z_shift 40, W 1000, residual gain 1/16 (Q32),
# reference gain -1/32 (Q32), center 2^24, z_gain 2^30, k 0.5 and h 8.25 (Q16), run length 5000;
# hold-off 0 (byte 3): a record written before the hold-off existed, which must still load.
WATCH = struct.pack("<BBBBIiiiiiif", 0, 14, 40, 0, 1000, 1 << 28, -(1 << 27), 1 << 24, 1 << 30,
                    1 << 15, 8 * 65536 + 16384, 5000.0)
assert len(WATCH) == 36


def matrix(rows):
    """An n x n matrix (n <= MAX_DOF) as the record's MAX_DOF x MAX_DOF float32 block."""
    out = b""
    for r in range(MAX_DOF):
        for c in range(MAX_DOF):
            out += f32(rows[r][c] if r < len(rows) and c < len(rows) else 0.0)
    return out


def calibration_record(with_dob=False, with_watch=False):
    flags = (1 if with_dob else 0) | (2 if with_watch else 0)
    body = b"VCAL" + struct.pack("<HHBBH", CAL_RECORD_VERSION, CAL_RECORD_BYTES, 2, flags, 0)
    body += struct.pack("<q", 1700000000)                   # created_unix_s
    body += struct.pack("<BBH", 0, 1, 7)                    # host 0.1.7
    body += b"rig-A two mass".ljust(24, b"\0")
    body += matrix([[0.57, 0.0], [0.0, 0.56]])              # mass_kg
    body += matrix([[1.25, -0.5], [-0.5, 0.75]])            # damping_ns_per_m
    body += matrix([[30.0, -15.0], [-15.0, 15.0]])          # stiffness_n_per_m
    channels = [
        # offset, gain, shift, unit, dof, full_scale
        (2048, 1 << 20, 0, 1, 0, 100.0),      # force1: N
        (2047, 1 << 20, 0, 1, 1, 100.0 if with_dob else 50.0),  # force2: N
        (2050, 3 << 19, 1, 2, 0, 490.3325),   # accel1: m/s^2
        (2046, 3 << 19, 1, 2, 1, 490.0 if with_dob else 490.3325),  # accel2
        (0, 1 << 17, 0, 3, 0, 0.5),           # encoder1: m
        (-5, -(1 << 17), 0, 3, 1, 0.5),       # encoder2: m, counting the other way
    ]
    for offset, gain, shift, unit, dof, full_scale in channels:
        body += struct.pack("<iiBBBB", offset, gain, shift, unit, dof, 0) + f32(full_scale)
    if with_dob:
        body += bytes([1, 3, 0xFF, 0])                    # DOB inputs: force2, accel2
        body += dob_description()
    else:
        body += bytes([0xFF, 0xFF, 0xFF, 0])              # no DOB inputs, reserved
        body += bytes(640)
    body += WATCH if with_watch else bytes(36)
    assert len(body) == CAL_RECORD_BYTES - 4
    return body + struct.pack("<I", zlib.crc32(body))


def calibration_record_chain4():
    """A chain of four masses (1.4, 1.2, 1.0, 0.8 kg; springs 4200..2400 N/m to ground first),
    each measured by one response input: acc1 on mass 1, x1 on 2, acc2 on 3, x2 on 4."""
    k = (4200.0, 3600.0, 3000.0, 2400.0)
    c = (3.0, 2.5, 2.0, 1.5)

    def chain(v):
        n = len(v)
        return [[(v[i] + (v[i + 1] if i + 1 < n else 0.0)) if i == j else
                 (-v[max(i, j)] if abs(i - j) == 1 else 0.0) for j in range(n)] for i in range(n)]

    body = b"VCAL" + struct.pack("<HHBBH", CAL_RECORD_VERSION, CAL_RECORD_BYTES, 4, 0, 0)
    body += struct.pack("<q", 1700000000) + struct.pack("<BBH", 0, 1, 7)
    body += b"chain4".ljust(24, b"\0")
    body += matrix([[1.4, 0, 0, 0], [0, 1.2, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 0.8]])
    body += matrix(chain(c)) + matrix(chain(k))
    channels = [
        (2048, 1 << 20, 0, 1, 3, 100.0),      # force1 on mass 4
        (2048, 1 << 20, 0, 1, 0xFF, 50.0),    # force2 on no mass
        (2048, 3 << 19, 1, 2, 0, 490.0),      # accel1 on mass 1
        (2048, 3 << 19, 1, 2, 2, 490.0),      # accel2 on mass 3
        (0, 1 << 17, 0, 3, 1, 0.5),           # encoder1 on mass 2
        (0, 1 << 17, 0, 3, 3, 0.5),           # encoder2 on mass 4
    ]
    for offset, gain, shift, unit, dof, full_scale in channels:
        body += struct.pack("<iiBBBB", offset, gain, shift, unit, dof, 0) + f32(full_scale)
    body += bytes([0xFF, 0xFF, 0xFF, 0]) + bytes(640) + bytes(36)
    assert len(body) == CAL_RECORD_BYTES - 4
    return body + struct.pack("<I", zlib.crc32(body))


def main():
    vectors = []

    def add(name, data):
        vectors.append((name, data))

    add("crc_check_input", b"123456789")
    add("crc_check_value", struct.pack("<I", zlib.crc32(b"123456789")))

    add("ping_request", report(0x01, token=0x1234, payload=b"hello"))
    add("ping_response", report(0x01, flags=FLAG_RESPONSE, token=0x1234, payload=b"hello"))

    info = struct.pack("<BBBBHHIII", PROTOCOL_MAJOR, PROTOCOL_MINOR, 0, 1, 2, 1, 0xDEADBEEF,
                       0x0000000F, 200)
    info += struct.pack("<II", 100, 98304)
    info += struct.pack("<HBB", 1000, 12, 4)                # 1000 reports/s, 12-bit ADC, watchdog
    info += struct.pack("<6B", 1, 1, 2, 2, 3, 3)
    info += struct.pack("<BB", 1, 1)                        # calibrated, slot B
    info += struct.pack("<III", 0xCAFEF00D, 3, 17)
    assert len(info) == 52
    add("info_response", report(0x02, flags=FLAG_RESPONSE, token=0x0102, payload=info))

    # get-info page 1 (2.1): the sampling instants, ns after the timer edge per channel.
    add("info_page_request", report(0x02, token=0x0103, payload=b"\x01"))
    add("sampling_info_response", report(0x02, flags=FLAG_RESPONSE, token=0x0103,
                                         payload=struct.pack("<6I", 2667, 5905, 2667, 2667, 2667, 2667)))

    # get-info page 2 (2.1): health, brown-out level 3 (4), a watchdog reset (4), the crystal
    # refused for its frequency (clock 3), measured at 12 000 340 Hz, 2 converter recoveries.
    add("health_page_request", report(0x02, token=0x0104, payload=b"\x02"))
    add("health_info_response", report(0x02, flags=FLAG_RESPONSE, token=0x0104,
                                       payload=struct.pack("<BBBBII", 4, 4, 3, 0, 12000340, 2)))

    # get-info page 4: the fault record after a fault reset: a BusFault (exception 5), CFSR
    # 0x00008200 (BFARVALID | PRECISERR), HFSR 0, MMFAR 0xE000ED34's reset value 0, BFAR
    # 0x40026400 (the DMA2 base, an illustrative address), stacked PC 0x08010abc, LR 0x08010a5b.
    add("fault_page_request", report(0x02, token=0x0107, payload=b"\x04"))
    add("fault_info_response", report(0x02, flags=FLAG_RESPONSE, token=0x0107,
                                      payload=struct.pack("<BBHIIIIII", 1, 5, 0, 0x00008200, 0, 0,
                                                          0x40026400, 0x08010ABC, 0x08010A5B)))

    # get-info page 3 (2.1): the residual test, watching and stale: W 1000, 812 windows, g 12.25,
    # h 8.25, last z -1, tripped at tick 811 999 with g 8.5, no clamps (Q16 values).
    add("watch_page_request", report(0x02, token=0x0105, payload=b"\x03"))
    add("watch_info_response", report(0x02, flags=FLAG_RESPONSE, token=0x0105,
                                      payload=struct.pack("<BBHIIiiiIiI", 2, 1, 0, 1000, 812, 12 * 65536 + 16384,
                                                          8 * 65536 + 16384, -65536, 811999, 8 * 65536 + 32768, 0)))

    # self-test (2.1): check 0 (hse-ppm) of 18 passes at -12.345 ppm (unit ppm, 10^-3) against
    # the host's USB frames (reference 1); check 12 (image-crc) is unavailable; check 18 is
    # refused invalid-argument, unknown-check.
    add("self_test_request", report(0x06, token=0x0106, payload=b"\x00"))
    add("self_test_response", report(0x06, flags=FLAG_RESPONSE, token=0x0106,
                                     payload=struct.pack("<BBBBbBHq", 0, 18, 1, 1, -3, 1, 0, -12345)))
    add("self_test_crc_response", report(0x06, flags=FLAG_RESPONSE, token=0x0107,
                                         payload=struct.pack("<BBBBbBHq", 12, 18, 2, 6, 0, 0, 0, 0)))
    add("refusal_unknown_check", report(0x06, status=1, flags=FLAG_RESPONSE, token=0x0108,
                                        payload=struct.pack("<HHI", 27, 0, 18)))

    status = struct.pack("<BBBBQ", 2, 1, 1, 0, 123456789012)
    status += struct.pack("<IIIIIIIIII", 5000, 400, 100, 2, 7, 1, 3, 40, 9, 0)
    assert len(status) == 52
    add("status_response", report(0x03, flags=FLAG_RESPONSE, token=0xFFFF, payload=status))

    acq = struct.pack("<IBBHBBHiII", 200, 0b100011, 0x03, 5, 1, 1, 0, 429496730, 250, 10000)
    assert len(acq) == 24
    add("acq_configure_request", report(0x20, token=0x0A0B, payload=acq))
    add("acq_configure_response",
        report(0x20, flags=FLAG_RESPONSE, token=0x0A0B, payload=struct.pack("<HHI", 12, 0, 6144)))

    # A refusal: acq-configure with status failed-precondition (3), no payload (a 2.0 device).
    add("refusal_response", report(0x20, status=3, flags=FLAG_RESPONSE, token=0x0A0C))
    # A 2.1 refusal: acq-configure with status invalid-argument (1) and its reason, observer-rate
    # (11), detail the observer's rate (5000 Hz): u16 reason, u16 reserved, u32 detail.
    add("refusal_reason_response", report(0x20, status=1, flags=FLAG_RESPONSE, token=0x0A0D,
                                          payload=struct.pack("<HHI", 11, 0, 5000)))
    # cal-commit refused failed-precondition (3), nothing-staged (13).
    add("refusal_nothing_staged", report(0x12, status=3, flags=FLAG_RESPONSE, token=0x0C0F,
                                         payload=struct.pack("<HHI", 13, 0, 0)))
    # get-clips (0x25): ticks, then clipped samples of force1..x2.
    add("clips_response", report(0x25, flags=FLAG_RESPONSE, token=0x2525,
                                 payload=struct.pack("<I6I", 50000, 1234, 0, 7, 0, 0, 65536)))

    add("log_read_request", report(0x24, token=0x7777, payload=struct.pack("<II", 10, 5)))

    # Log stream: channels force1, force2 (u16 12.4 codes), encoder2 (i32) plus d_hat (i32) ->
    # 12-byte records, four per stream data report after the 4-byte tick of its first record.
    # Records 10..14 at decimation 5; the board dropped the record of tick 1015, so the report
    # of records 10..12 ends at the gap and the next one starts at tick 1020.
    ticks = [1000, 1005, 1010, 1020, 1025]
    records = [
        struct.pack("<HHii", (2048 + i) << 4, (2047 - i) << 4, -3 * i, -(1 << 20) + i)
        for i in range(5)
    ]
    data_payloads = [struct.pack("<I", ticks[0]) + b"".join(records[0:3]),
                     struct.pack("<I", ticks[3]) + b"".join(records[3:5])]
    stream_bytes = b"".join(data_payloads)
    for seq, payload in enumerate(data_payloads):
        add(f"log_stream_{seq}", stream_data(0x7777, seq, payload))
    trailer = struct.pack("<IIIIHBBIHBBIIII", len(stream_bytes), zlib.crc32(stream_bytes), 10, 5,
                          12, 0b100011, 0x03, 200, 5, 3, 0, 0, 1, 0, 15)
    assert len(trailer) == 44
    add("log_stream_2", report(0x24, flags=FLAG_RESPONSE | FLAG_STREAM_END, token=0x7777,
                               sequence=2, payload=trailer))

    latest = struct.pack("<I6iiBB", 42, 1, -2, 3, -4, 5, -6, 99, 2, 1)
    add("latest_response", report(0x23, flags=FLAG_RESPONSE, token=3, payload=latest))

    record = calibration_record()
    add("calibration_record", record)
    add("calibration_record_dob", calibration_record(with_dob=True))
    add("calibration_record_watch", calibration_record(with_dob=True, with_watch=True))
    add("calibration_record_chain4", calibration_record_chain4())
    add("cal_put_begin", report(0x10, token=0x0C0C,
                                payload=struct.pack("<II", len(record), zlib.crc32(record))))
    chunks = (len(record) + 51) // 52
    assert chunks == 20
    add("cal_put_data_0", report(0x11, token=0x0C0C, sequence=0, payload=record[0:52]))
    add("cal_put_data_19", report(0x11, token=0x0C0C, sequence=19, payload=record[19 * 52:]))
    add("cal_commit_response",
        report(0x12, flags=FLAG_RESPONSE, token=0x0C0D, payload=struct.pack("<BBHI", 1, 0, 0, 8)))
    # cal-get sends the 1020-byte record in 18 stream data reports of up to 58 bytes.
    assert (len(record) + 57) // 58 == 18
    add("cal_get_trailer",
        report(0x13, flags=FLAG_RESPONSE | FLAG_STREAM_END, token=0x0C0E, sequence=18,
               payload=struct.pack("<IIBBHI", len(record), zlib.crc32(record), 1, 0, 0, 8)))

    add("dob_control_request", report(0x30, token=9, payload=b"\x01"))
    scenario = b"shaker".ljust(16, b"\0") + b"".join(f32(v) for v in (16.0, 2.5, 0.0, -1.0))
    add("scenario_request", report(0x70, token=0x70, payload=scenario))
    inject = struct.pack("<BBH", 2, 0, 0) + struct.pack("<6i", 1, 2, 3, 4, -5, -6) + \
        struct.pack("<6i", 2047, 2048, 4095, 0, 2147483647, -2147483648)
    add("inject_frames_request", report(0x71, token=0x71, payload=inject))

    lines = [
        "# Golden byte vectors of the vibid wire protocol.",
        "# Generated by scripts/golden/wire_vectors.py (struct.pack + zlib.crc32); do not edit.",
        f"protocol_major {PROTOCOL_MAJOR}",
        f"protocol_minor {PROTOCOL_MINOR}",
        f"cal_record_version {CAL_RECORD_VERSION}",
    ]
    lines += [f"{name} {data.hex()}" for name, data in vectors]
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text("\n".join(lines) + "\n")

    # Seed corpus for the fuzz targets (one directory each): valid inputs the fuzzer mutates from.
    v = dict(vectors)
    for target in ("wire_calibration_fuzz", "fw_request_fuzz", "wire_stream_fuzz"):
        (SEEDS / target).mkdir(parents=True, exist_ok=True)
    (SEEDS / "wire_calibration_fuzz/calibration_record").write_bytes(v["calibration_record"])
    (SEEDS / "wire_calibration_fuzz/calibration_record_dob").write_bytes(v["calibration_record_dob"])
    (SEEDS / "wire_calibration_fuzz/calibration_record_watch").write_bytes(v["calibration_record_watch"])
    (SEEDS / "wire_calibration_fuzz/calibration_record_chain4").write_bytes(v["calibration_record_chain4"])
    # Request seeds are in the harness's raw format (top bit of the first byte set); bit 0 is its
    # calibration switch (1: the filter is installed).
    (SEEDS / "fw_request_fuzz/requests").write_bytes(b"\x81" + v["ping_request"] + v["acq_configure_request"] +
                                                     v["log_read_request"] + v["dob_control_request"])
    (SEEDS / "fw_request_fuzz/get_clips").write_bytes(b"\x81" + v["acq_configure_request"] +
                                                      report(0x21, token=0x0A0E) +
                                                      report(0x25, token=0x0A0F))
    (SEEDS / "fw_request_fuzz/cal_put").write_bytes(b"\x80" + v["cal_put_begin"] + v["cal_put_data_0"])
    # Stream seeds in the raw format: a command id below 0x80, the token, the reports.
    (SEEDS / "wire_stream_fuzz/log_stream").write_bytes(bytes([0x24, 0x77, 0x77]) +
                                                        b"".join(v[f"log_stream_{i}"] for i in range(3)))
    # A log stream the board ends with a refusal that names its reason (log-overwritten, 16).
    (SEEDS / "wire_stream_fuzz/log_stream_refused").write_bytes(
        bytes([0x24, 0x77, 0x77]) + v["log_stream_0"] +
        report(0x24, status=2, flags=FLAG_RESPONSE, token=0x7777,
               payload=struct.pack("<HHI", 16, 0, 190171)))

if __name__ == "__main__":
    main()
