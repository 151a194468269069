"""The board (or vibid-emu): its profile, acquisitions whole or streamed, the watch on it, its
calibration and its observer (``vibid devices``, ``info``, ``acquire``, ``watch --device``,
``cal upload|commit``, ``dob start|stop``)."""
from __future__ import annotations

import json

import os
from typing import Iterator, Optional, Sequence

from . import _vibid
from ._checks import _flag, _input_path, _integer, _kind, _names, _real, _reals, _text
from ._vibid import DeviceError
from .model import Model, load_model
from .observer import ObserverDesign
from .recording import Recording

def list_devices() -> list:
    """(spec, description) of every board and emulator found (``vibid devices``)."""
    return _vibid.list_devices()


def _settings(seconds, rate_hz, log_rate_hz, decimation, channels, trigger, trigger_timeout_s,
              pretrigger_s, no_dob, allow_drops, scenario, scenario_params):
    """acquire's and stream's arguments, each of its type (TypeError naming it otherwise), in the
    library's settings; their values are checked there, as the CLI's are (ValueError with the
    CLI's message: a length that is not > 0, a rate the board cannot sample...)."""
    s = _vibid._AcquireSettings()
    s.seconds = _real("seconds", seconds)
    s.rate_hz = _real("rate_hz", rate_hz)
    s.log_rate_hz = _real("log_rate_hz", log_rate_hz)
    s.decimation = _integer("decimation", decimation)
    s.channels = _names("channels", channels)
    if channels is not None and not s.channels:
        # The library reads an empty list as "every channel": only None means that here.
        raise ValueError("channels: an empty list names no channel; name them "
                         "(channels=['force1', 'acc1']) or pass None for every channel")
    s.trigger = _text("trigger", trigger)
    s.trigger_timeout_s = _real("trigger_timeout_s", trigger_timeout_s)
    s.pretrigger_s = _real("pretrigger_s", pretrigger_s)
    s.no_dob = _flag("no_dob", no_dob)
    s.allow_drops = _flag("allow_drops", allow_drops)
    return s, _text("scenario", scenario), _reals("scenario_params", scenario_params)


class Board:
    """A board (or vibid-emu) opened by the ``--device`` URL: ``hid``, ``hid:SERIAL``,
    ``usbip://HOST:PORT``, ``serial:PATH``, ``qemu``; "" takes $VIBID_DEVICE, else the only
    board found. Use as a context manager or call close()."""

    def __init__(self, url: str = ""):
        import weakref
        self._b = _vibid._Board(_text("url", url))
        self._watches = weakref.WeakSet()  # live watches: stopped before the board is closed

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self) -> None:
        for w in list(self._watches):
            w.close()
        self._b.close()

    def info(self) -> dict:
        """The board's profile, as ``vibid info --json`` prints it."""
        return self._b.info()

    def state(self) -> str:
        """The acquisition state: idle, armed, acquiring, done."""
        return self._b.state()

    def acquire(self, seconds: float, rate_hz: float = 5000.0, log_rate_hz: float = 0.0,
                decimation: int = 0, channels=None, trigger: str = "",
                trigger_timeout_s: float = 0.0, pretrigger_s: float = 0.0, no_dob: bool = False,
                allow_drops: bool = False, scenario: str = "",
                scenario_params: Sequence[float] = ()) -> Recording:
        """Records from the board (``vibid acquire``, same options, defaults and checks) and
        returns the recording in SI units through the board's calibration, with each record's
        tick in ``sample_index``. ``channels``: names (["force1", "acc1"] or "force1,acc1"); all
        when None. d_hat is logged when the board's observer runs, unless ``no_dob``. Every
        argument is checked before the board starts (TypeError for a wrong type, ValueError with
        the CLI's message for a wrong value), and so is the link: an acquisition it cannot carry
        is refused. The memory used is that of the records asked for. However the acquisition
        ends, the records kept are returned: Ctrl-C stops the board and raises
        KeyboardInterrupt; a trigger that does not fire within ``trigger_timeout_s``, a log the
        board overwrote before it could be read, or a board that fails or goes away raises
        DeviceError; each carries the records kept in the exception's ``recording``
        attribute."""
        s, scenario, params = _settings(seconds, rate_hz, log_rate_hz, decimation, channels,
                                        trigger, trigger_timeout_s, pretrigger_s, no_dob,
                                        allow_drops, scenario, scenario_params)
        names, data, fs, index, instants, end, facts = self._b.acquire(s, scenario, params)
        rec = Recording(names=names[1:], data=data[1:], fs_hz=fs,
                        t0_s=float(data[0, 0]) if data.shape[1] else 0.0,
                        sample_index=index, sample_instants_us=instants or None, t_s=data[0],
                        facts=json.loads(facts))
        if end == "interrupted":
            e = KeyboardInterrupt(f"acquisition stopped by Ctrl-C: kept {rec.samples} records")
            e.recording = rec
            raise e
        if end:
            kind, why = end.split(": ", 1)
            e = DeviceError(why if kind == "incomplete" else
                            f"{why}: acquisition stopped, kept {rec.samples} records" if
                            kind == "trigger-timeout" else
                            f"{why}; kept the {rec.samples} records that had arrived")
            e.recording = rec
            raise e
        return rec

    def stream(self, seconds: float, rate_hz: float = 5000.0, log_rate_hz: float = 0.0,
               decimation: int = 0, channels=None, trigger: str = "",
               trigger_timeout_s: float = 0.0, pretrigger_s: float = 0.0, no_dob: bool = False,
               allow_drops: bool = False, scenario: str = "",
               scenario_params: Sequence[float] = ()) -> Iterator[Recording]:
        """The acquisition of ``acquire`` (same options, checks, preflight and calibration),
        yielding its records in blocks (Recordings, ``sample_index`` the board's ticks) as the
        board's reports arrive; every record exactly once, in order. Leaving the loop early
        (``break``, an exception, Ctrl-C) stops the board; the records after the last block are
        then not yielded. The arguments are checked when it is called, before the first block is
        asked for."""
        s, scenario, params = _settings(seconds, rate_hz, log_rate_hz, decimation, channels,
                                        trigger, trigger_timeout_s, pretrigger_s, no_dob,
                                        allow_drops, scenario, scenario_params)
        if s.trigger_timeout_s > 0.0 and s.trigger:
            raise ValueError("trigger_timeout_s: a stream waits for its trigger until the loop "
                             "is left; leave the loop to give up")
        st = self._b.stream_start(s, scenario, params)
        return self._blocks(st)

    @staticmethod
    def _blocks(st) -> Iterator[Recording]:
        fs = st.fs_hz
        next_index = 0
        finished = False

        def block(names, data, index):
            return Recording(names=names[1:], data=data[1:], fs_hz=fs,
                             t0_s=float(data[0, 0]) if data.shape[1] else 0.0,
                             sample_index=index, t_s=data[0])
        try:
            while True:
                r = st.next(0.1)
                if r[0] == "end":
                    break
                if r[0] == "wait":
                    continue
                _, first, names, data, index = r
                skip = max(0, next_index - first)  # a resumed stream may send a record again
                if skip >= index.size:
                    continue
                next_index = first + index.size
                yield block(names, data[:, skip:], index[skip:])
            names, data, index, _ = st.finish(next_index)
            finished = True
            if index.size:
                yield block(names, data, index)
        finally:
            if not finished:
                st.stop()
                try:
                    st.finish(next_index)
                except DeviceError:
                    pass

    def watch(self, seconds: Optional[float] = None, rate_hz: float = 1000.0, **options):
        """The rig watched on the board (``vibid watch --device``, the same runner, options and
        defaults): the acquisition started, preflighted and run as ``acquire`` runs it
        (``rate_hz``, ``log_rate_hz``, ``decimation``, ``channels`` (default acc1, acc2),
        ``no_dob``, ``scenario``, ``scenario_params``), for ``seconds`` (None: until the loop is
        left), and its records fed to the watch as they arrive. Returns a ``LiveWatch`` that
        yields each ``WatchBlock`` as the records complete it; ``responses``, ``reference`` (a
        recording file), ``journal`` and the analysis options are ``vibid.watch``'s. When the
        board logs its model test (``model_g``, ``model_stale``) every block carries its flag.
        Every option is checked (and the journal created) here, before the board is touched;
        leaving the loop (``break``, Ctrl-C) stops the board and keeps the journal."""
        from ._watch import _board_watch
        return _board_watch(self, seconds, rate_hz, **options)

    def cal_upload(self, model, design, sensors=None, label: str = "",
                   accept_flagged: bool = False) -> dict:
        """Builds the calibration record and stages it on the board (``vibid cal upload``):
        ``model`` a Model or a model file, ``design`` an ObserverDesign (or its JSON),
        ``sensors`` a sensors file's path or its JSON object (None: the scaling the board
        already holds); the label defaults to the model file's name. cal_commit() makes it
        permanent. A model whose verdict is flagged raises vibid.FlaggedResultError, nothing
        sent, unless ``accept_flagged=True``."""
        import json
        if isinstance(model, Model):
            m, default_label = model, "model"
        elif isinstance(model, (str, os.PathLike)):
            m, default_label = load_model(model), _vibid.label_from_model_path(os.fspath(model))
        else:
            raise TypeError(f"model: expected a vibid.Model or a model file's path, got "
                            f"{_kind(model)}")
        _vibid.require_usable(m.verdict, bool(accept_flagged),
                              "the model" if isinstance(model, Model) else
                              "model file " + os.fspath(model), "cal_upload",
                              "accept_flagged=True")
        if sensors is not None and not isinstance(sensors, dict):
            with open(_input_path("sensors", sensors)) as f:
                sensors = json.load(f)
        if isinstance(design, ObserverDesign):
            j = design.json
        elif isinstance(design, dict):
            j = design
        else:
            raise TypeError(f"design: expected an ObserverDesign (dob_design) or its JSON "
                            f"object, got {_kind(design)}")
        return self._b.cal_upload(m._m, j, sensors, _text("label", label) or default_label)

    def cal_commit(self) -> dict:
        """Writes the staged calibration record to flash (``vibid cal commit``)."""
        return self._b.cal_commit()

    def dob_start(self) -> None:
        """Runs the observer of the active calibration (``vibid dob start``)."""
        self._b.dob(True)

    def dob_stop(self) -> None:
        """Stops the observer (``vibid dob stop``); acquisitions then log no d_hat by default."""
        self._b.dob(False)

    def __repr__(self) -> str:
        return f"Board({self._b.describe()!r})"
