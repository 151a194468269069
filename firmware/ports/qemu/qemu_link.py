"""Host side of the QEMU board image's USART link.

Starts `qemu-system-arm -M netduinoplus2` with USART1 on a Unix socket, frames 64-byte reports
as the image does (shared/include/vibid/shared/wire/serial_frame.hpp: sync 'V','F', length 64, report, CRC-32 little-endian over
length + report) and runs request/response exchanges with the wire header of
shared/include/vibid/shared/wire/report.hpp. Written from those layouts, independently of the
C++ codecs, so a test through it checks both sides.
"""

import os
import socket
import struct
import subprocess
import tempfile
import time
import zlib

SYNC = b"VF"
REPORT_BYTES = 64
FRAME_BYTES = 2 + 1 + REPORT_BYTES + 4

MAGIC = 0x4256  # bytes 'V','B'
PROTOCOL_MAJOR = 2
FLAG_RESPONSE = 1 << 0
FLAG_STREAM_END = 1 << 1
HEADER = struct.Struct("<HBBBBHHBB")  # magic, major, command, status, flags, token, sequence, len, reserved
MAX_PAYLOAD = REPORT_BYTES - HEADER.size


def encode_frame(report: bytes) -> bytes:
    assert len(report) == REPORT_BYTES
    body = bytes([REPORT_BYTES]) + report
    return SYNC + body + struct.pack("<I", zlib.crc32(body))


class FrameDecoder:
    """Byte-stream to reports; drops bytes until a sync + length + CRC check passes."""

    def __init__(self):
        self.buffer = bytearray()
        self.crc_errors = 0

    def feed(self, data: bytes):
        self.buffer += data
        reports = []
        while True:
            start = self.buffer.find(SYNC)
            if start < 0:
                del self.buffer[:-1]  # Keep a possible first sync byte.
                return reports
            del self.buffer[:start]
            if len(self.buffer) < FRAME_BYTES:
                return reports
            frame = bytes(self.buffer[:FRAME_BYTES])
            (crc,) = struct.unpack("<I", frame[-4:])
            if frame[2] == REPORT_BYTES and crc == zlib.crc32(frame[2:-4]):
                reports.append(frame[3:-4])
                del self.buffer[:FRAME_BYTES]
            else:
                self.crc_errors += 1
                del self.buffer[:1]


def encode_report(command: int, payload: bytes = b"", token: int = 0, sequence: int = 0) -> bytes:
    assert len(payload) <= MAX_PAYLOAD
    header = HEADER.pack(MAGIC, PROTOCOL_MAJOR, command, 0, 0, token, sequence, len(payload), 0)
    return (header + payload).ljust(REPORT_BYTES, b"\0")


STREAM_DATA_TAG = 0xD5
STREAM_HEADER = struct.Struct("<BBHH")  # tag, payload length, token, sequence


class Response:
    """A full report, or a stream data report (6-byte header: no command, status or flags)."""

    def __init__(self, report: bytes):
        self.raw = report
        self.stream_data = report[0] == STREAM_DATA_TAG
        if self.stream_data:
            _tag, length, self.token, self.sequence = STREAM_HEADER.unpack_from(report)
            self.magic = self.major = self.command = self.status = self.flags = self.reserved = 0
            self.payload = report[STREAM_HEADER.size:STREAM_HEADER.size + length]
            return
        (self.magic, self.major, self.command, self.status, self.flags, self.token, self.sequence,
         length, self.reserved) = HEADER.unpack_from(report)
        self.payload = report[HEADER.size:HEADER.size + length]


class QemuBoard:
    """The netduinoplus2 image under QEMU, reachable through request()."""

    def __init__(self, elf: str, qemu: str = "qemu-system-arm", icount_shift: int = 0,
                 timeout_s: float = 20.0):
        self.elf = elf
        self.qemu = qemu
        self.icount_shift = icount_shift
        self.timeout_s = timeout_s
        self.decoder = FrameDecoder()
        self.pending = []
        self.token = 0x100

    def __enter__(self):
        self.tmp = tempfile.TemporaryDirectory()
        path = os.path.join(self.tmp.name, "usart1.sock")
        self.diag_path = os.path.join(self.tmp.name, "usart2.log")
        cmd = [self.qemu, "-M", "netduinoplus2", "-display", "none", "-monitor", "none",
               "-no-reboot", "-icount", f"shift={self.icount_shift},align=off,sleep=off",
               "-chardev", f"socket,id=link,path={path},server=on,wait=on",
               "-serial", "chardev:link", "-serial", f"file:{self.diag_path}",
               "-kernel", self.elf]
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        deadline = time.monotonic() + self.timeout_s
        self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        while True:
            try:
                self.sock.connect(path)
                break
            except (FileNotFoundError, ConnectionRefusedError):
                if self.proc.poll() is not None or time.monotonic() > deadline:
                    out = self.proc.stdout.read().decode(errors="replace") if self.proc.stdout else ""
                    raise RuntimeError(f"QEMU did not open its USART socket: {out.strip()}")
                time.sleep(0.05)
        self.sock.settimeout(self.timeout_s)
        # USART1 drops bytes until the image has enabled it; it says "ready" on USART2 then.
        while "ready" not in self.diagnostics():
            if self.proc.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError("the image did not report ready on its diagnostics USART")
            time.sleep(0.02)
        return self

    def __exit__(self, *exc):
        self.sock.close()
        self.proc.kill()
        self.proc.wait()
        self.tmp.cleanup()

    def diagnostics(self) -> str:
        """What the image wrote to its USART2 diagnostics port so far."""
        try:
            with open(self.diag_path, encoding="ascii", errors="replace") as f:
                return f.read()
        except FileNotFoundError:
            return ""

    def send(self, report: bytes):
        self.sock.sendall(encode_frame(report))

    def receive(self) -> Response:
        while not self.pending:
            data = self.sock.recv(4096)
            if not data:
                raise RuntimeError("QEMU closed the USART socket")
            self.pending += self.decoder.feed(data)
        return Response(self.pending.pop(0))

    def request(self, command: int, payload: bytes = b"", sequence: int = 0) -> Response:
        """One request, one response (with the same token)."""
        self.token = (self.token + 1) & 0xFFFF
        self.send(encode_report(command, payload, self.token, sequence))
        while True:
            r = self.receive()
            if r.token == self.token:
                return r

    def stream(self, command: int, payload: bytes = b""):
        """A request answered by data reports and a trailer: returns (data reports, trailer)."""
        self.token = (self.token + 1) & 0xFFFF
        self.send(encode_report(command, payload, self.token))
        data = []
        while True:
            r = self.receive()
            if r.token != self.token:
                continue
            if r.flags & FLAG_STREAM_END or r.status != 0:
                return data, r
            data.append(r)
