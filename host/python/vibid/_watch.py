"""vibid.watch: the rig watched while it runs (``vibid watch``), on the library's WatchSession;
vibid.ssi_cov: the output-only modes it tracks.

The session decides everything (the reference, the modes and their intervals, the block and
window tests, the alarm); this module converts: arrays in, each block out as a ``WatchBlock``
whose ``to_dict()`` is the JSON object ``vibid watch --json`` prints for it, key for key.
"""
from __future__ import annotations

import dataclasses
import json
import os
from typing import Iterator, Optional

import numpy as np

from . import _vibid
from ._checks import _input_path, _integer, _kind, _names, _output_path, _real, _repr
from .recording import Recording, read_recording

_DEFAULTS = _vibid._WatchOptions()  # the library's defaults, those of `vibid watch`


@dataclasses.dataclass(repr=False)
class WatchMode:
    """One mode of a block (or of the reference) with its 95 % half-widths."""
    omega_rad_s: float
    zeta: float
    omega_ci95_rad_s: float
    zeta_ci95: float

    @property
    def freq_hz(self) -> float:
        return self.omega_rad_s / (2.0 * np.pi)

    @property
    def freq_ci95_hz(self) -> float:
        return self.omega_ci95_rad_s / (2.0 * np.pi)

    def __repr__(self) -> str:
        return (f"WatchMode(freq_hz={self.freq_hz:.4f} ± {self.freq_ci95_hz:.4f}, "
                f"zeta={self.zeta:.4f} ± {self.zeta_ci95:.4f})")


def _modes(ms) -> list:
    return [WatchMode(m["omega_rad_s"], m["zeta"], m["ci95"]["omega_rad_s"], m["ci95"]["zeta"])
            for m in ms]


@dataclasses.dataclass(repr=False)
class WatchBlock:
    """One watched block, as a line of ``vibid watch --json``: its end ``t_s``, its number
    ``block`` (from 1 after the reference), the modes over the last ``modes_s`` seconds (none
    before that much has come: ``modes_message`` says why), the block's T² ``statistic`` and
    the F quantile at the per-block rate ``f_quantile``, not a calibrated threshold (one block's
    T² is heavier-tailed; ``block_over``: over it, shown, not an alarm), the window's test
    ``accumulated``
    ({statistic, threshold, blocks, window_blocks, alarm}), the sequential test ``sequential``
    ({statistic g, threshold h, onset_blocks: the onset that maximised g, blocks held, alarm}),
    ``alarm`` (this block completed a window that alarmed, or the sequential test alarmed),
    ``first_alarm_t_s``, the mode that ``moved`` most against the
    reference ({mode, omega_ref_rad_s, omega_rad_s, change_rad_s, ci95_rad_s, relative}), the
    board's model test ``board`` ({stale, statistic, threshold, stale_since_t_s}; None without
    the log's model columns), ``analysis_ms``. ``text`` is the CLI's line for it."""
    t_s: float
    block: int
    modes: list
    statistic: float
    f_quantile: float
    alarm: bool
    block_over: bool
    accumulated: dict
    sequential: dict
    first_alarm_t_s: Optional[float]
    moved: Optional[dict]
    board: Optional[dict]
    modes_message: str
    analysis_ms: float
    text: str
    _line: str = dataclasses.field(default="", compare=False)

    @classmethod
    def _of(cls, line: str, text: str) -> "WatchBlock":
        d = json.loads(line)
        return cls(t_s=d["t_s"], block=d["block"], modes=_modes(d["modes"]),
                   statistic=d["statistic"], f_quantile=d["f_quantile"], alarm=d["alarm"],
                   block_over=d["block_over"], accumulated=d["accumulated"],
                   sequential=d["sequential"],
                   first_alarm_t_s=d["first_alarm_t_s"], moved=d["moved"], board=d["board"],
                   modes_message=d["modes_message"], analysis_ms=d["analysis_ms"], text=text,
                   _line=line)

    def to_dict(self) -> dict:
        """The JSON object of ``vibid watch --json`` (and of its journal) for this block."""
        return json.loads(self._line)

    def __str__(self) -> str:
        return self.text

    def __repr__(self) -> str:
        return f"WatchBlock({self.text})"


@dataclasses.dataclass(repr=False)
class WatchReference:
    """The reference as the session built it: its ``source`` ("watched": the first
    ``reference_s`` seconds fed; "recording": one given), its span ``from_t_s`` to ``to_t_s``
    (its first and last sample), its length, its modes (SSI-cov, 95 % intervals), the test's
    model ``order``, its residuals ``dof`` over ``reference_blocks`` blocks, and the block's F
    quantile (not a calibrated threshold) and the window's threshold, the false alarms per hour
    this reference gives (``false_alarms_per_hour_95``: low, high; and their mean over
    references) and the reference that would narrow them (``advised_reference_s``); the
    sequential test's threshold (``sequential_threshold``; an exact reference's
    ``sequential_exact_threshold``) and the false alarms per hour this reference gives it
    (``sequential_false_alarms_per_hour_95``, ``sequential_false_alarms_per_hour_mean``)."""
    source: str
    from_t_s: float
    to_t_s: float
    seconds: float
    modes: list
    order: int
    dof: int
    reference_blocks: int
    block_f_quantile: float
    window_threshold: float
    false_alarms_per_hour_95: tuple
    false_alarms_per_hour_mean: float
    advised_reference_s: float
    sequential_threshold: float
    sequential_exact_threshold: float
    sequential_false_alarms_per_hour_95: tuple
    sequential_false_alarms_per_hour_mean: float
    analysis_ms: float
    _dict: dict = dataclasses.field(default_factory=dict, compare=False)

    @classmethod
    def _of(cls, d: dict) -> "WatchReference":
        return cls(source=d["source"], from_t_s=d["span"]["from_t_s"],
                   to_t_s=d["span"]["to_t_s"], seconds=d["seconds"], modes=_modes(d["modes"]),
                   order=d["order"],
                   dof=d["dof"], reference_blocks=d["reference_blocks"],
                   block_f_quantile=d["block_f_quantile"], window_threshold=d["window_threshold"],
                   false_alarms_per_hour_95=tuple(d["false_alarms_per_hour_95"]),
                   false_alarms_per_hour_mean=d["false_alarms_per_hour_mean"],
                   advised_reference_s=d["advised_reference_s"],
                   sequential_threshold=d["sequential_threshold"],
                   sequential_exact_threshold=d["sequential_exact_threshold"],
                   sequential_false_alarms_per_hour_95=tuple(
                       d["sequential_false_alarms_per_hour_95"]),
                   sequential_false_alarms_per_hour_mean=d["sequential_false_alarms_per_hour_mean"],
                   analysis_ms=d["analysis_ms"], _dict=d)

    def to_dict(self) -> dict:
        return json.loads(json.dumps(self._dict))

    def __repr__(self) -> str:
        return _repr("WatchReference", source=self.source, seconds=self.seconds,
                     modes=self.modes, order=self.order,
                     window_threshold=self.window_threshold,
                     false_alarms_per_hour_95=self.false_alarms_per_hour_95)


def _rows(name: str, x, rows: Optional[int] = None) -> np.ndarray:
    """Responses as (channels, samples) float64 in C order (a 1-D array is one channel)."""
    a = np.asarray(x)
    if a.dtype.kind not in "biuf":
        raise TypeError(f"{name}: expected real numbers (float64), got dtype {a.dtype}")
    if a.ndim == 1:
        a = a[None, :]
    if a.ndim != 2:
        raise ValueError(f"{name} must be 2-D (channels, samples), not {a.ndim}-D")
    if rows is not None and a.shape[0] != rows:
        raise ValueError(f"{name} has {a.shape[0]} rows, not {rows} (one per channel, shaped "
                         f"(channels, samples))")
    return np.ascontiguousarray(a, dtype=np.float64)


def _options(reference_s, block_s, window_blocks, false_alarm_per_hour, fmax_hz, modes_s, order,
             sequential_blocks=_DEFAULTS.sequential_blocks):
    """The analysis options, each of its type (TypeError naming it); their values are the
    library's to check."""
    o = _vibid._WatchOptions()
    o.reference_s = _real("reference_s", reference_s)
    o.block_s = _real("block_s", block_s)
    o.window_blocks = _integer("window_blocks", window_blocks)
    o.sequential_blocks = _integer("sequential_blocks", sequential_blocks)
    o.false_alarm_per_hour = _real("false_alarm_per_hour", false_alarm_per_hour)
    o.fmax_hz = _real("fmax_hz", fmax_hz)
    o.modes_s = _real("modes_s", modes_s)
    o.order = _integer("order", order)
    return o


class WatchSession:
    """A running rig watched block by block (the session ``vibid watch`` runs): ``feed`` the
    responses as they come, shaped (channels, samples) at ``fs_hz``; the first ``reference_s``
    seconds are the reference (or ``set_reference`` gives a recording of the rig as it should be
    before the first feed), then every ``block_s`` seconds completes a ``WatchBlock``. The options
    and their defaults are ``vibid watch``'s (``reference_s`` 1800, ``block_s`` 10,
    ``window_blocks`` 60, ``false_alarm_per_hour`` 0.01, ``fmax_hz`` 25, ``modes_s`` 120, ``order``
    0: from the reference's modes, ``sequential_blocks`` 60: the sequential test's longest onset);
    the library checks them (ValueError naming the option).
    ``board_threshold`` is the board's model-test threshold h, shown beside its statistic when the
    board's columns are fed."""

    def __init__(self, fs_hz: float, channels: int, reference_s: float = _DEFAULTS.reference_s,
                 block_s: float = _DEFAULTS.block_s,
                 window_blocks: int = _DEFAULTS.window_blocks,
                 false_alarm_per_hour: float = _DEFAULTS.false_alarm_per_hour,
                 fmax_hz: float = _DEFAULTS.fmax_hz, modes_s: float = _DEFAULTS.modes_s,
                 order: int = _DEFAULTS.order, board_threshold: Optional[float] = None,
                 sequential_blocks: int = _DEFAULTS.sequential_blocks):
        o = _options(reference_s, block_s, window_blocks, false_alarm_per_hour, fmax_hz, modes_s,
                     order, sequential_blocks)
        o.fs_hz = _real("fs_hz", fs_hz)
        o.channels = _integer("channels", channels)
        self._s = _vibid._WatchSession(o)
        self._o = o
        if board_threshold is not None:
            h = _real("board_threshold", board_threshold)
            if not h > 0.0:
                raise ValueError(f"board_threshold={h}: the board's threshold h is positive "
                                 "(info()['model_stale']['threshold'])")
            self._s.set_board_threshold(h)

    @property
    def options(self) -> dict:
        """The options as the session took them."""
        o = self._o
        return {"fs_hz": o.fs_hz, "channels": o.channels, "reference_s": o.reference_s,
                "block_s": o.block_s, "window_blocks": o.window_blocks,
                "sequential_blocks": o.sequential_blocks,
                "false_alarm_per_hour": o.false_alarm_per_hour, "fmax_hz": o.fmax_hz,
                "modes_s": o.modes_s, "order": o.order}

    @property
    def channels(self) -> int:
        return self._o.channels

    def set_reference(self, reference) -> WatchReference:
        """A recording of the rig as it should be, (channels, samples) at the same rate, in place
        of the first ``reference_s`` seconds: every sample fed is then watched. Before the first
        feed only."""
        self._s.set_reference(_rows("reference", reference, self._o.channels))
        return self.reference

    def feed(self, samples, t_first_s: Optional[float] = None, board=None) -> list:
        """Responses in order, (channels, samples); ``t_first_s`` the time of the first of them
        (kept from the first call: later times follow from the count). ``board``: the board's
        model test beside each sample, shaped (2, samples): its statistic g and its flag (0 or
        1), as a log's ``model_g`` and ``model_stale`` columns. Returns the blocks completed."""
        y = _rows("samples", samples, self._o.channels)
        b = None if board is None else _rows("board", board, 2)
        if b is not None and b.shape[1] != y.shape[1]:
            raise ValueError(f"board has {b.shape[1]} samples, the responses {y.shape[1]}: one "
                             "column of the board's statistic and flag per sample")
        t = None if t_first_s is None else _real("t_first_s", t_first_s)
        return [WatchBlock._of(line, text) for line, text in self._s.feed(y, b, t)]

    def gap(self, missing: int) -> None:
        """``missing`` samples were lost: the block under way is dropped, the next starts with
        the next sample fed (a gap in the reference is refused)."""
        self._s.gap(_integer("missing", missing))

    @property
    def has_reference(self) -> bool:
        return self._s.has_reference

    @property
    def reference_left_s(self) -> float:
        """Seconds of reference still to come (0 once built)."""
        return self._s.reference_left_s

    @property
    def reference(self) -> Optional[WatchReference]:
        """The reference's summary once it is built, else None."""
        d = self._s.reference()
        return None if d is None else WatchReference._of(d)

    @property
    def header(self) -> Optional[dict]:
        """The journal's first line once the reference is built (else None), as ``vibid watch
        --json`` prints it: {"header": "vibid watch", "version", "options" (with the block's and
        the window's false-alarm probabilities), "reference" (its source, span, modes with
        intervals and thresholds)}."""
        line = self._s.header()
        return None if line is None else json.loads(line)

    def __repr__(self) -> str:
        return _repr("WatchSession", fs_hz=self._o.fs_hz, channels=self._o.channels,
                     reference_left_s=self.reference_left_s)


class _Journal:
    """Each block's JSON line appended and flushed as it comes (``vibid watch -o``): a crash or
    Ctrl-C leaves every whole line. Created (or truncated) before anything is watched."""

    def __init__(self, path):
        self._f = None
        if path is not None:
            p = _output_path("journal", path)
            try:
                self._f = open(p, "w")
            except OSError as e:
                raise ValueError(f"journal={p!r}: cannot create the journal: {e.strerror}; give "
                                 "a writable path") from None

    def header(self, line: str) -> None:
        """The first line: the options and the reference (WatchSession.header)."""
        if self._f is not None:
            self._f.write(line + "\n")
            self._f.flush()

    def append(self, block: WatchBlock) -> None:
        if self._f is not None:
            self._f.write(block._line + "\n")
            self._f.flush()

    def close(self) -> None:
        if self._f is not None:
            self._f.close()
            self._f = None


def _recording(name: str, source) -> tuple:
    """A Recording or a recording file: (Recording, its name in messages)."""
    if isinstance(source, Recording):
        return source, "the " + ("reference " if name == "reference" else "") + "recording"
    if isinstance(source, (str, os.PathLike)):
        path = _input_path(name, source)
        return read_recording(path), path
    raise TypeError(f"{name}: expected a vibid.Recording, a recording file's path or an array "
                    f"(channels, samples), got {_kind(source)}")


class Watch:
    """The blocks of a watched recording or array, computed as they are iterated (each block's
    JSON line journaled as it comes). ``responses``: the columns watched; ``reference``: the
    reference's summary once built; ``session``: the WatchSession."""

    def __init__(self, session: WatchSession, y: np.ndarray, board: Optional[np.ndarray],
                 t0_s: Optional[float], responses: list, journal: _Journal,
                 file: Optional[str] = None):
        self.session, self.responses = session, responses
        self._y, self._board, self._t0 = y, board, t0_s
        self._journal = journal
        self._at = 0
        self._ready: list = []
        self._step = max(1, int(round(session.options["block_s"] * session.options["fs_hz"])))
        if not session.has_reference:
            # The reference now (it makes no block), so that its summary, and a reference that
            # shows no mode, are there before the first block is asked for.
            n = int(round(session.options["reference_s"] * session.options["fs_hz"]))
            board = None if board is None else board[:, :n]
            assert not session.feed(y[:, :n], t0_s, board)
            self._at = n
        self.header = session.header
        if self.header is not None:
            journal.header(json.dumps(self.header) if file is None else
                           json.dumps({**self.header, "reference": {**self.header["reference"],
                                                                    "file": file}}))

    @property
    def reference(self) -> Optional[WatchReference]:
        return self.session.reference

    def __iter__(self) -> Iterator[WatchBlock]:
        return self

    def __next__(self) -> WatchBlock:
        # Fed a block's worth at a time, as a board feeds it, so each block is out when made.
        while not self._ready and self._at < self._y.shape[1]:
            end = min(self._at + self._step, self._y.shape[1])
            board = None if self._board is None else self._board[:, self._at:end]
            self._ready = self.session.feed(self._y[:, self._at:end], self._t0, board)
            self._at = end
            for b in self._ready:
                self._journal.append(b)
        if not self._ready:
            self._journal.close()
            raise StopIteration
        return self._ready.pop(0)

    def close(self) -> None:
        """Stops the watch here (the journal keeps the blocks made so far)."""
        self._at = self._y.shape[1]
        self._ready = []
        self._journal.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __repr__(self) -> str:
        return _repr("Watch", responses=self.responses, fed_s=self._at / self.session.options[
            "fs_hz"], reference=self.reference)


def watch(source, fs_hz: Optional[float] = None, responses=None, reference=None,
          journal=None, board=None, t0_s: Optional[float] = None,
          reference_s: float = _DEFAULTS.reference_s, block_s: float = _DEFAULTS.block_s,
          window_blocks: int = _DEFAULTS.window_blocks,
          false_alarm_per_hour: float = _DEFAULTS.false_alarm_per_hour,
          fmax_hz: float = _DEFAULTS.fmax_hz, modes_s: float = _DEFAULTS.modes_s,
          order: int = _DEFAULTS.order, board_threshold: Optional[float] = None,
          sequential_blocks: int = _DEFAULTS.sequential_blocks) -> Watch:
    """The rig watched block by block (``vibid watch REC.csv``, the same options, defaults and
    blocks): ``source`` a recording (a ``vibid.Recording`` or a file as ``acquire`` writes it),
    or an array (channels, samples) at ``fs_hz``. A recording's watched columns are
    ``responses`` (names), by default every acceleration and position column, as the CLI's;
    when it has the board's model-test columns (``model_g``, ``model_stale``) each block carries
    the board's flag (``board``; for an array, ``board`` is that (2, samples) array).
    ``reference``: a recording (or array) of the rig as it should be, in place of the first
    ``reference_s`` seconds. ``journal``: a file each block's JSON line is appended to as it
    comes. Every argument is checked here; the blocks are computed as the returned ``Watch`` is
    iterated (``list(vibid.watch(...))`` for all). On a board (``source`` a ``vibid.Board``):
    ``Board.watch`` with these options."""
    from .board import Board
    if isinstance(source, Board):
        if fs_hz is not None or board is not None or t0_s is not None:
            raise ValueError("fs_hz, board and t0_s are a recording's or an array's; the board "
                             "gives them (Board.watch takes rate_hz)")
        return source.watch(responses=responses, reference=reference, journal=journal,
                            reference_s=reference_s, block_s=block_s,
                            window_blocks=window_blocks,
                            false_alarm_per_hour=false_alarm_per_hour, fmax_hz=fmax_hz,
                            modes_s=modes_s, order=order, sequential_blocks=sequential_blocks)
    if board_threshold is not None and board is None and not isinstance(
            source, (Recording, str, os.PathLike)):
        raise ValueError("board_threshold: the array's board columns are not given (board=...)")
    names = _names("responses", responses)
    if isinstance(source, np.ndarray) or (isinstance(source, (list, tuple)) and source):
        if fs_hz is None:
            raise ValueError("fs_hz: an array's sample rate must be given (fs_hz=...)")
        if names:
            raise ValueError("responses: an array has no column names; pass the rows to watch")
        y = _rows("source", source)
        fs = _real("fs_hz", fs_hz)
        columns = [f"response{i + 1}" for i in range(y.shape[0])]
        b = None if board is None else _rows("board", board, 2)
        t0 = t0_s
    else:
        if board is not None:
            raise ValueError("board: a recording's board columns are its model_g and model_stale")
        rec, where = _recording("source", source)
        if fs_hz is not None and _real("fs_hz", fs_hz) != rec.fs_hz:
            raise ValueError(f"fs_hz={fs_hz}: {where} is sampled at {rec.fs_hz} Hz; leave fs_hz "
                             "out for a recording")
        fs = rec.fs_hz
        columns, g, flag = _vibid.watch_columns(list(rec.names), names, str(where))
        y = np.ascontiguousarray(rec.data[[rec.index(n) for n in columns]])
        b = (None if g is None else
             np.ascontiguousarray(rec.data[[rec.index(g), rec.index(flag)]]))
        t0 = rec.t0_s if t0_s is None else t0_s
    if b is not None and b.shape[1] != y.shape[1]:
        raise ValueError(f"board has {b.shape[1]} samples, the responses {y.shape[1]}")
    session = WatchSession(fs, len(columns), reference_s=reference_s, block_s=block_s,
                           window_blocks=window_blocks, false_alarm_per_hour=false_alarm_per_hour,
                           fmax_hz=fmax_hz, modes_s=modes_s, order=order,
                           board_threshold=board_threshold, sequential_blocks=sequential_blocks)
    if reference is not None:
        if isinstance(reference, np.ndarray):
            ref = reference
        else:
            r, where = _recording("reference", reference)
            if abs(r.fs_hz / fs - 1.0) >= 1e-6:
                raise ValueError(f"reference: {where} is sampled at {r.fs_hz:g} Hz, the watched "
                                 f"responses at {fs:g} Hz; record both at one rate")
            ref = r.data[[r.index(n) for n in columns]]
        session.set_reference(ref)
    elif y.shape[1] / fs < session.options["reference_s"]:
        raise ValueError(f"watch: the responses hold {y.shape[1] / fs:g} s, shorter than the "
                         f"reference (reference_s={session.options['reference_s']:g}); give a "
                         "longer recording, a shorter reference_s or a reference")
    if t0 is not None:
        t0 = _real("t0_s", t0)
    ref_file = os.fspath(reference) if isinstance(reference, (str, os.PathLike)) else None
    return Watch(session, y, b, t0, columns, _Journal(journal), ref_file)


class LiveWatch:
    """The blocks of a watch on the board (``Board.watch``), as the board's records complete
    them. ``start``: what the board is about to log ({responses, log_rate_hz, board_columns,
    model_stale, model_text}), ``reference``: the reference's summary once built, ``result``:
    how the run ended ({stopped, warning, model_stale, model_text, model_before,
    reference_built, reference_left_s, blocks, log_rate_hz}), each None until known. Leaving the
    loop early (``break``, an exception, Ctrl-C) or ``close()`` stops the board; the journal keeps
    every block made. Held in a name (``w = board.watch(...)``), it runs until its end,
    ``close()``, the end of a ``with`` block over it, or the board's ``close()``; in a ``for``
    statement alone, until the loop is left."""

    def __init__(self, st):
        self._st = st
        self.start: Optional[dict] = None
        self.reference: Optional[WatchReference] = None
        self.header: Optional[dict] = None  # the journal's first line, once the reference is built
        self.result: Optional[dict] = None
        self._it = self._blocks()

    def __iter__(self) -> Iterator[WatchBlock]:
        return self

    def __next__(self) -> WatchBlock:
        return next(self._it)

    def _take(self, r) -> Optional[WatchBlock]:
        kind = r[0]
        if kind == "start":
            self.start = r[1]
        elif kind == "reference":
            self.reference = WatchReference._of(r[1])
        elif kind == "header":
            self.header = r[1]
        elif kind == "block":
            return WatchBlock._of(r[1], r[2])
        elif kind == "end":
            self.result = r[1]
        return None

    def _blocks(self) -> Iterator[WatchBlock]:
        finished = False
        try:
            while True:
                r = self._st.next(0.1)  # Ctrl-C is noticed between waits
                if r[0] == "end":
                    self._take(r)
                    finished = True
                    return
                block = self._take(r)
                if block is not None:
                    yield block
        finally:
            if not finished:
                # The runner stops the board at its next report; its end is waited for, so the
                # board is idle when the loop is left.
                self._st.stop()
                while True:
                    try:
                        r = self._st.next(0.1)
                    except Exception:  # the run's own error: the loop's is the one raised
                        break
                    if r[0] == "end":
                        self._take(r)
                        break

    def close(self) -> None:
        """Stops the board (the blocks made so far are kept in the journal)."""
        self._it.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __repr__(self) -> str:
        return _repr("LiveWatch", start=self.start, reference=self.reference, result=self.result)


def _board_watch(board, seconds: Optional[float] = None, rate_hz: float = 1000.0,
                 log_rate_hz: float = 0.0, decimation: int = 0, channels=None,
                 no_dob: bool = False, scenario: str = "", scenario_params=(), responses=None,
                 reference=None, journal=None, reference_s: float = _DEFAULTS.reference_s,
                 block_s: float = _DEFAULTS.block_s, window_blocks: int = _DEFAULTS.window_blocks,
                 false_alarm_per_hour: float = _DEFAULTS.false_alarm_per_hour,
                 fmax_hz: float = _DEFAULTS.fmax_hz, modes_s: float = _DEFAULTS.modes_s,
                 order: int = _DEFAULTS.order,
                 sequential_blocks: int = _DEFAULTS.sequential_blocks) -> LiveWatch:
    from .board import _settings
    if seconds is not None and _real("seconds", seconds) <= 0.0:
        raise ValueError(f"seconds={seconds}: watch for a positive length, or seconds=None "
                         "until the loop is left")
    s, scenario, params = _settings(0.0 if seconds is None else seconds, rate_hz, log_rate_hz,
                                    decimation, channels, "", 0.0, 0.0, no_dob, False, scenario,
                                    scenario_params)
    if reference is not None and not isinstance(reference, (str, os.PathLike)):
        raise TypeError(f"reference: expected a recording file's path (Recording.write_csv "
                        f"writes one), got {_kind(reference)}")
    ref = "" if reference is None else _input_path("reference", reference)
    path = "" if journal is None else _output_path("journal", journal)
    o = _options(reference_s, block_s, window_blocks, false_alarm_per_hour, fmax_hz, modes_s,
                 order, sequential_blocks)
    w = LiveWatch(board._b.watch_start(s, scenario, params, _names("responses", responses),
                                       ref, o, path))
    board._watches.add(w)
    return w


@dataclasses.dataclass(repr=False)
class OmaModes:
    """Output-only modes (SSI-cov) in ascending frequency: freq_hz, omega_rad_s, zeta, shapes
    (one column per mode, real-normalised: largest entry +1), 95 % half-widths in ``ci95``
    (omega_rad_s, freq_hz, zeta, shape), the stabilization diagram's poles as arrays
    (``stabilization``: order, freq_hz, zeta, stable, cluster), the rate analysed ``fs_hz``
    (after decimation), ``message`` (why a mode or interval is missing, or empty) and the
    library's ``json``."""
    freq_hz: np.ndarray
    omega_rad_s: np.ndarray
    zeta: np.ndarray
    shapes: np.ndarray
    ci95: dict
    stabilization: dict
    fs_hz: float
    message: str
    json: dict

    def __repr__(self) -> str:
        return _repr("OmaModes", freq_hz=self.freq_hz, zeta=self.zeta,
                     freq_ci95_hz=self.ci95["freq_hz"], message=self.message)


def ssi_cov(responses, fs_hz: float, fmax_hz: Optional[float] = None,
            fmin_hz: Optional[float] = None) -> OmaModes:
    """Output-only modes of responses alone (covariance-driven SSI, docs/watch.md: the
    stabilization diagram, the automatic pole choice and the 95 % intervals from the Hankel
    matrix's covariance over 20 blocks), the analysis each watch block runs: ``responses``
    (channels, samples) at ``fs_hz``, modes between ``fmin_hz`` (default fmax_hz/10) and
    ``fmax_hz`` (default fs_hz/2.5). The rig runs under broadband ambient or operating
    excitation; no force is measured."""
    o = _vibid._SsiCovOptions()
    o.fs_hz = _real("fs_hz", fs_hz)
    if fmax_hz is not None:
        o.fmax_hz = _real("fmax_hz", fmax_hz)
    if fmin_hz is not None:
        o.fmin_hz = _real("fmin_hz", fmin_hz)
    j = _vibid.ssi_cov(_rows("responses", responses), o)
    ms = j["modes"]
    channels = j["channels"]
    poles = j["stabilization"]["poles"]
    return OmaModes(
        freq_hz=np.array([m["freq_hz"] for m in ms], dtype=float),
        omega_rad_s=np.array([m["omega_rad_s"] for m in ms], dtype=float),
        zeta=np.array([m["zeta"] for m in ms], dtype=float),
        shapes=np.array([m["shape"] for m in ms], dtype=float).reshape(-1, channels).T,
        ci95={q: np.array([m["ci95"][q] for m in ms], dtype=float)
              for q in ("omega_rad_s", "freq_hz", "zeta")} | {
            "shape": np.array([m["ci95"]["shape"] for m in ms],
                              dtype=float).reshape(-1, channels).T},
        stabilization={k: np.array([p[k] for p in poles]) for k in
                       ("order", "freq_hz", "zeta", "stable", "cluster")},
        fs_hz=j["fs_hz"], message=j["message"], json=j)
